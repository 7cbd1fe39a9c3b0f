"""The ledger does its contacts' work a batch of steps at a time (``_contacts.Contacts.flush``).
A balance asked for after every step (each flushes what is held) and one asked for only at the
end (batches of ``BATCH`` steps, a structural change in the middle of one, pushes carried
over a batch's end) must give the same account: every term within 1e-12 of the scale, the same
sources, the same verdict."""

from __future__ import annotations

import math

import pymunk
import pytest

from dumbbell import spaces
from dumbbell.spaces._contacts import Contacts


def _pull(body, gravity, damping, dt):
    """A field pulling towards (0, 20), F = -k m (r - r0), k = 30 /s^2."""
    x, y = body.position
    pymunk.Body.update_velocity(body, (-30.0 * x, -30.0 * (y - 20.0)), damping, dt)


def _wind(body, gravity, damping, dt):
    """A push to the right no potential describes."""
    pymunk.Body.update_velocity(body, (gravity[0] + 40.0, gravity[1]), damping, dt)


def _space() -> pymunk.Space:
    space = pymunk.Space()
    space.gravity = (0, -600)
    floor = pymunk.Segment(space.static_body, (-400, 0), (400, 0), 4)
    floor.friction, floor.elasticity = 0.7, 0.3
    space.add(floor)
    for i in range(6):  # boxes started slightly into each other: the position correction
        box = pymunk.Body(1 + 0.1 * i, pymunk.moment_for_box(1, (20, 20)))
        box.position = (-100 + 19 * i, 13 + (i % 2) * 19)
        shape = pymunk.Poly.create_box(box, (20, 20))
        shape.friction, shape.elasticity = 0.6, 0.4
        space.add(box, shape)
    paddle = pymunk.Body(body_type=pymunk.Body.KINEMATIC)  # pushes the boxes: driven work
    paddle.position, paddle.velocity = (-160, 15), (60, 0)
    space.add(paddle, pymunk.Poly.create_box(paddle, (16, 30)))
    rail = pymunk.Body(2, math.inf)  # infinite moment: its spin is imposed
    rail.position, rail.angular_velocity = (60, 10), 0.5
    space.add(rail, pymunk.Poly.create_box(rail, (40, 12)))
    held = pymunk.Body(1, 50)  # a declared field holds it down on the floor
    held.position, held.velocity_func = (0, 25), _pull
    blown = pymunk.Body(1, 50)  # a custom velocity_func with no potential
    blown.position, blown.velocity_func = (120, 12), _wind
    for b in (held, blown):
        c = pymunk.Circle(b, 10)
        c.friction = 0.5
        space.add(b, c)
    return space


def _run(every_step: bool) -> spaces.Balance:
    space = _space()
    ledger = spaces.Ledger(space)
    ledger.declare_potential(_pull, lambda x, y, m: 15.0 * m * (x**2 + (y - 20.0) ** 2),
                             name="pull")
    for k in range(3 * Contacts.BATCH + 5):
        if k == Contacts.BATCH + 3:  # a body enters in the middle of a batch
            ball = pymunk.Body(1, 20)
            ball.position, ball.velocity = (-60, 60), (0, -50)
            space.add(ball, pymunk.Circle(ball, 8))
        dt = 1 / 120 if (k // 7) % 2 == 0 else 1 / 90  # a push carried across a change of dt
        space.step(dt)
        if every_step:
            ledger.balance()
    return ledger.balance()


def test_a_balance_at_the_end_is_the_one_asked_for_after_every_step():
    every, end = _run(True), _run(False)
    scale = every.scale
    assert (end.E0, end.E, end.scale) == (every.E0, every.E, every.scale)
    assert (end.complete, end.unaccounted) == (every.complete, every.unaccounted)
    a = {(t.source, t.kind): t.energy for t in every.terms}
    b = {(t.source, t.kind): t.energy for t in end.terms}
    assert {k for k, v in a.items() if abs(v) > 1e-12 * scale} == \
        {k for k, v in b.items() if abs(v) > 1e-12 * scale}
    for key in a.keys() | b.keys():
        assert abs(a.get(key, 0.0) - b.get(key, 0.0)) <= 1e-12 * scale, key
    assert abs(end.relative_closure) <= 1e-12 and abs(every.relative_closure) <= 1e-12
    # Every branch the batch takes the contacts' work out of was taken, with real work.
    kinds = {t.kind for t in end.terms if abs(t.energy) > 1e-6 * scale}
    assert {"contact", "kinematic", "velocity_func", "correction"} <= kinds, kinds
    assert any(t.source.startswith("pushed apart") for t in end.terms)
    assert any(t.source == "pull" for t in end.terms)


@pytest.mark.parametrize("held", [1, Contacts.BATCH - 1, Contacts.BATCH, Contacts.BATCH + 1])
def test_a_copy_or_a_detach_between_batches_keeps_the_account(held):
    # Steps still held when the account is read (a copy, a detach) are counted in it.
    import copy

    space = _space()
    ledger = spaces.Ledger(space)
    for _ in range(held):
        space.step(1 / 120)
    snapshot = copy.copy(ledger).balance()
    ledger.detach()
    final = ledger.balance()
    assert snapshot.steps == final.steps == held
    assert [(t.source, t.energy) for t in snapshot.terms] == \
        [(t.source, t.energy) for t in final.terms]
    assert any(t.kind == "contact" and t.energy for t in final.terms)
