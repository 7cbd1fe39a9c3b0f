"""spaces.check / suggest_dt / Driver / reach: the step-size guard on hand-built spaces and the
100 m drop, against closed forms and runs of the same spaces."""

from __future__ import annotations

import itertools
import math
import re

import pymunk
import pytest

from dumbbell import spaces
from dumbbell.errors import DumbbellError, UsageError
from dumbbell.model.scene import load_scene, scenes_dir
from dumbbell.solvers import simulate
from dumbbell.solvers.engine import FLOOR_THICKNESS, build

from .guard_cases import PUSHES, car, pushed

STABILITY = math.inf  # tolerance: stability only


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


def _energies(space: pymunk.Space, h: float, steps: int) -> list[float]:
    out = []
    for _ in range(steps):
        space.step(h)
        out.append(spaces.energy(space).E)
    return out


# --- springs: stability and the energy swing -------------------------------------------------


@pytest.mark.parametrize("mA, mB, static_b", [(0.1, 0.1, False), (1.0, 3.0, False),
                                              (2.0, 0.0, True)])
def test_spring_flagged_at_2_1_cleared_at_1_9_for_stability(mA, mB, static_b):
    k = 200.0
    space = _pair(mA, mB, k, static_b)
    mu = mA if static_b else mA * mB / (mA + mB)
    w = math.sqrt(k / mu)
    found = spaces.check(space, 2.1 / w, tolerance=STABILITY)
    assert [(f.kind, f.subject) for f in found] == [("spring", "DampedSpring 0")]
    assert found[0].value == pytest.approx(2.1, rel=1e-12) and found[0].limit == 2.0
    assert spaces.check(space, 1.9 / w, tolerance=STABILITY) == []
    dt = spaces.suggest_dt(space, 2.1 / w, tolerance=STABILITY)
    assert dt == pytest.approx(2.1 / w / 2) and spaces.check(space, dt, tolerance=STABILITY) == []


def test_rotary_spring_uses_both_moments():
    space = pymunk.Space()
    a, b = pymunk.Body(1.0, 0.2), pymunk.Body(1.0, 0.6)
    space.add(a, b, pymunk.DampedRotarySpring(a, b, 0.0, 5.0, 0.0))
    w = math.sqrt(5.0 * (1 / 0.2 + 1 / 0.6))
    assert [f.kind for f in spaces.check(space, 2.05 / w, tolerance=STABILITY)] == [
        "rotary-spring"]
    assert spaces.check(space, 1.95 / w, tolerance=STABILITY) == []
    # For a 1 % swing: w dt < 2 (0.01) / 2.01.
    assert spaces.check(space, 0.0099 / w) == []
    assert [f.kind for f in spaces.check(space, 0.0100 / w)] == ["rotary-spring"]


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


@pytest.mark.parametrize("wdt", [0.004, 0.03, 0.2, 0.7, 1.3, 1.8, 1.964])
@pytest.mark.parametrize("masses", [(1.0, 1.0), (0.3, 2.0)])
def test_energy_swing_closed_form_matches_pymunk(wdt, masses):
    # Symplectic Euler keeps H = v^2/2 + w^2 x^2/2 - (w^2 dt/2) x v, so E runs between
    # H / (1 + w dt/2) and H / (1 - w dt/2): from rest (x v = 0, E0 = H) the peak is
    # E0 / (1 - w dt/2), over every start (max E / min E - 1) the swing 2 w dt / (2 - w dt).
    # Measured on pymunk's own spring over two periods or more (the step's rotation angle is
    # not a simple fraction of a turn at these w dt, so the orbit visits every phase), E by
    # hand: 1/2 m v^2 for each body plus 1/2 k (d - rest)^2.
    k, rest = 400.0, 1.0
    mA, mB = masses
    w = math.sqrt(k * (1 / mA + 1 / mB))
    space = pymunk.Space()
    a, b = pymunk.Body(mA, math.inf), pymunk.Body(mB, math.inf)
    a.position, b.position = (0.0, 0.0), (1.01, 0.0)
    spring = pymunk.DampedSpring(a, b, (0, 0), (0, 0), rest, k, 0.0)
    space.add(a, b, spring)
    assert spaces.spring_omega(spring) == pytest.approx(w, rel=1e-12)

    def energy() -> float:
        d = (b.position - a.position).length
        return (0.5 * mA * a.velocity.dot(a.velocity) + 0.5 * mB * b.velocity.dot(b.velocity)
                + 0.5 * k * (d - rest) ** 2)

    e0 = energy()
    es = []
    for _ in range(max(3000, int(2 * 2 * math.pi / wdt))):
        space.step(wdt / w)
        es.append(energy())
    swing = spaces.energy_swing(wdt)
    assert swing == pytest.approx(2 * wdt / (2 - wdt), rel=1e-15)
    assert max(es) / e0 - 1 == pytest.approx(wdt / (2 - wdt), rel=2e-3)
    assert max(es) / min(es) - 1 == pytest.approx(swing, rel=2e-3)


