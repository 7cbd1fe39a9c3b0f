"""The ledger's shortcuts at every step, against the long way round:

- whether ``space.bodies`` still holds the bodies it knows is read, while no body sleeps,
  from Chipmunk's arrays of awake and static bodies and ``len(space.bodies)``, not a tuple
  of every body: bodies that leave or come without changing the awake array (a lone
  sleeping body removed, another put to sleep in the same gap, a body swapped inside a
  sleeping pile, a static body swapped for another) are still found, with their energy
  measured by hand;
- the end of a step checks only whether bodies and constraints came or went when nothing
  can change a body after the solver (no constraint ``post_solve``, no collision handler,
  no post-step callback before the ledger's, no add or remove pymunk deferred to the
  step's end); a post-step callback or a constraint's ``post_solve`` that changes a
  velocity, and a shape removed from a ``position_func`` or a ``pre_solve`` (its body's
  mass changes at the step's end) are still measured and named as the step's, and a space
  where those reads are not known gives the same balance bit for bit;
- a plain step (only gravity, the contacts and the program act; every body awake, no
  force, no damping) counts gravity and what no source explains in one pass: the same
  terms as the general one, to the last bits, and gravity's step error is 1/2 dt g . dP."""

from __future__ import annotations

import pymunk
import pytest

from dumbbell import spaces
from dumbbell.spaces import _inventory, _layout

from .ledger_measure import body_energy, terms_of


def _box(space: pymunk.Space, x: float, y: float = 0.5, m: float = 2.0) -> pymunk.Body:
    """A 1 x 1 box of ``m`` kg centred at (x, y)."""
    body = pymunk.Body(m, pymunk.moment_for_box(m, (1, 1)))
    body.position = (x, y)
    shape = pymunk.Poly.create_box(body, (1, 1))
    shape.friction = 1.0
    space.add(body, shape)
    return body


def _floored(sleep_time: float) -> pymunk.Space:
    """A space with g = 10 down, a floor at height 0, and bodies put to sleep after
    ``sleep_time`` s at rest."""
    space = pymunk.Space()
    space.gravity = (0.0, -10.0)
    space.sleep_time_threshold = sleep_time
    floor = pymunk.Segment(space.static_body, (-50, 0), (50, 0), 0.0)
    floor.friction = 1.0
    space.add(floor)
    return space


def _sleepy_space() -> tuple[pymunk.Space, list[pymunk.Body]]:
    space = _floored(0.05)
    return space, [_box(space, x) for x in (-10.0, 0.0, 10.0)]


def test_a_lone_sleeping_body_removed_leaves_with_its_energy():
    # Three boxes at rest fall asleep alone (each its own component): none is in the awake
    # array. Removing one changes neither the awake nor the static array; the sleeping
    # components and len(space.bodies) tell.
    space, boxes = _sleepy_space()
    ledger = spaces.Ledger(space)
    for _ in range(120):
        space.step(1 / 60)
    assert all(b.is_sleeping for b in boxes)
    g = space.gravity
    gone = body_energy(boxes[1], g)
    space.remove(boxes[1], *boxes[1].shapes)
    space.step(1 / 60)
    bal = ledger.balance()
    assert terms_of(bal, "left") == {"body 1": pytest.approx(-gone, rel=1e-15)}
    # -m g.y of a box at rest, its centre 0.5 up (less the contact's slop)
    assert gone == pytest.approx(-2.0 * -10.0 * 0.5, rel=2e-3)


def test_a_sleeping_body_removed_and_another_put_to_sleep_in_one_gap_are_both_found():
    # The awake array reads the same before and after: the one removed was asleep, the one
    # added is put to sleep at once. The sleeping components differ (another root).
    space, boxes = _sleepy_space()
    ledger = spaces.Ledger(space)
    for _ in range(120):
        space.step(1 / 60)
    g = space.gravity
    gone = body_energy(boxes[2], g)
    space.remove(boxes[2], *boxes[2].shapes)
    new = _box(space, 20.0)
    new.sleep()
    came = body_energy(new, g)
    space.step(1 / 60)
    bal = ledger.balance()
    assert terms_of(bal, "left") == {"body 2": pytest.approx(-gone, rel=1e-15)}
    assert terms_of(bal, "entered") == {"body 3": pytest.approx(came, rel=1e-15)}
    assert bal.complete, bal.unaccounted


