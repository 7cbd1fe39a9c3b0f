"""spaces.energy on hand-built pymunk spaces, against formulas written out here."""

from __future__ import annotations

import math
import subprocess
import sys

import pymunk
import pytest

from dumbbell import spaces

G = (0.0, -9.81)


def _rot(angle: float, p: tuple[float, float]) -> tuple[float, float]:
    c, s = math.cos(angle), math.sin(angle)
    return (c * p[0] - s * p[1], s * p[0] + c * p[1])


def _body(space: pymunk.Space, m: float, moment: float, cg: tuple[float, float],
          pos: tuple[float, float], angle: float, v: tuple[float, float], w: float
          ) -> pymunk.Body:
    b = pymunk.Body(m, moment)
    b.center_of_gravity = cg
    b.angle = angle
    b.position = pos
    b.velocity = v
    b.angular_velocity = w
    space.add(b, pymunk.Circle(b, 0.1))
    return b


def _cg_world(pos: tuple[float, float], angle: float, cg: tuple[float, float]
              ) -> tuple[float, float]:
    # pymunk's position is the body's origin; the centre of gravity sits at cg from it.
    r = _rot(angle, cg)
    return (pos[0] + r[0], pos[1] + r[1])


def test_one_body():
    space = pymunk.Space()
    space.gravity = G
    pos, angle, cg, v, w, m, moment = (1.0, 2.0), 0.4, (0.3, -0.1), (1.5, -2.0), 3.0, 2.0, 0.7
    _body(space, m, moment, cg, pos, angle, v, w)
    e = spaces.energy(space, about=(0.5, -1.0))
    rx, ry = _cg_world(pos, angle, cg)
    K_trans = 0.5 * m * (v[0] ** 2 + v[1] ** 2)
    K_rot = 0.5 * moment * w**2
    assert e.K_trans == pytest.approx(K_trans, rel=1e-14)
    assert e.K_rot == pytest.approx(K_rot, rel=1e-14)
    assert e.K_cm == pytest.approx(K_trans, rel=1e-14)
    assert e.K_int == pytest.approx(K_rot, rel=1e-14)
    assert e.U_g == pytest.approx(m * 9.81 * ry, rel=1e-14)
    assert e.U_spring == 0.0
    assert e.E == pytest.approx(K_trans + K_rot + m * 9.81 * ry, rel=1e-14)
    assert e.momentum == pytest.approx((m * v[0], m * v[1]), rel=1e-14)
    L_about = m * ((rx - 0.5) * v[1] - (ry + 1.0) * v[0]) + moment * w
    assert e.L_about == pytest.approx(L_about, rel=1e-13)
    assert e.L_cm == pytest.approx(moment * w, rel=1e-13)
    assert e.cm == pytest.approx((rx, ry), rel=1e-14)
    assert len(e.bodies) == 1 and e.bodies[0].subject == "body 0"
    assert e.skipped == () and e.unknown == () and e.complete


def test_two_bodies_and_a_spring():
    space = pymunk.Space()
    space.gravity = (1.0, -9.81)  # not vertical: U_g = -m g.r in general
    a = _body(space, 1.0, 0.2, (0.1, 0.0), (0.0, 1.0), 0.3, (1.0, 0.5), -2.0)
    b = _body(space, 3.0, 0.9, (0.0, 0.2), (2.0, 0.5), -1.1, (-0.5, 0.25), 1.0)
    k, rest, aa, ab = 50.0, 1.2, (0.2, 0.1), (-0.3, 0.4)
    space.add(pymunk.DampedSpring(a, b, aa, ab, rest, k, 0.0))
    e = spaces.energy(space)
    pa = _rot(0.3, aa)
    pb = _rot(-1.1, ab)
    d = math.dist((0.0 + pa[0], 1.0 + pa[1]), (2.0 + pb[0], 0.5 + pb[1]))
    U_spring = 0.5 * k * (d - rest) ** 2
    ra, rb = _cg_world((0.0, 1.0), 0.3, (0.1, 0.0)), _cg_world((2.0, 0.5), -1.1, (0.0, 0.2))
    K_trans = 0.5 * 1.0 * (1.0 + 0.25) + 0.5 * 3.0 * (0.25 + 0.0625)
    K_rot = 0.5 * 0.2 * 4.0 + 0.5 * 0.9 * 1.0
    V = ((1.0 * 1.0 + 3.0 * -0.5) / 4.0, (1.0 * 0.5 + 3.0 * 0.25) / 4.0)
    R = ((ra[0] + 3.0 * rb[0]) / 4.0, (ra[1] + 3.0 * rb[1]) / 4.0)
    K_cm = 0.5 * 4.0 * (V[0] ** 2 + V[1] ** 2)
    U_g = -4.0 * (1.0 * R[0] - 9.81 * R[1])
    assert e.U_spring == pytest.approx(U_spring, rel=1e-13)
    assert e.springs[0].U == pytest.approx(U_spring, rel=1e-13)
    assert e.K_trans == pytest.approx(K_trans, rel=1e-14)
    assert e.K_rot == pytest.approx(K_rot, rel=1e-14)
    assert e.K_cm == pytest.approx(K_cm, rel=1e-14)
    assert e.K_int == pytest.approx(K_trans + K_rot - K_cm, rel=1e-13)
    assert e.U_g == pytest.approx(U_g, rel=1e-13)
    assert e.E == pytest.approx(K_trans + K_rot + U_g + U_spring, rel=1e-13)
    L_cm = (1.0 * ((ra[0] - R[0]) * 0.5 - (ra[1] - R[1]) * 1.0)
            + 3.0 * ((rb[0] - R[0]) * 0.25 - (rb[1] - R[1]) * -0.5) + 0.2 * -2.0 + 0.9 * 1.0)
    assert e.L_cm == pytest.approx(L_cm, rel=1e-12)
    # Angular momentum about a point moves by R x P (the system's momentum about the origin).
    P = e.momentum
    assert e.L_about == pytest.approx(L_cm + R[0] * P[1] - R[1] * P[0], rel=1e-12)


