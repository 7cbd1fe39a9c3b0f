"""dumbbell.spaces on a fifth round of programs written as outside pymunk programs are (issue
28's cases, varied): each defect found there, against an independent measurement through
pymunk's public API."""

from __future__ import annotations

import math
import warnings

import pymunk
import pytest

from dumbbell import spaces


def _kinetic(body: pymunk.Body) -> float:
    return (0.5 * body.mass * body.velocity.length_squared
            + 0.5 * body.moment * body.angular_velocity ** 2)


def _energy(space: pymunk.Space) -> float:
    """Kinetic, gravitational and the default springs' energy, from pymunk's getters."""
    gx, gy = space.gravity
    out = []
    for b in space.bodies:
        if b.body_type == pymunk.Body.DYNAMIC:
            p = b.local_to_world(b.center_of_gravity)
            out.append(_kinetic(b) - b.mass * (gx * p[0] + gy * p[1]))
    for c in space.constraints:
        if isinstance(c, pymunk.DampedSpring):
            d = (c.a.local_to_world(c.anchor_a) - c.b.local_to_world(c.anchor_b)).length
            out.append(0.5 * c.stiffness * (d - c.rest_length) ** 2)
    return math.fsum(out)


def _sum(bal: spaces.Balance, kind: str) -> float:
    return math.fsum(t.energy for t in bal.terms if t.kind == kind)


@pytest.mark.parametrize("event, public", [("begin", False), ("pre_solve", False),
                                           ("separate", False), ("begin", True),
                                           ("pre_solve", True)])
def test_a_velocity_set_by_a_callback_before_the_solver_is_booked_as_it_changed_energy(
        event, public):
    # Balls dropping on an elastic floor, a handler halving (typed) or kicking (wildcard)
    # the ball it touches. These callbacks run after pymunk moved the bodies with the
    # velocity the last step left: the program term is the kinetic energy the callback
    # changed, not that plus a teleport inferred from the new velocity (before round 5
    # it was 2-10 % off, the difference hidden in gravity's step error). The same with the
    # public API ledger (the fallback), where a ball added from a callback also made every
    # ball touching the floor look moved by the program (what touched was forgotten when
    # the space changed).
    from dumbbell.spaces.ledger import PublicLedger

    space = pymunk.Space()
    space.gravity = (0, -900)
    floor = pymunk.Segment(space.static_body, (-500, 0), (500, 0), 5)
    floor.collision_type, floor.elasticity = 2, 0.8
    space.add(floor)
    for i in range(3):
        b = pymunk.Body(1 + i, 100 * (1 + i))
        b.position, b.velocity = (-300 + 150 * i, 30 + 20 * i), (10 * i, -200)
        c = pymunk.Circle(b, 20)
        c.collision_type, c.elasticity, c.friction = 1, 0.9, 0.5
        space.add(b, c)
    ledger = (PublicLedger if public else spaces.Ledger)(space)
    measured, entered = [0.0], []

    def halve(arbiter, space, data):
        for s in arbiter.shapes:
            if s.body is not None and s.body.body_type == pymunk.Body.DYNAMIC:
                e = _kinetic(s.body)
                s.body.velocity *= 0.5
                s.body.angular_velocity *= 0.5
                measured[0] += _kinetic(s.body) - e

    def kick(arbiter, space, data):
        for s in arbiter.shapes:
            if s.body is not None and s.body.body_type == pymunk.Body.DYNAMIC:
                e = _kinetic(s.body)
                s.body.apply_impulse_at_local_point((30, 40), (5, 0))
                measured[0] += _kinetic(s.body) - e
        if len(space.bodies) < 6:  # a ball dropped in from the callback: 'entered'
            extra = pymunk.Body(2, 50)
            extra.position, extra.velocity = (400, 300), (0, 10)
            space.add(extra, pymunk.Circle(extra, 5))
            entered.append(_kinetic(extra) - 2 * space.gravity[1] * 300)

    space.on_collision(1, 2, **{event: halve})
    space.on_collision(None, None, **{event: kick})
    E0 = _energy(space)
    for _ in range(120):
        space.step(1 / 120)
    bal = ledger.balance()
    assert measured[0] != 0.0
    assert abs(_sum(bal, "program") - measured[0]) <= 1e-9 * bal.scale
    assert entered and abs(_sum(bal, "entered") - math.fsum(entered)) <= 1e-9 * bal.scale
    assert abs((_energy(space) - E0) - (bal.E - bal.E0)) <= 1e-9 * bal.scale
    assert abs(bal.closure) <= 1e-12 * bal.scale and bal.complete is False