def test_a_static_body_swapped_in_one_gap_is_a_change_of_bodies():
    # One static body removed and another added: len(space.bodies) and the awake array stay;
    # the static array does not.
    space = pymunk.Space()
    old = pymunk.Body(body_type=pymunk.Body.STATIC)
    ball = pymunk.Body(1, 1)
    space.add(old, ball, pymunk.Circle(ball, 1))
    ledger = spaces.Ledger(space)
    space.step(0.01)
    new = pymunk.Body(body_type=pymunk.Body.STATIC)
    space.remove(old)
    space.add(new)
    t = ledger._b.table
    F, P = t.pre.both()
    assert _inventory.changed(ledger._b, space, F, P) == "bodies added or removed"
    space.step(0.01)
    assert new in ledger._b.table.body_key and old not in ledger._b.table.body_key
    assert ledger.balance().complete


def test_a_body_removed_and_added_again_in_one_gap_changes_nothing():
    space, boxes = _sleepy_space()
    space.sleep_time_threshold = float("inf")
    ledger = spaces.Ledger(space)
    for _ in range(30):
        space.step(1 / 60)
    space.remove(boxes[0], *boxes[0].shapes)
    space.add(boxes[0], *boxes[0].shapes)
    for _ in range(30):
        space.step(1 / 60)
    bal = ledger.balance()
    assert "left" not in bal.by_kind() and "entered" not in bal.by_kind()
    assert bal.complete, bal.unaccounted


def test_pymunks_callback_dicts_are_where_the_ledger_reads_them():
    assert _layout.callbacks_known() is True


def _ball_space() -> tuple[pymunk.Space, pymunk.Body]:
    space = pymunk.Space()
    space.gravity = (0.0, -10.0)
    floor = pymunk.Segment(space.static_body, (-50, 0), (50, 0), 0.1)
    floor.elasticity = 1.0
    ball = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.5))
    ball.position, ball.velocity = (0.0, 2.0), (1.0, 0.0)
    shape = pymunk.Circle(ball, 0.5)
    shape.elasticity = 1.0
    space.add(ball, shape)
    return space, ball


def test_a_post_step_callback_set_between_steps_is_measured_inside_the_step():
    # Registered by the program between steps, pymunk runs it after the solver of the next
    # step, before the ledger's end of it: its change is the step's, unattributed.
    space, ball = _ball_space()
    ledger = spaces.Ledger(space)
    changed = [0.0]

    def slow(space_, key):
        before = body_energy(ball, space_.gravity)
        ball.velocity *= 0.5
        changed[0] += body_energy(ball, space_.gravity) - before

    for i in range(120):
        if i % 10 == 3:
            space.add_post_step_callback(slow, i)
        space.step(1 / 60)
    bal = ledger.balance()
    assert changed[0] < 0
    assert terms_of(bal, "unattributed") == {"body 0": pytest.approx(changed[0], rel=1e-12)}
    assert "program" not in bal.by_kind()


def test_a_constraint_post_solve_is_measured_inside_the_step():
    space, ball = _ball_space()
    anchor = pymunk.Body(1.0, 1.0)
    anchor.position = (5.0, 5.0)
    joint = pymunk.SlideJoint(anchor, ball, (0, 0), (0, 0), 0.0, 100.0)
    space.add(anchor, joint)
    ledger = spaces.Ledger(space)
    changed = [0.0]

    def slow(constraint, space_):
        before = body_energy(ball, space_.gravity)
        ball.angular_velocity += 0.25
        changed[0] += body_energy(ball, space_.gravity) - before

    for i in range(120):
        joint.post_solve = slow if i % 10 == 3 else None
        space.step(1 / 60)
    bal = ledger.balance()
    assert changed[0] > 0
    assert terms_of(bal, "unattributed") == {"body 0": pytest.approx(changed[0], rel=1e-12)}