def test_energy_swing_is_unbounded_from_2_and_refuses_nonsense():
    assert spaces.energy_swing(2.0) == math.inf and spaces.energy_swing(0.0) == 0.0
    with pytest.raises(UsageError, match="w_dt"):
        spaces.energy_swing(-0.1)


def _stiff() -> pymunk.Space:
    """Issue 20's case: two 1 kg bodies on DampedSpring(k = 1e6, rest = 1), 1 cm stretched."""
    space = pymunk.Space()
    a, b = pymunk.Body(1.0, math.inf), pymunk.Body(1.0, math.inf)
    a.position, b.position = (0.0, 0.0), (1.01, 0.0)
    space.add(a, b, pymunk.DampedSpring(a, b, (0, 0), (0, 0), 1.0, 1e6, 0.0))
    return space


def _swing(space: pymunk.Space, h: float, periods: float = 3.0) -> float:
    """Largest |E - E0| / E0 over ``periods`` periods of the stiff spring at step ``h``."""
    w = math.sqrt(1e6 / 0.5)
    e0 = spaces.energy(space).E
    es = _energies(space, h, int(periods * 2 * math.pi / w / h) + 1)
    return max(abs(e - e0) for e in es) / e0


def test_the_stiff_spring_gets_a_step_whose_swing_is_under_the_tolerance():
    w = math.sqrt(1e6 / 0.5)
    # The old suggestion, w dt = 1.964: stable, energy up to 56 x E0 (closed form 1/(1-0.982)).
    assert _swing(_stiff(), 1.964 / w, 40) + 1 == pytest.approx(1 / (1 - 0.982), rel=5e-3)
    for tolerance in (0.01, 0.1):
        dt = spaces.suggest_dt(_stiff(), 1 / 60, tolerance=tolerance)
        n = round((1 / 60) / dt)
        assert (1 / 60) / n == dt and spaces.check(_stiff(), dt, tolerance=tolerance) == []
        assert spaces.energy_swing(w * dt) <= tolerance
        assert spaces.energy_swing(w * (1 / 60) / (n - 1)) > tolerance  # the fewest sub-steps
        measured = _swing(_stiff(), dt)
        assert measured <= tolerance and measured > tolerance / 4
    text = spaces.report(_stiff(), 1 / 60)
    assert "the springs' energy swing at it: at most 1 %" in text
    assert "unstable: the energy grows without bound from w dt = 2" in text


def test_bad_tolerance_is_one_clear_error():
    for bad in (0, -1, float("nan"), "1%", None, True):
        with pytest.raises(UsageError, match="tolerance"):
            spaces.check(_stiff(), 1e-3, tolerance=bad)


# --- tunnelling and the reach estimates ------------------------------------------------------


def test_high_drop_tunnels_and_the_suggested_dt_does_not():
    scene = load_scene(scenes_dir() / "extreme" / "high-drop.toml")
    space = build(scene).space
    found = spaces.check(space, 0.025, tolerance=STABILITY)
    assert {f.kind for f in found} == {"tunnelling"}
    assert {f.subject for f in found} == {"body 0", "body 1"}
    # Each particle's own fall (100.2 m for A, to where it meets the floor), not both
    # particles' energy in one: sqrt(2 g h) plus the step's lag g dt / 2 (and a hair more).
    g, dt = scene.system.g, 0.025
    h = 0.5 * g * dt
    exact = h + math.sqrt(h * h + 2 * g * 100.2)
    assert [r.speed for r in spaces.reach(space, dt)] == pytest.approx([exact, exact])
    dt = spaces.suggest_dt(space, 0.025, tolerance=STABILITY)
    n = round(0.025 / dt)
    assert n > 1 and 0.025 / n == dt
    assert spaces.check(space, dt, tolerance=STABILITY) == []
    # ... and the run: at 0.025 s pymunk lets the dumbbell through; at the guard's dt it
    # bounces (the same scene through the project's solver, and the space sub-stepped).
    assert simulate(scene, "pymunk", dt=0.025).verdict.status == "tunnelled"
    # It bounces and reaches its end; the guard checks tunnelling, not the energy error
    # (0.11 at this step: inaccurate, past run.inaccurate_energy = 0.1).
    assert simulate(scene, "pymunk", dt=dt).verdict.complete
    driver = spaces.Driver(space, 0.025, tolerance=STABILITY)
    assert driver.substeps == n
    lowest = math.inf
    peak = 0.0
    while driver.t < 6.0:
        driver.step()
        lowest = min(lowest, *(b.position.y for b in space.bodies))
        if all(b.velocity.y <= 0 for b in space.bodies):  # still on the way down
            peak = max(peak, *(b.velocity.length for b in space.bodies))
    # Never past the floor box's middle (from where a contact would push it on through).
    assert lowest > -scene.system.A.radius - 0.5 * FLOOR_THICKNESS
    assert max(b.position.y for b in space.bodies) > 50.0  # it bounced back up
    # Until the first bounce each particle stays under its estimate. After it the spring can
    # put both particles' energy into one (up to sqrt(2) x): the estimate is not a bound for
    # joined bodies, and says so.
    assert 0.99 * exact < peak <= exact
    assert not any(r.bound for r in spaces.reach(build(scene).space, 0.025))