def test_rotary_spring_energy_matches_pymunks_motion():
    # The sign convention matters with a rest angle: pymunk's torque is -k(a_a - a_b - rest).
    # With the right one, E stays put while the spring swings (here: both bodies turn).
    space = pymunk.Space()
    a = _body(space, 1.0, 0.05, (0.0, 0.0), (0.0, 0.0), 0.9, (0.0, 0.0), 0.0)
    b = _body(space, 1.0, 0.15, (0.0, 0.0), (1.0, 0.0), -0.2, (0.0, 0.0), 0.5)
    k, rest = 2.0, 0.3
    space.add(pymunk.DampedRotarySpring(a, b, rest, k, 0.0))
    e0 = spaces.energy(space)
    assert e0.U_spring == pytest.approx(0.5 * k * (0.9 - -0.2 - rest) ** 2, rel=1e-14)
    assert e0.K_rot == pytest.approx(0.5 * 0.15 * 0.25, rel=1e-14)
    swing = []
    for _ in range(4000):
        space.step(1e-4)
        swing.append(spaces.energy(space).U_spring)
    assert max(swing) - min(swing) > 0.5 * e0.E  # the energy really moves between terms
    assert spaces.energy(space).E == pytest.approx(e0.E, rel=1e-3)  # the method's O(dt) swing
    assert spaces.energy(space).L_cm == pytest.approx(e0.L_cm, abs=1e-12)  # internal torques


def test_static_kinematic_infinite_moment_and_unknowns_are_reported():
    space = pymunk.Space()
    space.gravity = G
    a = _body(space, 2.0, math.inf, (0.0, 0.0), (0.0, 3.0), 0.0, (0.0, -1.0), 0.0)
    spinning = _body(space, 1.0, math.inf, (0.0, 0.0), (5.0, 3.0), 0.0, (0.0, 0.0), 2.0)
    wall = pymunk.Body(body_type=pymunk.Body.STATIC)
    wall.position = (0.0, 5.0)
    belt = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    belt.velocity = (3.0, 0.0)
    space.add(wall, belt)
    k, rest = 40.0, 1.5
    space.add(pymunk.DampedSpring(wall, a, (0.5, 0.0), (0.0, 0.0), rest, k, 0.1))
    custom = pymunk.DampedSpring(a, spinning, (0.0, 0.0), (0.0, 0.0), 1.0, 10.0, 0.0)
    custom.force_func = lambda s, dist: -3.0 * (dist - 1.0) ** 3
    space.add(custom, pymunk.SimpleMotor(a, belt, 1.0), pymunk.PivotJoint(spinning, belt, (5, 3)))
    e = spaces.energy(space)
    d = math.dist((0.5, 5.0), (0.0, 3.0))
    assert e.U_spring == pytest.approx(0.5 * k * (d - rest) ** 2, rel=1e-14)
    assert e.K_rot == 0.0  # infinite moments: no rotational term, not inf or nan
    assert e.K_trans == pytest.approx(0.5 * 2.0 * 1.0, rel=1e-14)  # the belt's speed not counted
    assert e.U_g == pytest.approx(9.81 * (2.0 * 3.0 + 1.0 * 3.0), rel=1e-14)
    reasons = {s.subject: s.reason for s in e.skipped}
    assert "static" in reasons["body 2"] and "kinematic" in reasons["body 3"]
    assert "infinite moment" in reasons["body 1"] and "body 0" not in reasons
    unknown = {s.subject for s in e.unknown}
    assert unknown == {"DampedSpring 1", "SimpleMotor 2"} and not e.complete
    assert any("damping 0.1" in n for n in e.notes)


