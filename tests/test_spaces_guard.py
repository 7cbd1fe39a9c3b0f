"""spaces.check / suggest_dt / Driver: the step-size guard on hand-built spaces and the 100 m
drop."""

from __future__ import annotations

import itertools
import math

import pymunk
import pytest

from dumbbell import spaces
from dumbbell.model.scene import load_scene, scenes_dir
from dumbbell.solvers import simulate
from dumbbell.solvers.engine import FLOOR_THICKNESS, build


def _pair(mA: float, mB: float, k: float, static_b: bool = False) -> pymunk.Space:
    space = pymunk.Space()
    a = pymunk.Body(mA, math.inf)
    a.position = (0.0, 0.0)
    if static_b:
        b = space.static_body
    else:
        b = pymunk.Body(mB, math.inf)
        b.position = (1.0, 0.0)
        space.add(b)
    space.add(a, pymunk.DampedSpring(a, b, (0, 0), (0, 0), 1.0, k, 0.0))
    return space


@pytest.mark.parametrize("mA, mB, static_b", [(0.1, 0.1, False), (1.0, 3.0, False),
                                              (2.0, 0.0, True)])
def test_spring_flagged_at_2_1_cleared_at_1_9(mA, mB, static_b):
    k = 200.0
    space = _pair(mA, mB, k, static_b)
    mu = mA if static_b else mA * mB / (mA + mB)
    w = math.sqrt(k / mu)
    found = spaces.check(space, 2.1 / w)
    assert [(f.kind, f.subject) for f in found] == [("spring", "DampedSpring 0")]
    assert found[0].value == pytest.approx(2.1, rel=1e-12) and found[0].limit == 2.0
    assert spaces.check(space, 1.9 / w) == []
    dt = spaces.suggest_dt(space, 2.1 / w)
    assert dt == pytest.approx(2.1 / w / 2) and spaces.check(space, dt) == []


def test_rotary_spring_uses_both_moments():
    space = pymunk.Space()
    a, b = pymunk.Body(1.0, 0.2), pymunk.Body(1.0, 0.6)
    space.add(a, b, pymunk.DampedRotarySpring(a, b, 0.0, 5.0, 0.0))
    w = math.sqrt(5.0 * (1 / 0.2 + 1 / 0.6))
    assert [f.kind for f in spaces.check(space, 2.05 / w)] == ["rotary-spring"]
    assert spaces.check(space, 1.95 / w) == []


def test_spring_really_blows_up_past_the_limit():
    # The guard's limit is pymunk's: past w*dt = 2 the spring's energy grows without bound.
    k, m = 200.0, 0.1
    w = math.sqrt(k / (m / 2))
    grown = {}
    for wdt in (1.9, 2.1):
        space = _pair(m, m, k)
        next(iter(space.bodies)).position = (1.05, 0.0)  # stretched by 5 cm
        e0 = spaces.energy(space).E
        spaces.step(space, 300 * wdt / w, substeps=300)
        grown[wdt] = spaces.energy(space).E / e0
    assert grown[1.9] < 20 and grown[2.1] > 1e6


def test_high_drop_tunnels_and_the_suggested_dt_does_not():
    scene = load_scene(scenes_dir() / "extreme" / "high-drop.toml")
    space = build(scene).space
    found = spaces.check(space, 0.025)
    assert {f.kind for f in found} == {"tunnelling"}
    assert {f.subject for f in found} == {"body 0", "body 1"}
    dt = spaces.suggest_dt(space, 0.025)
    n = round(0.025 / dt)
    assert n > 1 and 0.025 / n == dt
    assert spaces.check(space, dt) == []
    # ... and the run: at 0.025 s pymunk lets the dumbbell through; at the guard's dt it
    # bounces (the same scene through the project's solver, and the space sub-stepped).
    assert simulate(scene, "pymunk", dt=0.025).verdict.status == "tunnelled"
    assert simulate(scene, "pymunk", dt=dt).verdict.ok
    driver = spaces.Driver(space, 0.025)
    assert driver.substeps == n
    lowest = math.inf
    while driver.t < 6.0:
        driver.step()
        lowest = min(lowest, *(b.position.y for b in space.bodies))
    # Never past the floor box's middle (from where a contact would push it on through).
    assert lowest > -scene.system.A.radius - 0.5 * FLOOR_THICKNESS
    assert max(b.position.y for b in space.bodies) > 50.0  # it bounced back up