def _ball(y: float, r: float = 0.5, m: float = 2.0) -> tuple[pymunk.Body, pymunk.Circle]:
    body = pymunk.Body(m, pymunk.moment_for_circle(m, 0, r))
    body.position = (0.0, y)
    return body, pymunk.Circle(body, r)


def test_a_dropped_ball_reaches_its_own_fall_and_no_more():
    # A ball of radius 0.5 at y = 20 over a floor whose top is at y = 0.1 (segment at 0,
    # radius 0.1): it meets it after a fall of 20 - 0.5 - 0.1 = 19.4. Far below, a second floor
    # it cannot reach first: not the lowest static shape anywhere.
    space = pymunk.Space()
    space.gravity = (0.0, -10.0)
    body, shape = _ball(20.0)
    space.add(body, shape, pymunk.Segment(space.static_body, (-5, 0), (5, 0), 0.1),
              pymunk.Segment(space.static_body, (-50, -1000), (50, -1000), 0.1))
    dt = 1e-3
    (r,) = spaces.reach(space, dt)
    h = 0.5 * 10.0 * dt
    assert r.fall == pytest.approx(19.4, rel=1e-12)
    assert r.speed == pytest.approx(h + math.sqrt(h * h + 2 * 10.0 * 19.4), rel=1e-12)
    assert r.bound and not r.point and r.held == ""
    assert r.level == pytest.approx(-(20.0 - 19.4), rel=1e-12)  # depth along g: -y
    peak = 0.0
    for _ in range(3000):
        space.step(dt)
        peak = max(peak, body.velocity.length)
    assert r.speed - 2 * 10.0 * dt < peak <= r.speed


def test_a_ball_slides_down_a_slope_and_falls_to_the_floor_under_its_lower_end():
    # Slope from (-4, 3) down to (4, 1); under its lower end a floor at y = -2 (top -1.9);
    # the ball (r = 0.5, bottom at 9.5) lands on the slope, runs off its low end, falls on.
    space = pymunk.Space()
    space.gravity = (0.0, -10.0)
    body, shape = _ball(10.0)
    slope = pymunk.Segment(space.static_body, (-4, 3), (4, 1), 0.1)
    floor = pymunk.Segment(space.static_body, (3, -2), (12, -2), 0.1)
    space.add(body, shape, slope, floor)
    (r,) = spaces.reach(space, 1e-3)
    assert r.fall == pytest.approx(9.5 - (-1.9), rel=1e-12)
    # A wall at the slope's low end keeps the ball on the slope: the fall stops at its end.
    wall = pymunk.Segment(space.static_body, (4, 1), (4, 6), 0.1)
    space.add(wall)
    (r,) = spaces.reach(space, 1e-3)
    assert r.fall == pytest.approx(9.5 - (1 + 0.1), rel=1e-12)
    peak = 0.0
    for _ in range(4000):
        space.step(1e-3)
        peak = max(peak, body.velocity.length)
    assert peak <= r.speed


def test_a_pendulum_is_held_by_its_pivot():
    # A bar of length L pivoted at one end to the static body, starting level: its centre of
    # gravity can drop L/2, so omega <= sqrt(2 m g (L/2) / I_pivot) and its far end moves at
    # omega (L + radius). A floor far below is out of its reach: no tunnelling row.
    m, L, radius, g = 1.5, 2.0, 0.05, 9.81
    space = pymunk.Space()
    space.gravity = (0.0, -g)
    bar = pymunk.Body(m, pymunk.moment_for_segment(m, (-L / 2, 0), (L / 2, 0), radius))
    bar.position = (L / 2, 0.0)
    seg = pymunk.Segment(bar, (-L / 2, 0), (L / 2, 0), radius)
    pivot = pymunk.PivotJoint(space.static_body, bar, (0.0, 0.0))
    floor = pymunk.Segment(space.static_body, (-10, -5), (10, -5), 0.01)
    space.add(bar, seg, pivot, floor)
    (r,) = spaces.reach(space, 1e-3)
    i_pivot = bar.moment + m * (L / 2) ** 2
    omega = math.sqrt(2 * m * g * (L / 2) / i_pivot)
    assert r.point and r.held == "PivotJoint 0" and r.fall == pytest.approx(L / 2)
    assert r.speed == pytest.approx(omega * (L + radius), rel=1e-12)
    assert [f for f in spaces.check(space, 0.05, tolerance=STABILITY)
            if f.kind == "tunnelling"] == []
    fastest = 0.0
    for _ in range(3000):
        space.step(1e-3)
        fastest = max(fastest, abs(bar.angular_velocity) * (L + radius))
    assert 0.97 * r.speed < fastest <= r.speed * 1.001  # pymunk's pivot gives a little


