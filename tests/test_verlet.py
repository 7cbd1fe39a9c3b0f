"""The ``verlet`` solver against the exact solution: second order through the impacts,
bounded energy error, impacts located inside the step."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dumbbell.model.energy import relative_energy_error
from dumbbell.model.scene import load_scene
from dumbbell.solvers import METHODS, RunOptions, simulate, solver_class, supported
from tests.conftest import SCENES, make_scene

#: A heavy A on a soft spring: A reaches the floor too (exact: B, A, B, A, B in [0, 1] s).
A_HITS = {"bodies.A.height": 0.5, "bodies.B.height": 0.3, "spring.stiffness": 5.0,
          "bodies.A.mass": 1.0, "bodies.B.mass": 0.1}


def position_error(scene, dt: float, t_end: float, every: int = 1) -> float:
    """Largest |x - x_exact| of either particle at the verlet run's samples (m)."""
    run = simulate(scene, "verlet", dt=dt, t_end=t_end, every=every)
    exact = simulate(scene, "exact", dt=dt, t_end=t_end, every=every)
    assert run.verdict.ok and np.array_equal(run.t, exact.t)
    return max(np.max(np.abs(run[c] - exact[c])) for c in ("xA", "xB"))


def test_supported_scenes():
    assert "verlet" in supported(make_scene())
    assert "verlet" in supported(load_scene(SCENES / "tilted-2d.toml"))
    for name in ("friction-2d.toml", "rigid-2d.toml"):
        assert "verlet" not in supported(load_scene(SCENES / name))


def test_second_order_over_one_second_with_impacts():
    # [0, 1 s] holds the textbook's first two impacts; dt 1e-3 -> 1e-4 must cut the error
    # about 100-fold (order 2), where a late velocity flip would allow only 10-fold.
    scene = make_scene()
    coarse = position_error(scene, 1e-3, 1.0)
    fine = position_error(scene, 1e-4, 1.0)
    order = math.log10(coarse / fine)
    assert 1.8 < order < 2.2, (coarse, fine)
    assert fine < 2e-6


def test_first_impact_is_exact_under_uniform_gravity():
    # Before the first impact the spring is at rest and both particles fall freely; Verlet is
    # exact for a constant force, so the located impact is sqrt(2 h0 / g) to rounding, even
    # with a step of 1 ms that does not divide it.
    traj = simulate(make_scene(), "verlet", dt=1e-3, t_end=0.6)
    first = traj.first_impact()
    assert first.body == "B"
    assert abs(first.t - math.sqrt(2 * 1.0 / 9.8)) < 1e-12
    assert first.v_before == pytest.approx(-math.sqrt(2 * 9.8 * 1.0), rel=1e-12)
    assert first.v_after == -first.v_before


def test_impact_times_match_exact_with_both_bodies_hitting():
    scene = make_scene(A_HITS)
    exact = simulate(scene, "exact", dt=1e-4, t_end=1.0)
    assert [e.body for e in exact.events] == ["B", "A", "B", "A", "B"]
    worst = {}
    for dt in (1e-3, 1e-4):
        run = simulate(scene, "verlet", dt=dt, t_end=1.0)
        assert [e.body for e in run.events] == [e.body for e in exact.events]
        worst[dt] = max(abs(a.t - b.t) for a, b in zip(run.events, exact.events, strict=True))
        # Located inside the step, not at a step boundary.
        assert any(abs(e.t / dt - round(e.t / dt)) > 1e-3 for e in run.events)
    assert worst[1e-4] < 1e-6
    assert worst[1e-3] / worst[1e-4] > 50  # second order in the impact times too
    assert position_error(scene, 1e-4, 1.0) < 1e-5


