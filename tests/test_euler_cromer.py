"""The hand-written reference against the textbook listing and against the exact solution."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dumbbell import simulate
from tests.conftest import make_scene


def textbook_listing(t_end: float, dt: float = 1e-5) -> tuple[np.ndarray, ...]:
    """The listing of section 13.5.1 transcribed to plain Python, typos fixed (vA[0], not
    vA[1]), the same operations in the same order."""
    m, k, b, h0, g = 0.1, 200.0, 0.2, 1.0, 9.8
    n = round(t_end / dt) + 1
    xA, vA, xB, vB = [0.0] * n, [0.0] * n, [0.0] * n, [0.0] * n
    xA[0] = h0 + b
    xB[0] = h0
    for i in range(n - 1):
        f = k * (xA[i] - xB[i] - b)
        fA = -f - m * g
        fB = f - m * g
        aA = fA / m
        vA[i + 1] = vA[i] + aA * dt
        xA[i + 1] = xA[i] + vA[i + 1] * dt
        aB = fB / m
        vB[i + 1] = vB[i] + aB * dt
        xB[i + 1] = xB[i] + vB[i + 1] * dt
        if (xB[i + 1] < 0.0) and (xB[i] >= 0.0):
            vB[i + 1] = abs(vB[i + 1])
    return tuple(np.array(c) for c in (xA, vA, xB, vB))


def test_bit_for_bit_with_the_textbook_listing(textbook):
    # 0.6 s holds the first two impacts (0.452 s and 0.499 s), so the flip rule is covered.
    expected = textbook_listing(0.6)
    traj = simulate(textbook, "euler-cromer", t_end=0.6, every=1)
    assert len(traj.events) == 2
    for name, column in zip(("xA", "vA", "xB", "vB"), expected, strict=True):
        assert np.array_equal(traj[name], column), name


def test_every_keeps_the_same_floats(textbook):
    full = simulate(textbook, "euler-cromer", t_end=1.0, every=1)
    sparse = simulate(textbook, "euler-cromer", t_end=1.0, every=250)
    assert len(sparse) == 100_000 // 250 + 1
    assert np.array_equal(sparse.t, full.t[::250])
    for name in ("xA", "vA", "xB", "vB"):
        assert np.array_equal(sparse[name], full[name][::250])


def test_no_internal_motion_before_the_first_impact(textbook):
    traj = simulate(textbook, "euler-cromer", t_end=1.0, every=1)
    t1 = math.sqrt(2 * 1.0 / 9.8)
    first = traj.first_impact()
    assert first.body == "B"
    # The flip happens at the first step inside the floor. Euler-Cromer's free fall runs ahead
    # (x_n = x0 - g dt^2 n(n+1)/2), which moves the crossing earlier by about dt/2.
    assert abs(first.t - t1) <= 2e-5
    before = traj.t < first.t
    # Zero to rounding: in floats the spring starts at 1.2 - 1.0 - 0.2 = -5.6e-17 m.
    assert traj["K_int"][before].max() < 1e-28
    after = (traj.t >= first.t) & (traj.t < first.t + 1e-4)
    assert traj["K_int"][after].min() > 1.0
    # Reversing vB sets V = 0: K_cm drops to (almost) nothing, and K_int takes its place.
    j = int(np.searchsorted(traj.t, first.t))
    assert traj["K_cm"][j] < 1e-6
    assert traj["K_int"][j] == pytest.approx(traj["K_cm"][j - 1], rel=1e-3)


def test_converges_to_the_exact_solution_over_one_second(textbook):
    exact = simulate(textbook, "exact", t_end=1.0, dt=1e-5, every=100)
    errors = []
    for dt in (1e-3, 1e-4, 1e-5):
        every = round(1e-3 / dt)
        ec = simulate(textbook, "euler-cromer", t_end=1.0, dt=dt, every=every)
        assert np.allclose(ec.t, exact.t)
        errors.append(max(np.abs(ec[c] - exact[c]).max() for c in ("xA", "xB")))
    assert errors[0] > 3 * errors[1] > 9 * errors[2]
    assert errors[2] < 2e-4  # docs/physics.md: about 1e-4 m up to 1 s at dt = 1e-5


def test_energy_error_is_bounded_and_first_order(textbook):
    spreads = []
    for dt in (1e-4, 1e-5):
        traj = simulate(textbook, "euler-cromer", dt=dt, t_end=3.0, every=10)
        E = traj["E"]
        spreads.append((E.max() - E.min()) / E[0])
    assert spreads[1] < 1e-3
    assert 4 < spreads[0] / spreads[1] < 25


def test_unequal_masses_conserve_energy_and_momentum_of_the_centre():
    scene = make_scene({"bodies.A.mass": 0.05, "bodies.B.mass": 0.4})
    traj = simulate(scene, "euler-cromer", t_end=3.0, dt=1e-5, every=10)
    assert traj.verdict.ok and len(traj.events) > 2
    E = traj["E"]
    assert (E.max() - E.min()) / E[0] < 2e-3
    exact = simulate(scene, "exact", t_end=3.0, dt=1e-5, every=10)
    Ex = exact["E"]
    assert (Ex.max() - Ex.min()) / Ex[0] < 1e-12
    # Before the first impact both solvers agree closely.
    before = exact.t < exact.events[0].t - 1e-3
    assert np.abs(traj["xB"][before] - exact["xB"][before]).max() < 1e-4


def test_without_a_floor_the_centre_of_mass_falls_freely_forever():
    scene = make_scene({"bodies.A.height": 1.25}, drop=("floor",))
    traj = simulate(scene, "euler-cromer", t_end=2.0, dt=1e-5, every=100)
    assert traj.events == () and traj.verdict.ok
    X = 0.5 * (traj["xA"] + traj["xB"])
    free_fall = 1.125 - 0.5 * 9.8 * traj.t**2
    # Euler-Cromer's free fall is first order: x_n = x0 - g dt^2 n(n+1)/2.
    assert np.abs(X - free_fall).max() < 9.8 * 1e-5 * 2.0
    E = traj["E"]
    assert (E.max() - E.min()) / abs(E[0]) < 1e-3
    assert traj["xB"].min() < -15  # it really went through where the floor would be


def test_either_particle_can_hit_the_floor():
    # A soft spring and a fast downward start: A catches up with B and reaches the floor.
    scene = make_scene({"spring.stiffness": 0.5, "bodies.A.velocity": -6.0})
    for solver in ("euler-cromer", "exact"):
        traj = simulate(scene, solver, t_end=2.0, dt=1e-5, every=100)
        assert {e.body for e in traj.events} == {"A", "B"}, solver
        assert traj.verdict.ok, traj.verdict