def test_each_body_has_its_own_budget_and_a_collision_passes_some_of_it_on():
    # Two equal, inelastic boxes over one floor, one 1 m up, one 100 m up. Each falls its own
    # height; a collision passes the other at most 4 m1 m2 / (m1 + m2)^2 ((1 + e)/2)^2 = 1/4
    # of the high one's energy (half its speed), more than the low one's own 1 m fall.
    space = pymunk.Space()
    space.gravity = (0.0, -10.0)
    space.add(pymunk.Segment(space.static_body, (-50, 0), (50, 0), 0.0))
    boxes = []
    for x, y in ((-10, 1.5), (10, 100.5)):
        b = pymunk.Body(1.0, 1.0)
        b.position = (x, y)
        space.add(b, pymunk.Poly.create_box(b, (1.0, 1.0)))
        boxes.append(b)
    low, high = spaces.reach(space, 1e-9)
    assert high.speed == pytest.approx(math.sqrt(2 * 10 * 100), rel=1e-6)
    assert low.speed == pytest.approx(0.5 * high.speed, rel=1e-6)
    assert "passed on" in low.source and not low.bound and not high.bound
    # Elastic (e = 1) equal masses pass everything: Newton's cradle.
    for s in space.shapes:
        s.elasticity = 1.0
    low, high = spaces.reach(space, 1e-9)
    assert low.speed == pytest.approx(high.speed, rel=1e-12)


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
    (r,) = spaces.reach(space, 1e-3)
    assert r.speed == pytest.approx(20.0) and not r.bound and "kinematic" in r.source


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

    found = spaces.check(row(), dt, tolerance=STABILITY)
    assert [(f.kind, f.subject) for f in found] == [("spring-network", "body 1")]
    space = row()
    e0 = spaces.energy(space).E
    spaces.step(space, 300 * dt, substeps=300)
    assert spaces.energy(space).E > 1e6 * e0  # really unstable
    space = row()
    h = spaces.suggest_dt(space, dt, tolerance=STABILITY)
    assert spaces.check(space, h, tolerance=STABILITY) == []
    spaces.step(space, 300 * h, substeps=300)
    assert spaces.energy(space).E < 2 * e0


# --- messages ---------------------------------------------------------------------------------


def _pixels() -> pymunk.Space:
    """A pixel-unit space as pygame programs build them: y down, g = 900, balls on a floor."""
    space = pymunk.Space()
    space.gravity = (0.0, 900.0)
    for x in (100, 200):
        b = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 10))
        b.position = (x, 50.0)
        c = pymunk.Circle(b, 10)
        c.elasticity = 0.9
        space.add(b, c)
    floor = pymunk.Segment(space.static_body, (0, 500), (600, 500), 1.0)
    floor.elasticity = 0.9
    space.add(floor)
    return space


def _holds(text: str) -> list[tuple[float, str, float]]:
    """Every 'a REL b' comparison printed in a report, checked as it reads."""
    ops = {"<": float.__lt__, "<=": float.__le__, ">=": float.__ge__, ">": float.__gt__}
    found = re.findall(r"(-?[\d.]+(?:e[+-]?\d+)?)(?: \w+)? (<=|>=|<|>) (-?[\d.]+(?:e[+-]?\d+)?)",
                       text)
    for a, rel, b in found:
        assert ops[rel](float(a), float(b)), f"{a} {rel} {b} is false"
    return found


def test_messages_speak_the_space_units_with_true_inequalities_and_reasons():
    space = _pixels()
    text = spaces.report(space, 0.1, units="px")
    assert "px/s" in text and " m/s" not in text and "lengths in px" in text
    plain = spaces.report(space, 0.1)
    assert " m/s" not in plain and "units/s" in plain and "units='m' or 'px'" in plain
    assert len(_holds(text)) >= 4
    found = {f.kind: f for f in spaces.check(space, 0.1, units="px")}
    assert set(found) >= {"tunnelling", "bias"}
    bias = found["bias"]
    assert str(bias).startswith("bias: space.collision_bias: 0.001797 < 1;")  # never '>'
    assert "adds energy" in bias.fix and "1 - bias^dt" in bias.fix
    assert found["tunnelling"].unit == "px" and "px per step" in found["tunnelling"].fix
    for f, ok in spaces.survey(space, 0.1, units="px"):
        assert ok == f.ok
        _holds(str(f))


def test_the_slop_finding_gives_its_reason_and_its_suggestion_is_a_hundredth():
    space = pymunk.Space()
    ball = pymunk.Body(0.1, pymunk.moment_for_circle(0.1, 0, 0.02))
    circle = pymunk.Circle(ball, 0.02)
    circle.elasticity = 1.0
    floor = pymunk.Segment(space.static_body, (-1, 0), (1, 0), 0.01)
    floor.elasticity = 1.0
    space.add(ball, circle, floor)
    kinds = {f.kind: f for f in spaces.check(space, 1e-3, units="m")}
    assert set(kinds) == {"slop", "bias"}
    slop = kinds["slop"]
    assert slop.limit == pytest.approx(0.1 * 0.02) and slop.dt_max is None
    assert str(slop).startswith("slop: space.collision_slop: 0.1 m > 0.002 m;")
    assert "a tenth of the smallest shape (0.02 m)" in slop.fix
    assert "collision_slop = 0.0002 m, a hundredth" in slop.fix and "re-forming" in slop.fix
    space.collision_slop = 1e-4
    space.collision_bias = 1.0
    assert spaces.check(space, 1e-3) == []
    assert spaces.suggest_dt(space, 1e-3) == 1e-3