def test_the_short_end_of_step_gives_the_balance_of_the_long_one(monkeypatch):
    # A pile of boxes knocked by a ball, bodies removed and added between steps: once with
    # the short end of step, once with every body read at every step's end.
    def run() -> tuple:
        space, boxes = _sleepy_space()
        space.sleep_time_threshold = float("inf")
        for i in range(5):
            _box(space, 0.0, 1.5 + i)
        ledger = spaces.Ledger(space)
        for i in range(200):
            if i == 50:
                space.remove(boxes[0], *boxes[0].shapes)
            if i == 90:
                _box(space, -20.0, 3.0).velocity = (4.0, 1.0)
            space.step(1 / 60)
        bal = ledger.balance()
        return bal.E, bal.closure, bal.terms, bal.complete

    short = run()
    monkeypatch.setattr(_layout, "callbacks_known", lambda: False)
    assert run() == short
    assert short[3] is True


def _pile_run(steps: int = 240, kick: bool = False) -> tuple[spaces.Balance, float]:
    """Balls thrown onto a floor and onto each other (contacts, bounces, friction, a
    program's kick between steps); the balance and the sum of dt/2 g . (P1 - P0) over the
    steps, from pymunk's getters."""
    g = (0.0, -9.81)
    space = pymunk.Space()
    space.gravity = g
    floor = pymunk.Segment(space.static_body, (-20, 0), (20, 0), 0.1)
    floor.friction, floor.elasticity = 0.6, 0.5
    space.add(floor)
    balls = []
    for i in range(12):
        b = pymunk.Body(1.0 + 0.1 * i, pymunk.moment_for_circle(1.0 + 0.1 * i, 0, 0.4))
        b.position, b.velocity = (-3.0 + 0.55 * i, 1.0 + 0.9 * i), (0.3 * (i % 3 - 1), 0.0)
        shape = pymunk.Circle(b, 0.4)
        shape.friction, shape.elasticity = 0.6, 0.5
        space.add(b, shape)
        balls.append(b)
    ledger = spaces.Ledger(space)
    dt = 1 / 120
    error = 0.0
    for i in range(steps):
        if kick and i == steps // 2:
            balls[3].velocity += (2.0, 1.0)
        p0 = sum((b.mass * b.velocity for b in balls), pymunk.Vec2d(0, 0))
        space.step(dt)
        p1 = sum((b.mass * b.velocity for b in balls), pymunk.Vec2d(0, 0))
        error += 0.5 * dt * (g[0] * (p1.x - p0.x) + g[1] * (p1.y - p0.y))
    return ledger.balance(), error


@pytest.mark.parametrize("kick", [False, True])
def test_a_plain_step_gives_the_terms_of_the_general_one(monkeypatch, kick):
    from dumbbell.spaces._inventory import Build

    short, error = _pile_run(kick=kick)
    assert terms_of(short, "step error")["gravity"] == pytest.approx(error, rel=1e-9, abs=1e-12)
    monkeypatch.setattr(Build, "plain", property(lambda self: False))
    long, _ = _pile_run(kick=kick)
    assert short.E == long.E and short.complete is long.complete is (not kick)
    assert {(t.source, t.kind) for t in short.terms} == {(t.source, t.kind) for t in long.terms}
    def key(t):
        return (t.source, t.kind)

    for a, b in zip(sorted(short.terms, key=key), sorted(long.terms, key=key), strict=True):
        assert a.energy == pytest.approx(b.energy, rel=0, abs=1e-13 * short.scale), a.source
    assert abs(short.closure) <= 1e-12 * short.scale