def test_import_is_lazy():
    code = ("import sys, dumbbell.spaces; "
            "print(sorted(m for m in ('pymunk', 'matplotlib', 'imageio', 'PIL') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[]"


def test_what_moves_energy_over_time_is_named_in_the_snapshot():
    # The minimal case: the snapshot cannot count what a joint does over a run, but
    # it says which joints can (the ledger counts them), and a custom velocity_func's field
    # is energy it cannot see.
    space = pymunk.Space()
    body = pymunk.Body(1, pymunk.moment_for_circle(1, 0, 0.1))
    body.velocity = (2, 0)
    pivot = pymunk.PivotJoint(space.static_body, body, (0, 0))
    pivot.max_force = 10.0
    space.add(body, pymunk.Circle(body, 0.1), pivot,
              pymunk.SlideJoint(space.static_body, body, (0, 0), (0, 0), 0, 1))
    e = spaces.energy(space)
    assert e.complete and len(e.notes) == 2
    assert "SlideJoint 1: a stop" in e.notes[1] and "max_force 10" in e.notes[0]
    body.velocity_func = lambda b, g, d, dt: pymunk.Body.update_velocity(b, (0, -1), d, dt)
    e = spaces.energy(space)
    assert not e.complete and [u.subject for u in e.unknown] == ["body 0"]
    assert "velocity_func" in e.unknown[0].reason


def test_printed_values_claim_a_unit_only_when_the_program_names_one():
    # Issue 29 item 14: a value of a space carries its unit when known, and pymunk has none:
    # a pixel space's energies are not joules unless the program says they are.
    import pymunk

    def space_now():
        space = pymunk.Space()
        space.gravity = (0, 900)
        ball = pymunk.Body(2, 100)
        ball.position, ball.velocity = (10, -500), (30, 0)
        space.add(ball, pymunk.Circle(ball, 5))
        return space

    # By hand: K = m v^2 / 2 = 900; U_g = -m g . r = -2 (900 * -500) = 900000.
    E = 0.5 * 2 * 30**2 - 2 * (900 * -500)
    for units, energy, momentum in [(None, "energy units", "momentum units"),
                                    ("px", "kg px²/s²", "kg px/s"), ("m", "J", "kg m/s"),
                                    (("cm", "g", "ms"), "g cm²/ms²", "g cm/ms")]:
        space = space_now()
        shown = repr(spaces.energy(space, units=units))
        assert f"E = {E:.9g} {energy}:" in shown and f"momentum = (60, 0) {momentum}" in shown
        assert (" J" in shown) == (units == "m")
        ledger = spaces.Ledger(space, units=units)
        heat = spaces.HeatCounter(space, units=units)
        space.step(1 / 60)
        table = ledger.balance().table()
        assert energy in repr(ledger.balance()) and energy in table and energy in repr(heat)
        assert ("J" in table.replace(",", " ").split()) == (units == "m")
        ledger.detach()
        heat.detach()


@pytest.mark.parametrize("kind", ["PinJoint", "DampedSpring"])
def test_a_constraint_to_a_body_outside_the_space_is_named(kind):
    # A body joined by a constraint and not in the space: pymunk's impulses change its
    # velocity (its kinetic energy went 6.0 -> 7.08 J while E fell 0.5 -> 0.29 J), and
    # spaces.energy said nothing. E is still the space's bodies' own (checked by hand); the
    # note says where the rest went.
    space = pymunk.Space()
    outside = pymunk.Body(3.0, 3.0)
    outside.position, outside.velocity = (0.0, 3.0), (0.0, 2.0)
    disc = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.1))
    disc.position, disc.velocity = (0.0, 4.0), (1.0, 0.0)
    joint = (pymunk.PinJoint(outside, disc) if kind == "PinJoint" else
             pymunk.DampedSpring(outside, disc, (0, 0), (0, 0), 1.0, 5.0, 0.0))
    space.add(disc, pymunk.Circle(disc, 0.1), joint)
    for _ in range(60):
        space.step(1 / 60)
    e = spaces.energy(space, units="m")
    d = outside.position.get_distance(disc.position)
    spring = 0.5 * 5.0 * (d - 1.0) ** 2 if kind == "DampedSpring" else 0.0
    hand = (0.5 * disc.mass * disc.velocity.length_squared
            + 0.5 * disc.moment * disc.angular_velocity ** 2 + spring)
    assert e.E == pytest.approx(hand, rel=1e-12)
    (note,) = [n for n in e.notes if "not in the space" in n]
    assert note.startswith(f"{kind} 0 joins a body that is not in the space")
    plain = pymunk.Space()
    plain.add(pymunk.Body(1.0, 1.0))
    assert not any("not in the space" in n for n in spaces.energy(plain).notes)
