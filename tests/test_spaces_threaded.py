"""dumbbell.spaces on a space made with ``pymunk.Space(threaded=True)``.

pymunk's threaded solver (Munk2D's cpHastySpace) splits each step's solver iterations
between ``space.threads`` threads (at most 2), each sweeping every contact and joint at the
same time, without locks, in steps with more than 50 touching pairs and joints. At the
default ``threads = 1`` a step is the serial solver's, bit for bit; at 2, impulses can be
lost, and runs do not repeat. The guard says so in a row of its own, and a ledger that
cannot account for a body names the threads as well as the callbacks it names on any space.
"""

from __future__ import annotations

import platform

import pymunk
import pytest

from dumbbell import spaces

pytestmark = pytest.mark.skipif(platform.system() == "Windows",
                                reason="pymunk has no threaded solver on Windows")


def _pile(threaded: bool, threads: int = 1) -> pymunk.Space:
    """A pile of 55 boxes on a floor and a ball on a pivot with a finite max_force thrown
    into it (pixels, y up): well over 50 touching pairs once the pile settles."""
    space = pymunk.Space(threaded=threaded)
    if threaded:
        space.threads = threads
    space.gravity = (0, -900)
    floor = pymunk.Segment(space.static_body, (-500, 0), (500, 0), 2)
    floor.friction = 0.8
    space.add(floor)
    for i in range(10):
        for j in range(10 - i):
            box = pymunk.Body(1, pymunk.moment_for_box(1, (20, 20)))
            box.position = (j * 21 + i * 10.5, 11 + i * 21)
            shape = pymunk.Poly.create_box(box, (20, 20))
            shape.friction, shape.elasticity = 0.6, 0.2
            space.add(box, shape)
    ball = pymunk.Body(5, pymunk.moment_for_circle(5, 0, 10))
    ball.position, ball.velocity = (-200, 50), (400, 0)
    pivot = pymunk.PivotJoint(space.static_body, ball, (-300, 200), (0, 0))
    pivot.max_force = 2000
    space.add(ball, pymunk.Circle(ball, 10), pivot)
    return space


def _run(space: pymunk.Space, steps: int = 240) -> spaces.Balance:
    ledger = spaces.Ledger(space)
    for _ in range(steps):
        space.step(1 / 120)
    return ledger.balance()


def test_one_thread_is_counted_as_the_serial_solver_bit_for_bit():
    serial, threaded = _run(_pile(False)), _run(_pile(True, 1))
    assert threaded.complete is True
    assert (threaded.E, threaded.E0) == (serial.E, serial.E0)
    assert [(t.source, t.kind, t.energy) for t in threaded.terms] == \
        [(t.source, t.kind, t.energy) for t in serial.terms]


def test_two_threads_are_never_counted_as_complete_unless_everything_closes():
    # Whether the threads lose an impulse in this run depends on how they interleave: the
    # ledger says complete only when nothing is left over, and otherwise names the threads.
    space = _pile(True, 2)
    bal = _run(space)
    assert abs(bal.E - spaces.energy(space).E) <= 1e-9 * bal.scale
    if bal.complete:
        assert bal.unaccounted == () and abs(bal.relative_closure) <= bal.tolerance
    else:
        reasons = dict(bal.unaccounted)
        assert reasons and all("space.threads = 2" in why for why in reasons.values()), reasons


@pytest.mark.parametrize("threads", [1, 2])
def test_a_callbacks_change_names_the_threads_only_when_there_are_two(threads):
    # A post_solve callback halving a ball's velocity (a change inside the step, on any
    # space): with two threads the reason names them as well as the callbacks.
    space = pymunk.Space(threaded=True)
    space.threads = threads
    space.gravity = (0, -900)
    space.add(pymunk.Segment(space.static_body, (-100, 0), (100, 0), 5))
    ball = pymunk.Body(1, 100)
    ball.position, ball.velocity = (0, 30), (20, -100)
    shape = pymunk.Circle(ball, 10)
    shape.elasticity = 0.5
    space.add(ball, shape)

    def post_solve(arbiter, space, data):
        ball.velocity = ball.velocity * 0.5

    space.on_collision(None, None, post_solve=post_solve)
    bal = _run(space, 60)
    assert bal.complete is False
    why = dict(bal.unaccounted)["ball" if "ball" in dict(bal.unaccounted) else "body 0"]
    assert "a collision's post_solve" in why
    assert ("space.threads = 2" in why) is (threads == 2), why


@pytest.mark.parametrize("threaded, threads, row", [
    (False, 1, None),
    (True, 1, (1.0, True)),
    (True, 2, (2.0, False)),
])
def test_the_guard_has_a_threads_row_for_a_threaded_space(threaded, threads, row):
    space = _pile(threaded, threads)
    rows = [f for f, _ in spaces.survey(space, 1 / 120) if f.kind == "threads"]
    if row is None:
        assert rows == []
        return
    (f,) = rows
    assert (f.value, f.ok) == row
    assert (f.subject, f.limit, f.relation, f.dt_max) == ("space.threads", 1.0, "<=", None)
    assert "space.threads = 1" in f.fix
    space.collision_bias = 1.0  # the pile's one other setting to fix
    text = spaces.report(space, 1 / 120)
    assert ("FAIL threads" in text) is (threads == 2)
    assert text.splitlines()[-1].strip() == ("the step is fine; the failures are settings"
                                             if threads == 2 else "nothing to fix")
    assert spaces.suggest_dt(space, 1 / 120) == 1 / 120  # no step fixes a setting