def test_a_body_swapped_inside_a_sleeping_pile_is_found():
    # A game replaces the top box of a pile that sleeps as one component: only the pile's
    # root is in Chipmunk's arrays, and the pile falls asleep again inside the next step
    # (sleep_time_threshold below dt), so the arrays and the number of bodies read as before
    # the swap. 30 J leave with the 2 kg box at 1.5 m, 300 J come with the 20 kg one.
    space = _floored(0.01)
    _box(space, 0.0, 0.5)
    top = _box(space, 0.0, 1.5)
    ledger = spaces.Ledger(space)
    for _ in range(200):
        space.step(1 / 60)
    assert top.is_sleeping
    g = space.gravity
    gone = body_energy(top, g)
    space.remove(top, *top.shapes)
    heavy = _box(space, 0.0, 1.5, m=20.0)
    heavy.position = top.position
    came = body_energy(heavy, g)
    for _ in range(3):
        space.step(1 / 60)
    bal = ledger.balance()
    assert bal.E == pytest.approx(spaces.energy(space).E, rel=1e-12)
    assert terms_of(bal, "left") == {"body 1": pytest.approx(-gone, rel=1e-12)}
    assert terms_of(bal, "entered") == {"body 2": pytest.approx(came, rel=1e-12)}
    assert gone == pytest.approx(30.0, rel=1e-3) and came == pytest.approx(300.0, rel=1e-3)


def test_a_body_swapped_in_a_component_put_to_sleep_by_hand_is_found():
    space = pymunk.Space()
    space.sleep_time_threshold = 1.0
    a, d = pymunk.Body(1, 1), pymunk.Body(1, 1)
    space.add(a, d)
    ledger = spaces.Ledger(space)
    a.sleep()
    d.sleep_with_group(a)
    space.step(0.01)
    space.remove(d)
    c = pymunk.Body(1, 1)
    c.velocity = (10, 0)  # 50 J
    space.add(c)
    a.sleep()
    c.sleep_with_group(a)
    space.step(0.01)
    bal = ledger.balance()
    assert bal.E == spaces.energy(space).E == 50.0
    assert terms_of(bal, "entered") == {"body 2": 50.0}


@pytest.mark.parametrize("how", ["position_func", "pre_solve"])
def test_a_shape_removed_inside_the_step_is_the_steps_change(how):
    # pymunk defers a remove asked for inside the step to its end, after the solver: the
    # ball's mass changes there (its shapes give it), which is the step's (unattributed),
    # not the program's between steps. By hand: the ball's energy after that step, less a
    # twin's that kept its 2 kg part (the same motion until the step's end).
    def run(remove: bool) -> tuple[pymunk.Space, pymunk.Body, spaces.Ledger]:
        space = pymunk.Space()
        space.gravity = (0, -10)
        ball = pymunk.Body()
        ball.position, ball.velocity = (0, 5), (3, 0)
        core = pymunk.Circle(ball, 0.5)
        core.mass = 1.0
        extra = pymunk.Circle(ball, 0.3, (0.6, 0))
        extra.mass = 2.0
        space.add(ball, core, extra)
        ledger = spaces.Ledger(space)

        def drop() -> None:
            if remove and ledger.steps == 5 and extra in space.shapes:
                space.remove(extra)

        if how == "position_func":
            def move(body, dt):
                pymunk.Body.update_position(body, dt)
                drop()

            ball.position_func = move
        else:
            anchor = pymunk.Body(body_type=pymunk.Body.STATIC)
            joint = pymunk.SlideJoint(anchor, ball, (0, 0), (0, 0), 0.0, 1e6)
            joint.pre_solve = lambda c, s: drop()
            space.add(anchor, joint)
        for _ in range(6):
            space.step(0.01)
        assert (extra in space.shapes) is not remove
        return space, ball, ledger

    space, ball, ledger = run(True)
    _, twin, _ = run(False)
    changed = body_energy(ball, space.gravity) - body_energy(twin, space.gravity)
    bal = ledger.balance()
    assert bal.E == pytest.approx(spaces.energy(space).E, rel=1e-12)
    inside = {s: e for s, e in terms_of(bal, "unattributed").items() if "inside the step" in s}
    assert inside == {"a mass, moment, centre of gravity or body type inside the step "
                      "(a callback)": pytest.approx(changed, rel=1e-12)}
    assert changed < -100
    assert not any("mass" in s for s in terms_of(bal, "program"))
    assert not bal.complete
