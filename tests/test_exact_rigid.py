"""The rigid dumbbell's closed-form flight (the ``exact`` solver in 2D): impacts that cannot be
missed, grazing ones included, and the impulse law, against independent calculations."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from dumbbell.model.scene import load_scene, scene_from_dict
from dumbbell.solvers import simulate, solver_class
from dumbbell.solvers.exact_rigid import first_impact_state

from .conftest import SCENES


@pytest.fixture(scope="module")
def rigid():
    return load_scene(SCENES / "rigid-2d.toml")


@pytest.fixture(scope="module")
def rigid_run(rigid):
    return simulate(rigid, "exact", every=100)


def brute_force_impacts(mA, mB, L, g, e, rA, rB, vA, vB, count, scan=1e-5):
    """Impacts of a rigid dumbbell found by scanning each end's height on a fine grid and the
    impulse written with the 2D cross product (independent of the solver's code)."""
    M = mA + mB
    I = mA * mB / M * L * L
    R = (mA * np.asarray(rA) + mB * np.asarray(rB)) / M
    V = (mA * np.asarray(vA) + mB * np.asarray(vB)) / M
    d = np.asarray(rA) - np.asarray(rB)
    w = np.asarray(vA) - np.asarray(vB)
    th = math.atan2(d[1], d[0])
    om = (d[0] * w[1] - d[1] * w[0]) / (d @ d)
    arms = {"A": mB / M * L, "B": -mA / M * L}
    t0, out = 0.0, []
    while len(out) < count:
        def y(tau, a, R=R, V=V, th=th, om=om):
            return R[1] + V[1] * tau - 0.5 * g * tau**2 + a * np.sin(th + om * tau)
        grid = np.arange(2e-4, 5.0, scan)  # skip the end that just left the floor
        first = []
        for body, a in arms.items():
            below = np.flatnonzero(y(grid, a) <= 0)
            if below.size:
                j = below[0]
                first.append((brentq(y, grid[j - 1], grid[j], args=(a,), xtol=1e-15), body))
        tau, body = min(first)
        R = R + V * tau + np.array([0.0, -0.5 * g * tau**2])
        V = V + np.array([0.0, -g * tau])
        th += om * tau
        r = arms[body] * np.array([math.cos(th), math.sin(th)])  # contact point from R
        v_c = V + om * np.array([-r[1], r[0]])
        # J n with n = (0, 1): (1 + e) v_n / (1/M + (r x n)^2 / I)
        J = -(1 + e) * v_c[1] / (1 / M + r[0] ** 2 / I)
        V = V + np.array([0.0, J / M])
        om += r[0] * J / I
        t0 += tau
        out.append((t0, body))
    return out


def test_rigid_scene_never_below_floor_and_finds_the_fifth_impact(rigid, rigid_run):
    assert rigid_run.verdict.ok
    assert rigid_run.t[-1] == pytest.approx(10.0)
    assert min(rigid_run["yA"].min(), rigid_run["yB"].min()) >= -1e-9
    A, B = rigid.system.A, rigid.system.B
    truth = brute_force_impacts(A.mass, B.mass, rigid.system.rigid.length, rigid.system.g, 1.0,
                                (A.x, A.height), (B.x, B.height), (A.vx, A.vy), (B.vx, B.vy), 5)
    got = [(e.t, e.body) for e in rigid_run.events[:5]]
    assert [b for _, b in got] == [b for _, b in truth]
    np.testing.assert_allclose([t for t, _ in got], [t for t, _ in truth], rtol=0, atol=1e-9)
    assert got[4][1] == "B" and got[4][0] == pytest.approx(2.6800, abs=1e-4)


def test_first_impact_rotation(rigid_run):
    first = rigid_run.events[0]
    j = int(np.searchsorted(rigid_run.t, first.t)) + 1  # first sample after the impact
    assert rigid_run.state["omega"][j] == pytest.approx(-35.4175, abs=1e-4)
    assert rigid_run["K_rot"][j] == pytest.approx(1.2544, abs=1e-4)
    _, after = first_impact_state(30.0, 1.0)
    assert after.omega == pytest.approx(-35.4175, abs=1e-4)
    assert 0.5 * 0.1 * 0.1 / 0.2 * 0.2**2 * after.omega**2 == pytest.approx(1.2544, abs=1e-4)


def test_energy_is_kept_and_matches_the_reference_before_its_miss(rigid, rigid_run):
    E = rigid_run["E"]
    assert np.max(np.abs(E - E[0])) / E[0] < 1e-12
    ref = simulate(rigid, "reference", every=100, t_end=2.6)
    n = len(ref.t)
    err = max(np.max(np.abs(ref[c] - rigid_run[c][:n])) for c in ("xA", "yA", "xB", "yB"))
    assert err < 1e-6


def _graze_scene(gap: float, w: float = 1.0, g: float = 0.0, mA: float = 0.1, mB: float = 0.1,
                 phi0: float = 0.3, L: float = 0.2, vy: float = 0.0):
    """A dumbbell turning at ``w`` whose end A swings down to ``gap`` (m) above the floor at
    its lowest point (phi0 / w s later): the centre of mass at rest (g = 0) or thrown up at
    ``vy`` so that it is at its apex when A is lowest."""
    M = mA + mB
    a = mB / M * L
    t_low = phi0 / w
    th = -math.pi / 2 - phi0
    Y_low = a + gap
    Y0 = Y_low - vy * t_low + 0.5 * g * t_low**2 if vy else Y_low
    u = (math.cos(th), math.sin(th))
    aB = mA / M * L
    rA = (a * u[0], Y0 + a * u[1])
    rB = (-aB * u[0], Y0 - aB * u[1])
    vA = (-w * a * u[1], vy + w * a * u[0])
    vB = (w * aB * u[1], vy - w * aB * u[0])
    return scene_from_dict({
        "dimensions": 2,
        "bodies": {"A": {"mass": mA, "x": rA[0], "height": rA[1], "velocity": list(vA)},
                   "B": {"mass": mB, "x": rB[0], "height": rB[1], "velocity": list(vB)}},
        "rigid": {"length": L}, "floor": {"elasticity": 1.0}, "gravity": {"g": g},
        "run": {"t_end": 2 * t_low, "dt": 1e-3, "solver": "exact"},
    }), a, t_low


@pytest.mark.parametrize("w, mA", [(1.0, 0.1), (3.0, 0.3), (0.5, 0.05)])
def test_grazing_touch_is_found_and_near_miss_is_not(w, mA):
    # Normal speed at the crossing: v = w sqrt(2 a depth), so depth = v^2 / (2 a w^2).
    _, a, t_low = _graze_scene(0.0, w=w, mA=mA)
    depth = 1e-14 / (2 * a * w * w)
    scene, a, t_low = _graze_scene(-depth, w=w, mA=mA)
    run = simulate(scene, "exact")
    assert len(run.events) >= 1 and run.events[0].body == "A"
    assert run.events[0].v_before == pytest.approx(-1e-7, rel=0.05)
    assert run.events[0].t == pytest.approx(t_low, abs=1e-5)
    miss = simulate(_graze_scene(1e-9, w=w, mA=mA)[0], "exact")
    assert miss.events == () and miss.verdict.ok


def test_grazing_touch_under_gravity_is_found():
    # A turns fast while the centre of mass rises to its apex just as A passes its lowest
    # point: there y'' = a w^2 - g, so the depth for a 1e-7 m/s crossing is v^2 / (2 y'').
    w, phi0, g = 12.0, math.pi / 2, 9.8
    vy = g * phi0 / w
    _, a, _ = _graze_scene(0.0, w=w, g=g, vy=vy, phi0=phi0)
    depth = 1e-14 / (2 * (a * w * w - g))
    scene, _, t_low = _graze_scene(-depth, w=w, g=g, vy=vy, phi0=phi0)
    run = simulate(scene, "exact")
    assert run.events and run.events[0].body == "A"
    assert run.events[0].v_before == pytest.approx(-1e-7, rel=0.05)
    assert run.events[0].t == pytest.approx(t_low, abs=1e-5)
    miss = simulate(_graze_scene(1e-9, w=w, g=g, vy=vy, phi0=phi0)[0], "exact")
    assert miss.events == () and miss.verdict.ok


@pytest.mark.parametrize("tilt", [0.0, 10.0, 30.0, 55.0, 80.0])
@pytest.mark.parametrize("e", [0.0, 0.3, 1.0])
def test_effective_restitution_of_the_equal_mass_dumbbell(tilt, e):
    before, after = first_impact_state(tilt, e)
    s2 = math.sin(math.radians(tilt)) ** 2
    assert -after.VY / before.VY == pytest.approx((e - s2) / (1 + s2), abs=1e-9)


@pytest.mark.parametrize("mA, mB, tilt, e", [(0.1, 0.3, 25.0, 0.7), (0.5, 0.05, -40.0, 1.0),
                                             (0.2, 0.2, 140.0, 0.0)])
def test_impulse_law_with_unequal_masses(mA, mB, tilt, e):
    before, after = first_impact_state(tilt, e, mA=mA, mB=mB, length=0.3)
    M, L = mA + mB, 0.3
    I = mA * mB / M * L * L
    hit = "A" if after.hA == 0.0 else "B"
    a = mB / M * L if hit == "A" else -mA / M * L
    rx, ry = a * math.cos(before.theta), a * math.sin(before.theta)
    assert before.Y + ry == pytest.approx(0.0, abs=1e-12)
    v_n = [s.VY + s.omega * rx for s in (before, after)]
    assert v_n[1] == pytest.approx(-e * v_n[0], abs=1e-12)
    # Angular momentum about the contact point (frictionless: no horizontal impulse).
    L_c = [I * s.omega + M * (ry * s.VX - rx * s.VY) for s in (before, after)]
    assert L_c[1] == pytest.approx(L_c[0], abs=1e-12)
    assert after.VX == before.VX


def test_flat_landing_hits_both_ends_at_once():
    before, after = first_impact_state(90.0, 1.0)
    assert after.VY == pytest.approx(-before.VY, rel=1e-12)
    assert after.omega == pytest.approx(0.0, abs=1e-9)


def test_exact_runs_rigid_scenes_only_without_friction(rigid):
    exact = solver_class("exact")
    assert exact.supports(rigid) is None
    assert "friction" in exact.supports(rigid.with_values({"floor.friction": 0.5}))
    spring = load_scene(SCENES / "tilted-2d.toml")
    assert "reference" in exact.supports(spring)


def test_inelastic_floor_ends_failed_at_rest(rigid):
    run = simulate(rigid.with_values({"floor.elasticity": 0.5}), "exact", t_end=20.0)
    assert run.verdict.status == "failed" and "rest" in run.verdict.reason
    assert min(run["yA"].min(), run["yB"].min()) >= -1e-9


def test_bench_truth_point_checks_rigid_against_extended_precision(rigid_run):
    from dumbbell.analysis.extended import extended_precision_rigid

    err, t_err = extended_precision_rigid(rigid_run, 2.0)
    assert err < 1e-12 and t_err < 1e-12


def test_a_truth_that_misses_an_impact_ends_failed(rigid, textbook):
    from dumbbell.solvers import METHODS, RunOptions
    from dumbbell.solvers.verdicts import RawRun, judge

    # The DOP853 reference steps over the grazing swing of B at 2.68 s on the rigid scene.
    ref = simulate(rigid, "reference", every=100)
    assert ref.verdict.status == "failed" and ref.verdict.t == pytest.approx(2.68, abs=0.01)
    assert "below the floor" in ref.verdict.reason and "missed an impact" in ref.verdict.reason
    assert min(ref["yA"][:-1].min(), ref["yB"][:-1].min()) >= -1e-9
    # Any sample of any truth more than 1e-9 m below the floor ends the run there.
    for run in (simulate(textbook, "exact", every=100, t_end=2.0),
                simulate(rigid, "exact", every=100, t_end=2.0)):
        key = "x" if run.scene.system.dimensions == 1 else "y"
        j = len(run.t) // 3
        options = RunOptions(run.dt, 2.0, run.every)
        verdict, keep, energy = judge(METHODS["exact"], run.scene, options,
                                      RawRun(run.t, run.state, run.events, run.verdict))
        assert verdict.ok and keep == len(run.t)
        state = dict(run.state, **{f"{key}B": run.state[f"{key}B"].copy()})
        state[f"{key}B"][j] = -2e-9
        verdict, keep, energy = judge(METHODS["exact"], run.scene, options,
                                      RawRun(run.t, state, run.events, run.verdict))
        assert verdict.status == "failed" and verdict.t == run.t[j] and keep == j + 1
        assert all(len(col) == keep for col in energy.values())


def test_exact_and_exact_rigid_do_not_import_each_other():
    # exact runs the rigid scenes through exact_rigid; what both need lives in _closed_form,
    # so the dependency goes one way, at any level of the files (functions included).
    import ast

    import dumbbell.solvers

    def imported(name):
        path = Path(dumbbell.solvers.__file__).parent / f"{name}.py"
        found = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                found.add(("." * node.level) + (node.module or ""))
            elif isinstance(node, ast.Import):
                found.update(alias.name for alias in node.names)
        return found

    assert ".exact_rigid" in imported("exact")
    assert not {".exact", "dumbbell.solvers.exact", "..exact"} & imported("exact_rigid")
    assert not {"..exact", "dumbbell.solvers.exact"} & imported("kernels/exact")