def test_printed_numbers_keep_the_relation_true():
    # 0.10004 against 0.1 printed with 4 digits would read '0.1 > 0.1'.
    f = spaces.Finding("slop", "space.collision_slop", 0.10004, 0.1, "x", None, "<=", "m")
    assert f.comparison() == "0.10004 m > 0.1 m" and not f.ok
    assert spaces.Finding("x", "y", 1.0, 1.0, "z", None, "<=").comparison() == "1 <= 1"


def test_a_big_space_gets_a_short_report():
    space = pymunk.Space()
    space.gravity = (0.0, -900.0)
    space.add(pymunk.Segment(space.static_body, (-10, 0), (2000, 0), 1.0))
    for i in range(100):
        b = pymunk.Body(1.0, 100.0)
        b.position = (i * 15.0, 20.0 + (i % 7) * 30)
        space.add(b, pymunk.Poly.create_box(b, (10, 10)))
    text = spaces.report(space, 1 / 60)
    assert len(text.splitlines()) < 20 and "more passed; the closest to its limit" in text


def test_bad_dt_is_one_clear_error():
    with pytest.raises(UsageError, match="dt = -1"):
        spaces.check(pymunk.Space(), -1)
    for bad in ("", "a very long unit name", 3, "p\nx"):
        with pytest.raises(UsageError, match="units"):
            spaces.report(_pixels(), 0.1, units=bad)


@pytest.mark.parametrize("call", ["check", "survey", "report", "suggest_dt", "reach", "step"])
@pytest.mark.parametrize("dt", [1e6 * (1 + 1e-12), 1e7, 1e154, 1e300])
def test_every_guard_function_takes_the_steps_a_space_can_take(call, dt):
    # spaces.step and Driver refused a frame past 1e6 s, the others took any: reach then
    # gave a fall's speed of 9e152 at 1e150 s and 278 (the free fall, its lag lost to an
    # overflow) from 1e154 s on. Every function has the one border now.
    space = pymunk.Space()
    space.gravity = (0.0, -900.0)
    body, shape = _ball(1.0, 10.0, 1.0)
    body.position = (0.0, 53.0)
    space.add(body, shape, pymunk.Segment(space.static_body, (-100, 0), (100, 0), 0.0))
    with pytest.raises(UsageError, match=r"^dt = .*: must be a finite number > 0 and <= 1e\+06"):
        getattr(spaces, call)(space, dt)
    (fall,) = spaces.reach(space, 1e6)
    assert fall.speed == pytest.approx(900.0 * 1e6, rel=1e-9)  # at the border: g dt


# --- states no step fixes (issue 24) -----------------------------------------------------------


def _ball_space() -> tuple[pymunk.Space, pymunk.Body]:
    space = pymunk.Space()
    space.gravity = (0.0, -9.81)
    body, shape = _ball(1.0, 0.1, 1.0)
    space.add(body, shape, pymunk.Segment(space.static_body, (-1, 0), (1, 0), 0.01))
    return space, body


def _broken(case: str) -> pymunk.Space:
    space, body = _ball_space()
    if case == "inf velocity":
        body.velocity = (math.inf, 0.0)
    elif case == "nan velocity":
        body.velocity = (0.0, math.nan)
    elif case == "nan position":
        body.position = (math.nan, 1.0)
    elif case == "nan spin":
        body.angular_velocity = math.nan
    elif case == "after step(nan)":
        space.step(math.nan)
    elif case == "mass 0":
        space.add(pymunk.Body())
    return space


@pytest.mark.parametrize("case", ["inf velocity", "nan velocity", "nan position", "nan spin",
                                  "after step(nan)", "mass 0"])
def test_a_state_no_step_fixes_is_named_never_stepped_smaller(case):
    space = _broken(case)
    who = "body 1" if case == "mass 0" else "body 0"
    text = spaces.report(space, 0.01)
    assert f"FAIL state          {who}" in text and "no step is suggested" in text
    assert "sub-steps" not in text and "nothing to fix" not in text
    value = "mass = 0" if case == "mass 0" else ("inf" if "inf" in case else "nan")
    assert value in text
    (finding,) = spaces.check(space, 0.01)
    assert finding.kind == "state" and finding.subject == who and finding.dt_max is None
    for call in (spaces.suggest_dt, spaces.substeps, spaces.Driver, spaces.reach):
        with pytest.raises(DumbbellError) as err:
            call(space, 0.01)
        message = str(err.value)
        assert message.startswith(f"space: {who}: ") and value in message
        assert len(message) < 300 and "\n" not in message


def test_a_kinematic_body_at_1e300_is_a_speed_not_an_overflow():
    space, _ = _ball_space()
    k = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    k.velocity = (1e300, 0.0)
    space.add(k, pymunk.Circle(k, 0.1))
    text = spaces.report(space, 0.01, units="m")
    assert "1e+300 m/s" in text and "no step is suggested" in text
    (r,) = spaces.reach(space, 0.01)
    assert r.speed == pytest.approx(1e300) and math.isfinite(r.speed)
    for call in (spaces.suggest_dt, spaces.substeps, spaces.Driver):
        with pytest.raises(UsageError, match=r"dt = 0.01: .* 1,000,000,000 sub-steps .*body 0"):
            call(space, 0.01)