def _boxes_and_a_kinematic(cog_after_position: bool = False) -> pymunk.Space:
    space = pymunk.Space()
    space.gravity = (0, -9.81)
    space.add(pymunk.Segment(space.static_body, (-50, 0), (50, 0), 0.1))
    boxes = []
    for i in range(3):
        b = pymunk.Body(1 + i, 0.1 * (1 + i))
        if not cog_after_position:
            b.center_of_gravity = (0.1, -0.05 * i)
        b.position, b.velocity = (-3 + 3 * i, 1 + i), (i, -2)
        if cog_after_position:
            b.center_of_gravity = (0.1, -0.05 * i)
        space.add(b, pymunk.Poly.create_box(b, (0.5, 0.3)))
        boxes.append(b)
    k = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    k.position, k.velocity = (10, 0.5), (-1, 0)
    space.add(k, pymunk.Circle(k, 0.3))
    space.add(pymunk.DampedSpring(boxes[0], boxes[1], (0, 0), (0, 0), 2.5, 30, 0.2))
    return space


def _booked_to_the_callbacks(space, ledger, measured: list[float]) -> spaces.Balance:
    """Step ``space`` 120 times at 1/120 s: what its callbacks changed, measured by hand
    (``measured[0]``, not zero), is the ledger's ``unattributed``, and nothing is booked as
    the program's. Returns the balance."""
    for _ in range(120):
        space.step(1 / 120)
    bal = ledger.balance()
    assert measured and measured[0] != 0.0
    assert not [t for t in bal.terms if t.kind == "program"]
    assert abs(_sum(bal, "unattributed") - measured[0]) <= 1e-9 * bal.scale
    return bal


def _counts_a_second(space, ledger, E_hand: float, E_ledger: float) -> None:
    """Step ``space`` 60 times at 1/60: the ledger closes to rounding and its change of E
    from ``E_ledger`` is the hand computation's from ``E_hand``."""
    for _ in range(60):
        space.step(1 / 60)
    bal = ledger.balance()
    assert bal.complete is True and abs(bal.closure) <= 1e-12 * bal.scale
    assert abs((_energy(space) - E_hand) - (bal.E - E_ledger)) <= 1e-9 * bal.scale


def test_the_public_api_ledger_counts_a_space_with_a_kinematic_body():
    # The fallback ledger took the springs' kicks out of every row with the dynamic rows'
    # inverse masses: with a kinematic body it stopped at step 0 (a numpy broadcast error).
    from dumbbell.spaces.ledger import PublicLedger

    space = _boxes_and_a_kinematic()
    ledger = PublicLedger(space, units="m")
    _counts_a_second(space, ledger, _energy(space), ledger.balance().E0)