def test_pixel_defaults_in_an_si_space_are_flagged():
    space = pymunk.Space()
    ball = pymunk.Body(0.1, pymunk.moment_for_circle(0.1, 0, 0.02))
    circle = pymunk.Circle(ball, 0.02)
    circle.elasticity = 1.0
    floor = pymunk.Segment(space.static_body, (-1, 0), (1, 0), 0.01)
    floor.elasticity = 1.0
    space.add(ball, circle, floor)
    kinds = {f.kind: f for f in spaces.check(space, 1e-3)}
    assert set(kinds) == {"slop", "bias"}
    assert kinds["slop"].limit == pytest.approx(0.1 * 0.02) and kinds["slop"].dt_max is None
    space.collision_slop = 1e-4
    space.collision_bias = 1.0
    assert spaces.check(space, 1e-3) == []
    assert spaces.suggest_dt(space, 1e-3) == 1e-3


def test_bad_dt_is_one_clear_error():
    from dumbbell.errors import UsageError

    with pytest.raises(UsageError, match="dt = -1"):
        spaces.check(pymunk.Space(), -1)


def test_a_row_of_springs_is_faster_than_each_spring():
    # Three equal masses in a row, two springs: the fastest mode is sqrt(3 k/m), each spring
    # alone says sqrt(2 k/m). At sqrt(2 k/m) dt = 1.8 every spring passes, yet pymunk blows up.
    k, m = 100.0, 0.5
    dt = 1.8 / math.sqrt(2 * k / m)
    assert math.sqrt(3 * k / m) * dt > 2

    def row() -> pymunk.Space:
        space = pymunk.Space()
        bodies = []
        for i in range(3):
            b = pymunk.Body(m, math.inf)
            b.position = (float(i), 0.0)
            bodies.append(b)
            space.add(b)
        for a, b in itertools.pairwise(bodies):
            space.add(pymunk.DampedSpring(a, b, (0, 0), (0, 0), 1.0, k, 0.0))
        bodies[0].position = (-0.05, 0.0)
        return space

    found = spaces.check(row(), dt)
    assert [(f.kind, f.subject) for f in found] == [("spring-network", "body 1")]
    space = row()
    e0 = spaces.energy(space).E
    spaces.step(space, 300 * dt, substeps=300)
    assert spaces.energy(space).E > 1e6 * e0  # really unstable
    space = row()
    h = spaces.suggest_dt(space, dt)
    assert spaces.check(space, h) == []
    spaces.step(space, 300 * h, substeps=300)
    assert spaces.energy(space).E < 2 * e0


def test_a_fast_kinematic_paddle_counts_as_the_closing_speed():
    # A ball at rest, no gravity; a thin kinematic paddle sweeps at it at 20 m/s.
    space = pymunk.Space()
    space.collision_slop = 1e-4
    ball = pymunk.Body(0.1, math.inf)
    ball.position = (0.0, 0.0)
    space.add(ball, pymunk.Circle(ball, 0.02))
    paddle = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    paddle.position, paddle.velocity = (-1.0, 0.0), (20.0, 0.0)
    space.add(paddle, pymunk.Segment(paddle, (0, -0.5), (0, 0.5), 0.005))
    limit = 0.005 + 0.02
    found = spaces.check(space, 1.1 * limit / 20.0)
    assert [(f.kind, f.subject) for f in found] == [("tunnelling", "body 0")]
    assert found[0].value == pytest.approx(1.1 * limit, rel=1e-12)
    assert spaces.check(space, 0.9 * limit / 20.0) == []