# --- sub-steps keep the program's forces (issue 28) --------------------------------------------


def _advance(space, push, substeps: int, driver: bool, frames: int = 1) -> None:
    if driver:
        d = spaces.Driver(space, 0.05, substeps=substeps)
        for _ in range(frames):
            push()
            d.step()
    else:
        for _ in range(frames):
            push()
            spaces.step(space, 0.05, substeps=substeps)


def _motion(space) -> list[float]:
    (body,) = space.bodies
    return [*body.velocity, body.angular_velocity, *body.position, body.angle]


@pytest.mark.parametrize("driver", [False, True], ids=["step", "Driver"])
@pytest.mark.parametrize("how", PUSHES)
def test_a_per_frame_push_acts_over_the_whole_frame_in_every_sub_step(how, driver):
    # The program sets its push once a frame; pymunk clears it after each step. The
    # velocity after a frame is the same with 1 and with n sub-steps (1e-9), and so is the
    # spin; the positions and angle differ by the sub-steps' own (first-order) step error, so
    # a push the program works out from them (at a point, along the body's axes) is compared
    # over one frame.
    frames = 1 if how in ("world point", "local point") else 3
    results = {}
    for n in (1, 7):
        space, push = pushed(how)
        _advance(space, push, n, driver, frames=frames)
        results[n] = _motion(space)
    one, many = results[1], results[7]
    assert many[:3] == pytest.approx(one[:3], rel=1e-9, abs=1e-9 * max(map(abs, one[:3])))
    # The velocity has really changed by the push (not only by gravity).
    space, push = pushed(how)
    _advance(space, lambda: None, 7, driver, frames=frames)
    assert max(abs(a - b) for a, b in zip(_motion(space)[:3], many[:3], strict=True)) > 0.1
    if how in ("force", "torque"):   # by hand: v0 + (g + F/m) t, w0 + T/I t, t = 0.15 s
        f, torque = ((40.0, -30.0), 0.0) if how == "force" else ((0.0, 0.0), 500.0)
        expected = [10.0 + f[0] / 2.0 * 0.15, -5.0 + (900.0 + f[1] / 2.0) * 0.15,
                    0.2 + torque / 300.0 * 0.15]
        assert many[:3] == pytest.approx(expected, rel=1e-12)


def test_one_newton_on_one_kilogram_for_one_second_is_one_metre_a_second():
    # The case: 1.0 m/s with one sub-step, 0.1 m/s with ten before the fix.
    for n in (1, 10, 1000):
        for driver in (False, True):
            space = pymunk.Space()
            body = pymunk.Body(1.0, 1.0)
            space.add(body)
            body.force, body.torque = (1.0, 0.0), 2.0
            if driver:
                spaces.Driver(space, 1.0, substeps=n).step()
            else:
                spaces.step(space, 1.0, substeps=n)
            assert body.velocity.x == pytest.approx(1.0, rel=1e-12)
            assert body.angular_velocity == pytest.approx(2.0, rel=1e-12)
            # After the frame the forces are cleared, as pymunk leaves them without sub-steps.
            assert body.force == (0, 0) and body.torque == 0


def test_the_push_is_one_frame_s_and_a_velocity_func_that_keeps_forces_keeps_them():
    # Driver.step(3) without a new push: the push acts in the first frame only, as with one
    # sub-step. A velocity_func that never calls pymunk's update leaves the force set: it
    # stays as it was after the frame, with and without sub-steps.
    for n in (1, 5):
        space = pymunk.Space()
        body = pymunk.Body(1.0, 1.0)
        space.add(body)
        body.force = (3.0, 0.0)
        spaces.Driver(space, 0.1, substeps=n).step(3)
        assert body.velocity.x == pytest.approx(0.3, rel=1e-12)
        frozen = pymunk.Body(1.0, 1.0)
        frozen.velocity_func = lambda b, g, d, dt: None
        space.add(frozen)
        frozen.force, frozen.velocity = (3.0, 4.0), (1.0, 0.0)
        spaces.step(space, 0.1, substeps=n)
        assert frozen.force == (3.0, 4.0) and frozen.velocity == (1.0, 0.0)


def test_a_car_driven_by_wheel_torques_keeps_its_speed_at_the_advised_sub_steps():
    # The guard asks for sub-steps (its suspension springs); with them the car reaches the
    # speed it reaches without them (it reached 1/n of it before the fix).
    n = spaces.substeps(car().space, 1 / 60)
    assert n > 10
    speeds = {}
    for sub in (1, n):
        c = car()
        d = spaces.Driver(c.space, 1 / 60, substeps=sub)
        for _ in range(120):
            c.drive()
            d.step()
        speeds[sub] = c.chassis.velocity.x
    # Rolling without slipping: torque 2 T over the car's inertia along the road.
    assert speeds[1] > 300 and speeds[n] == pytest.approx(speeds[1], rel=1e-3)


# --- the border of stepping, and a state that stops being finite (issue 30) ---------------------