def test_energy_error_bounded_and_second_order():
    scene = make_scene()
    errs = {}
    for dt in (1e-3, 1e-4):
        traj = simulate(scene, "verlet", dt=dt, t_end=10.0, every=10)
        assert traj.verdict.ok and len(traj.events) > 15
        err = relative_energy_error(traj.energy)
        # No drift: the second half of the run is no worse than the first (bounded error).
        half = len(err) // 2
        assert err[half:].max() < 1.5 * err[:half].max()
        errs[dt] = err.max()
    assert errs[1e-4] < 2e-5
    assert 70 < errs[1e-3] / errs[1e-4] < 130


def test_no_floor_matches_exact():
    scene = make_scene({"bodies.A.velocity": 1.0}, drop=("floor",))
    assert position_error(scene, 1e-3, 1.0) < 2e-4
    assert position_error(scene, 1e-4, 1.0) < 2e-6


def test_samples_every_nth_step():
    traj = simulate(make_scene(), "verlet", dt=1e-4, t_end=0.5, every=7)
    n_steps = 5000
    assert len(traj.t) == n_steps // 7 + 1
    np.testing.assert_array_equal(traj.t, np.arange(len(traj.t)) * 7 * 1e-4)
    full = simulate(make_scene(), "verlet", dt=1e-4, t_end=0.5)
    np.testing.assert_array_equal(traj["xB"], full["xB"][::7])


def test_unstable_step_is_a_verdict():
    # w = sqrt(k/mu) = 63.25 rad/s: dt = 0.04 s gives w*dt = 2.5 > 2.
    traj = simulate(make_scene(), "verlet", dt=0.04, t_end=20.0)
    assert traj.verdict.status == "unstable"
    assert "w*dt" in traj.verdict.reason
    assert np.all(np.isfinite(traj["xA"]))


def test_inelastic_floor_comes_to_rest_as_failed():
    # A lone particle pair with e = 0.5 bounces infinitely often in finite time.
    scene = make_scene({"floor.elasticity": 0.5, "spring.stiffness": 2000.0})
    traj = simulate(scene, "verlet", dt=1e-3, t_end=10.0)
    assert traj.verdict.status == "failed"
    assert "rest" in traj.verdict.reason
    for ev in traj.events:
        assert ev.v_after == pytest.approx(-0.5 * ev.v_before, abs=1e-15)


def test_2d_upright_is_the_1d_motion():
    # With the axis vertical the 2D kernel moves along y only and must reproduce the 1D
    # motion (the spring force is computed differently, so equal to rounding, not bits).
    upright = load_scene(SCENES / "tilted-2d.toml").with_values({"tilt": 0.0})
    two = simulate(upright, "verlet", dt=1e-4, t_end=1.0, every=1)
    one = simulate(make_scene(), "verlet", dt=1e-4, t_end=1.0)
    assert np.all(two["xA"] == 0.0) and np.all(two["vxB"] == 0.0)
    for c in ("A", "B"):
        np.testing.assert_allclose(two[f"y{c}"], one[f"x{c}"], rtol=0, atol=1e-9)
    assert [e.body for e in two.events] == [e.body for e in one.events]


@pytest.mark.skipif("reference" not in METHODS, reason="needs the 2D reference solver")
def test_2d_tilted_second_order_against_the_reference():
    # Tilted 30 degrees: B hits, the impulse sets the dumbbell turning, then A hits (0.498 s).
    scene = load_scene(SCENES / "tilted-2d.toml")
    errs = {}
    for dt in (1e-3, 1e-4):
        run = simulate(scene, "verlet", dt=dt, t_end=0.8, every=1)
        truth = solver_class("reference").solve(scene, RunOptions(dt, 0.8),
                                                 estimate_error=False)
        assert [e.body for e in run.events] == [e.body for e in truth.events] == ["B", "A"]
        errs[dt] = max(np.max(np.hypot(run[f"x{c}"] - truth[f"x{c}"],
                                       run[f"y{c}"] - truth[f"y{c}"])) for c in "AB")
        assert relative_energy_error(run.energy).max() < 1e-3 * (dt / 1e-3) ** 2
    assert 1.8 < math.log10(errs[1e-3] / errs[1e-4]) < 2.2
    assert errs[1e-4] < 1e-5