def test_a_centre_of_gravity_set_after_the_position_keeps_the_full_ledger():
    # Chipmunk keeps p (the centre of gravity's world position) when center_of_gravity is
    # set; until the next step pymunk's transform still puts the old centre there. The
    # ledger's check of its reads compared p with the transform's, refused the space and
    # fell back to the public API ledger (which then stopped: the test above).
    space = _boxes_and_a_kinematic(cog_after_position=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ledger = spaces.Ledger(space, units="m")
    assert type(ledger) is spaces.Ledger
    space.step(1 / 60)
    # The transform follows p after a step: the hand computation from there.
    _counts_a_second(space, ledger, _energy(space), ledger.balance().E)


def test_a_kind_the_ledger_never_writes_is_refused_by_sources():
    # sources(kind="contacts") (a misspelt kind) gave [] as if nothing had happened.
    from dumbbell.errors import UsageError
    from dumbbell.spaces.balance import KINDS

    space = pymunk.Space()
    space.gravity = (0, -9.81)
    ball = pymunk.Body(1, 1)
    space.add(ball, pymunk.Circle(ball, 0.1))
    ledger = spaces.Ledger(space)
    space.step(0.01)
    bal = ledger.balance()
    assert {t.kind for t in bal.terms} <= set(KINDS)
    assert [t.kind for t in bal.sources("step error")] == ["step error"]
    for bad in ("contacts", 5):
        with pytest.raises(UsageError, match=r"^kind = .*: must be None \(every kind\) or one of"):
            bal.sources(kind=bad)


@pytest.mark.parametrize("change", ["add a dense shape", "remove a dense shape", "set a mass"])
def test_a_mass_changed_from_a_callback_is_the_callbacks_not_the_programs(change):
    # A post-step callback (asked for from a collision's begin) adding or removing a shape
    # with a density, or setting a mass: the change came from inside the step, so all of
    # it is 'unattributed' (a callback). Before round 5 the mass's part was booked as the
    # program's ('program: a mass, ...') at the next step, the move of the centre of
    # gravity as the callback's.
    space = pymunk.Space()
    space.gravity = (0, -900)
    space.add(pymunk.Segment(space.static_body, (-300, 0), (300, 0), 5))
    a = pymunk.Body()
    a.position, a.velocity, a.angular_velocity = (0, 100), (30, -50), 2
    disc, wedge = pymunk.Circle(a, 10), pymunk.Poly(a, [(0, 0), (-20, 0), (-20, -8)])
    disc.density, wedge.density = 0.01, 0.03
    b = pymunk.Body(1, 100)
    b.position, b.velocity = (80, 150), (0, -100)
    space.add(a, disc, wedge, b, pymunk.Poly.create_box(b, (20, 20)), pymunk.PinJoint(a, b))
    ledger = spaces.Ledger(space)
    measured, asked = [0.0], []

    def act(space, key):
        e = _energy(space)
        if change == "add a dense shape":
            extra = pymunk.Poly(a, [(0, 0), (30, 0), (30, 10)])
            extra.density = 0.02
            space.add(extra)
        elif change == "remove a dense shape":
            space.remove(wedge)
        else:
            b.mass = 3.0
        measured[0] += _energy(space) - e

    def begin(arbiter, space, data):
        if not asked:
            asked.append(space.add_post_step_callback(act, "act"))
        return True

    space.on_collision(None, None, begin=begin)
    E0 = _energy(space)
    bal = _booked_to_the_callbacks(space, ledger, measured)
    assert asked
    assert abs((_energy(space) - E0) - (bal.E - bal.E0)) <= 1e-9 * bal.scale


@pytest.mark.parametrize("change", ["gravity", "stiffness", "rest_length"])
def test_gravity_or_a_spring_set_from_a_post_solve_callback_is_the_callbacks(change):
    # Booked as 'program: space.gravity' (or a spring's settings) at the next step before.
    space = pymunk.Space()
    space.gravity = (0, -900)
    space.add(pymunk.Segment(space.static_body, (-300, 0), (300, 0), 5))
    ball = pymunk.Body(1, 100)
    ball.position, ball.velocity = (0, 40), (0, -300)
    spring = pymunk.DampedSpring(space.static_body, ball, (0, 200), (0, 0), 180, 30, 0.1)
    space.add(ball, pymunk.Circle(ball, 10), spring)
    ledger = spaces.Ledger(space)
    measured = []

    def post_solve(arbiter, space, data):
        if not measured:
            e = _energy(space)
            if change == "gravity":
                space.gravity = (0, -500)
            else:
                setattr(spring, change, 80 if change == "stiffness" else 20)
            measured.append(_energy(space) - e)

    space.on_collision(None, None, post_solve=post_solve)
    _booked_to_the_callbacks(space, ledger, measured)