@pytest.mark.parametrize("dt", [1e300, 1e7, math.inf, -1.0, 0.0])
def test_an_absurd_frame_step_is_refused_before_any_step(dt):
    space, body = _ball_space()
    before = tuple(body.position)
    for call in (lambda: spaces.Driver(space, dt, substeps=1),
                 lambda: spaces.step(space, dt, substeps=3)):
        with pytest.raises(UsageError) as err:
            call()
        message = str(err.value)
        assert message.startswith("dt = ") and "\n" not in message and len(message) < 200
    assert tuple(body.position) == before


def test_driver_stops_where_the_state_stops_being_finite_and_names_the_frame():
    # Issue 20's stiff spring stepped at w h = 2.1 > 2 grows 1.88 times a step until it
    # overflows. The frame (2 sub-steps) in which pymunk's own stepping first gives a state
    # that is not finite is the one named, and the driver has counted the frames up to it.
    h = 2.1 / math.sqrt(1e6 / 0.5)
    plain = _stiff()
    first = None
    for frame in range(1, 2000):
        plain.step(h)
        plain.step(h)
        if not all(math.isfinite(x) for b in plain.bodies for x in (*b.position, *b.velocity)):
            first = frame
            break
    assert first is not None and first > 100
    space = _stiff()
    driver = spaces.Driver(space, 2 * h, substeps=2)
    with pytest.raises(DumbbellError) as err:
        driver.step(5000)
    message = str(err.value)
    assert message.startswith("space: body 0: ") and f"after frame {first} " in message
    assert "stopped being finite" in message and "\n" not in message
    assert driver.frames == first
    with pytest.raises(UsageError, match=r"^space: body 0: .* is not a finite number"):
        driver.step()
    assert driver.frames == first


def test_a_nan_the_program_set_is_refused_before_stepping():
    space, body = _ball_space()
    driver = spaces.Driver(space, 0.01)
    driver.step(2)
    body.velocity = (math.nan, 0.0)
    for call in (driver.step, lambda: spaces.step(space, 0.01)):
        with pytest.raises(UsageError, match=r"^space: body 0: velocity = \(nan, 0\)"):
            call()
    assert driver.frames == 2


def test_a_force_a_callback_sets_inside_the_step_is_kept_on_top_of_the_push():
    # A constraint's post_solve sets a force after each step's velocity update: pymunk keeps
    # it for the next step. With n sub-steps it acts in the n - 1 later sub-steps, on top of
    # the program's push, and what it set last is left for the next frame, as without them.
    for n in (1, 4):
        space = pymunk.Space()
        body = pymunk.Body(2.0, 1.0)
        hook = pymunk.DampedSpring(space.static_body, body, (0, 0), (0, 0), 0.0, 0.0, 0.0)
        hook.post_solve = lambda c, s: setattr(c.b, "force", c.b.force + (1.0, 0.0))
        space.add(body, hook)
        body.force = (6.0, 0.0)
        spaces.step(space, 0.2, substeps=n)
        assert body.velocity.x == pytest.approx((6.0 * 0.2 + (n - 1) * 1.0 * 0.2 / n) / 2.0,
                                                rel=1e-12)
        assert body.force == (1.0, 0.0)


# --- the centre of gravity, not the body's origin (issue 28's owed tests) ----------------------
# pymunk's Body.position is the body's origin; its centre of gravity is the local point
# Body.center_of_gravity, and Body.velocity is the velocity of that point. Each space here
# puts the centre of gravity far from the origin, so an estimate taken from `position`
# gives another number.


def test_a_bar_pivoted_at_its_origin_falls_from_its_centre_of_gravity():
    # The bar's origin is the pivot; its centre of gravity is L/2 along it. Level at the
    # start, it can drop L/2 and turn about the pivot with I = I_cg + m (L/2)^2.
    m, L, radius, g = 1.5, 2.0, 0.05, 9.81
    space = pymunk.Space()
    space.gravity = (0.0, -g)
    i_cg = pymunk.moment_for_segment(m, (-L / 2, 0), (L / 2, 0), radius)
    bar = pymunk.Body(m, i_cg)
    bar.center_of_gravity = (L / 2, 0.0)
    bar.position = (0.0, 0.0)
    space.add(bar, pymunk.Segment(bar, (0, 0), (L, 0), radius),
              pymunk.PivotJoint(space.static_body, bar, (0.0, 0.0)))
    (r,) = spaces.reach(space, 1e-3)
    omega = math.sqrt(2 * m * g * (L / 2) / (i_cg + m * (L / 2) ** 2))
    assert r.point and r.fall == pytest.approx(L / 2, rel=1e-12)
    assert r.level == pytest.approx(L / 2, rel=1e-12)          # depth along g: -y of the cg
    assert r.speed == pytest.approx(omega * (L + radius), rel=1e-12)
    fastest = 0.0
    for _ in range(3000):
        space.step(1e-3)
        fastest = max(fastest, abs(bar.angular_velocity) * (L + radius))
    assert 0.97 * r.speed < fastest <= r.speed * 1.001


def test_a_bob_on_a_pin_falls_from_its_centre_of_gravity():
    # The pin holds the bob's centre of gravity 2 m from the anchor; its origin is 3 m away
    # from its centre of gravity. Level at the start: it can drop the pin's length.
    space = pymunk.Space()
    space.gravity = (0.0, -10.0)
    bob = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.1))
    bob.center_of_gravity = (-3.0, 1.0)
    bob.position = (5.0, -1.0)                    # centre of gravity at (2, 0)
    space.add(bob, pymunk.Circle(bob, 0.1, (-3.0, 1.0)),
              pymunk.PinJoint(space.static_body, bob, (0.0, 0.0), (-3.0, 1.0)))
    (r,) = spaces.reach(space, 1e-4)
    assert r.held == "PinJoint 0" and r.fall == pytest.approx(2.0, rel=1e-12)
    h = 0.5 * 10.0 * 1e-4
    assert r.speed == pytest.approx(h + math.sqrt(h * h + 2 * 10.0 * 2.0), rel=1e-12)


def test_a_free_body_falls_to_the_floor_from_its_shapes_and_its_level_is_its_cg_s():
    # Origin at y = 20, centre of gravity and ball 3 below it: the ball (r = 0.5) meets the
    # floor (top at 0.1) after 20 - 3 - 0.5 - 0.1 = 16.4; its centre of gravity then is at
    # y = 0.6 (depth -0.6).
    space = pymunk.Space()
    space.gravity = (0.0, -10.0)
    body = pymunk.Body(2.0, pymunk.moment_for_circle(2.0, 0, 0.5))
    body.center_of_gravity = (5.0, -3.0)
    body.position = (0.0, 20.0)
    space.add(body, pymunk.Circle(body, 0.5, (5.0, -3.0)),
              pymunk.Segment(space.static_body, (-5, 0), (15, 0), 0.1))
    (r,) = spaces.reach(space, 1e-3)
    assert r.fall == pytest.approx(16.4, rel=1e-12)
    assert r.level == pytest.approx(-0.6, rel=1e-12)
    h = 0.5 * 10.0 * 1e-3
    assert r.speed == pytest.approx(h + math.sqrt(h * h + 2 * 10.0 * 16.4), rel=1e-12)


def test_tunnelling_takes_a_spinning_body_s_reach_from_its_centre_of_gravity():
    # A ball of radius 1 centred on its centre of gravity, 3 from the origin, spinning at
    # 10 rad/s, at rest otherwise, no gravity: its fastest point moves at 10 x 1, not 10 x 4.
    space = pymunk.Space()
    space.collision_slop = 1e-3
    body = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 1.0))
    body.center_of_gravity = (3.0, 0.0)
    body.angular_velocity = 10.0
    space.add(body, pymunk.Circle(body, 1.0, (3.0, 0.0)),
              pymunk.Segment(space.static_body, (-10, -2), (10, -2), 0.1))
    (r,) = spaces.reach(space, 1e-3)
    assert r.now == pytest.approx(10.0, rel=1e-12)
    limit = 0.5 * 0.2 + 0.5 * 2.0
    (row,) = [f for f, _ in spaces.survey(space, 0.2, speeds="state") if f.kind == "tunnelling"]
    assert row.value == pytest.approx(10.0 * 0.2, rel=1e-12) and row.limit == limit


def test_a_spring_between_centres_of_gravity_moves_no_rotation():
    # Anchors at each body's centre of gravity (far from their origins): w = sqrt(k / mu),
    # the moments do not enter.
    space = pymunk.Space()
    a, b = pymunk.Body(1.0, 0.01), pymunk.Body(3.0, 0.02)
    a.center_of_gravity, b.center_of_gravity = (0.0, 4.0), (-2.0, 0.0)
    a.position, b.position = (0.0, 0.0), (3.0, 4.0)
    spring = pymunk.DampedSpring(a, b, (0.0, 4.0), (-2.0, 0.0), 1.0, 300.0, 0.0)
    space.add(a, b, spring)
    assert spaces.spring_omega(spring) == pytest.approx(math.sqrt(300.0 / 0.75), rel=1e-12)


def test_a_state_no_step_fixes_carries_the_space_s_units():
    space, body = _ball_space()
    body.velocity = (math.nan, 0.0)
    assert "velocity = (nan, 0) m/s is not a finite number" in spaces.report(space, 0.01,
                                                                             units="m")
    space, body = _ball_space()
    body.position = (math.inf, 1.0)
    assert "position = (inf, 1) px is not" in spaces.report(space, 0.01, units="px")
    space = _broken("mass 0")
    assert "mass = 0 kg: pymunk steps" in spaces.report(space, 0.01)


def test_a_spring_s_row_states_its_closed_form_no_drift_and_its_swing():
    # Issue 28: every constraint's row gives its drift; a spring's step keeps a modified
    # energy, so its closed form is no drift and a swing of 2 w dt / (2 - w dt).
    w = math.sqrt(200.0 / 0.05)
    ((row, ok),) = spaces.survey(_pair(0.1, 0.1, 200.0), 0.5 / w, tolerance=STABILITY)
    assert ok and row.note == "no drift: its energy swings by at most 66.7 % and back"
    assert spaces.energy_swing(0.5) == pytest.approx(2 / 3)
