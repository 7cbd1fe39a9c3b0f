"""The piecewise-analytic solution against independent truth."""

from __future__ import annotations

import itertools
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from dumbbell import simulate
from dumbbell.model.scene import load_scene
from dumbbell.solvers.exact import segments
from dumbbell.solvers.exact_rigid import flight
from tests.conftest import SCENES, make_scene


def test_first_impact_at_the_free_fall_time(textbook):
    traj = simulate(textbook, "exact", t_end=1.0, every=100)
    first = traj.first_impact()
    assert first.body == "B"
    assert first.t == pytest.approx(math.sqrt(2 * 1.0 / 9.8), abs=1e-12)
    assert first.v_before == pytest.approx(-math.sqrt(2 * 9.8 * 1.0), rel=1e-12)
    assert first.v_after == -first.v_before


def test_energy_is_constant_to_1e_12_over_ten_seconds(textbook):
    traj = simulate(textbook, "exact", every=10)
    E = traj["E"]
    assert E[0] == pytest.approx(2.156, rel=1e-15)
    assert np.abs(E - E[0]).max() / E[0] < 1e-12
    assert 15 <= len(traj.events) <= 40  # docs/physics.md: about 22 impacts in 10 s


def test_internal_energy_is_zero_until_the_first_impact(textbook):
    traj = simulate(textbook, "exact", t_end=1.0, every=10)
    before = traj.t < traj.events[0].t
    assert traj["K_int"][before].max() < 1e-28  # zero to rounding of 1.2 - 1.0 - 0.2


def test_centre_of_mass_falls_on_a_parabola_between_impacts(textbook):
    traj = simulate(textbook, "exact", t_end=4.0, dt=1e-4, every=1)
    X = 0.5 * (traj["xA"] + traj["xB"])
    # Before the first impact: X = X0 - g t^2 / 2 with X0 = 1.1 m.
    first = traj.events[0].t
    m = traj.t < first
    assert np.abs(X[m] - (1.1 - 4.9 * traj.t[m] ** 2)).max() < 1e-13
    # Between later impacts: a least-squares parabola fits to rounding, with curvature -g/2.
    times = [e.t for e in traj.events]
    checked = 0
    for t0, t1 in itertools.pairwise(times):
        m = (traj.t > t0) & (traj.t < t1)
        if m.sum() < 50:
            continue
        tau = traj.t[m] - t0
        coeffs = np.polyfit(tau, X[m], 2)
        assert coeffs[0] == pytest.approx(-4.9, rel=1e-9)
        assert np.abs(np.polyval(coeffs, tau) - X[m]).max() < 1e-11
        checked += 1
    assert checked >= 3


def test_impact_heights_are_on_the_floor(textbook):
    segs, events, verdict = segments(textbook, 10.0)
    assert verdict.ok
    for seg, event in zip(segs[1:], events, strict=True):
        assert seg.t0 == event.t
        xB = seg.X0 - 0.5 * (0.2 + seg.s0)
        xA = seg.X0 + 0.5 * (0.2 + seg.s0)
        assert abs(xB if event.body == "B" else xA) < 1e-12


@pytest.mark.parametrize("gap", [-1e-10, 1e-10])
def test_grazing_impacts_are_found_and_near_misses_are_not(gap):
    # Without gravity B oscillates about a fixed centre of mass; its lowest point is
    # hB - 0.1 m (A starts 0.1 m above B: the spring compressed by 0.1 m). With hB = 0.1 + gap
    # B skims the floor: into it by 1e-10 m, or past it 1e-10 m above, half a period later.
    scene = make_scene({"bodies.B.height": 0.1 + gap, "bodies.A.height": 0.2 + gap},
                       drop=("gravity",))
    half_period = math.pi / math.sqrt(200.0 / 0.05)
    traj = simulate(scene, "exact", t_end=3 * half_period, dt=1e-6, every=1)
    if gap < 0:
        first = traj.first_impact()
        assert first is not None and first.body == "B"
        assert first.t == pytest.approx(half_period, abs=1e-4)
        # The touch is tangential: the speed is that of a 1e-10 m dip, sqrt(2 a d).
        assert abs(first.v_before) < 1e-2
    else:
        assert traj.events == ()
    assert traj["xB"].min() > -2e-10


def test_no_floor_means_one_segment_and_no_impacts():
    scene = make_scene(drop=("floor",))
    segs, events, verdict = segments(scene, 10.0)
    assert len(segs) == 1 and events == [] and verdict.ok


def test_zero_gravity_is_pure_vibration():
    scene = make_scene({"bodies.A.height": 1.3, "bodies.A.velocity": 0.5}, drop=("gravity",))
    traj = simulate(scene, "exact", t_end=2.0, dt=1e-4, every=1)
    s = traj["xA"] - traj["xB"] - 0.2
    w = math.sqrt(200.0 / 0.05)
    # s(t) = s0 cos wt + (s0'/w) sin wt with s0 = 0.1 m and s0' = 0.5 m/s.
    assert np.abs(s - (0.1 * np.cos(w * traj.t) + 0.5 / w * np.sin(w * traj.t))).max() < 1e-13
    E = traj["E"]
    assert np.abs(E - E[0]).max() / E[0] < 1e-13


def test_inelastic_floor_loses_energy_at_each_impact():
    scene = make_scene({"floor.elasticity": 0.8})
    traj = simulate(scene, "exact", t_end=2.0, dt=1e-4, every=10)
    assert "E_lost" in traj.columns
    for ev in traj.events:
        assert ev.v_after == pytest.approx(-0.8 * ev.v_before, rel=1e-15)
    # E + E_lost = E(0) on every row, and E_lost only grows.
    assert np.allclose(traj["E"] + traj["E_lost"], traj["E"][0], rtol=0, atol=1e-13)
    assert np.all(np.diff(traj["E_lost"]) > -1e-12)
    assert traj["E_lost"][-1] > 0.3


# --- the compiled kernels reproduce the arithmetic they stand for, bit for bit -------------


@pytest.fixture(scope="module")
def kernels():
    from dumbbell.solvers.exact import warm_up
    from dumbbell.solvers.kernels import exact as compiled

    assert warm_up() >= 0  # compiled, or loaded from numba's cache
    return compiled


def _motion(kernels, k=200.0, mA=0.1, mB=0.1, b=0.2, g=9.8, e=1.0):
    M = mA + mB
    w = math.sqrt(k / (mA * mB / M))
    return kernels.Motion(g, w, w**2, mB / M, mA / M, b, e, 1e-14, 1e-13, 1e-9)


def test_kernel_hypot_is_pythons_math_hypot(kernels):
    # The C library's hypot, which numba would call, differs from Python's in the last bit
    # for about one pair in 400; the search's curvature bound must use Python's.
    rng = np.random.default_rng(1)
    x = rng.standard_normal(20_000) * 10.0 ** rng.uniform(-12, 12, 20_000)
    y = np.where(rng.random(20_000) < 0.3, x * rng.uniform(0.999, 1.001, 20_000),
                 rng.standard_normal(20_000) * 10.0 ** rng.uniform(-12, 12, 20_000))
    special = [0.0, -0.0, 5e-324, 1e-310, 2.2250738585072014e-308, 1e-200, 1.0, 3.0, 4.0,
               1e300, 1.7e308, math.inf, -math.inf, math.nan]
    pairs = [*zip(x.tolist(), y.tolist(), strict=True),
             *itertools.product(special, special)]
    differ = [(a, b) for a, b in pairs
              if repr(kernels.hypot(a, b)) != repr(math.hypot(a, b))]
    assert differ == []


def test_kernel_brentq_is_scipys_brentq(kernels, textbook):
    from scipy.optimize import brentq

    m = _motion(kernels)
    rng = np.random.default_rng(2)
    segs, events, _ = segments(textbook, 10.0)
    checked = 0
    for seg, event in zip(segs, events, strict=False):
        row = np.array([seg.t0, seg.X0, seg.V0, seg.s0, seg.sd0])
        body = 0 if event.body == "A" else 1
        root = event.t - seg.t0

        def height(tau, row=row, body=body):
            return kernels._height(row, body, tau, m)[0]

        for _ in range(20):
            # Brackets from wide to a few ulps, each side of the impact.
            lo = max(root - 10.0 ** rng.uniform(-9, -1.5), 0.0)
            hi = root + 10.0 ** rng.uniform(-9, -2.5)
            if not (height(lo) > 0 > height(hi)):
                continue
            ours, ok = kernels.brentq_fall((row, body, m), lo, hi, 1e-14)
            theirs = brentq(height, lo, hi, xtol=1e-14, rtol=4 * np.finfo(float).eps)
            assert ok and ours.hex() == theirs.hex(), (lo, hi)
            checked += 1
    assert checked > 200
    # No sign change: scipy refuses, and so does the kernel.
    row = np.array([0.0, 1.1, 0.0, 0.0, 0.0])
    assert not kernels.brentq_fall((row, 1, m), 0.0, 0.1, 1e-14)[1]


@pytest.mark.parametrize("k", [200.0, 0.0])
def test_kernel_samples_are_the_closed_form_as_numpy_evaluates_it(kernels, k):
    m = _motion(kernels, k=k if k else 1.0)
    if not k:
        m = m._replace(w=0.0, w2=0.0)
    rng = np.random.default_rng(3)
    starts = np.sort(rng.uniform(0, 5, 8))
    starts[0] = 0.0
    rows = np.column_stack([starts, rng.uniform(0, 2, 8), rng.uniform(-5, 5, 8),
                            rng.uniform(-0.1, 0.1, 8), rng.uniform(-3, 3, 8)])
    t = np.sort(np.concatenate([rng.uniform(0, 6, 3000), starts]))
    got = kernels.sample(rows, t, m)
    # Each time belongs to the last segment that starts at or before it.
    owner = np.searchsorted(starts, t, side="right") - 1
    t0, X0, V0, s0, sd0 = (rows[owner, c] for c in range(5))
    tau = t - t0
    X = X0 + V0 * tau - 0.5 * m.g * tau * tau
    V = V0 - m.g * tau
    if k:
        cos, sin = np.cos(m.w * tau), np.sin(m.w * tau)
        s, sd = s0 * cos + (sd0 / m.w) * sin, -s0 * m.w * sin + sd0 * cos
    else:
        s, sd = s0 + sd0 * tau, sd0 + 0.0 * tau
    want = [X + m.cA * (m.b + s), V + m.cA * sd, X - m.cB * (m.b + s), V - m.cB * sd]
    for c in range(4):
        assert np.array_equal(got[c], want[c]), c


def test_rigid_samples_are_the_closed_form_as_numpy_evaluates_it(kernels):
    rng = np.random.default_rng(4)
    starts = np.sort(rng.uniform(0, 5, 6))
    starts[0] = 0.0
    rows = np.column_stack([starts, *(rng.uniform(-3, 3, (6, 6)).T)])  # t X Y VX VY theta omega
    t = np.sort(rng.uniform(0, 6, 2000))
    arm_a, arm_b, g = 0.12, -0.08, 9.8
    got = kernels.rigid_sample(rows, t, arm_a, arm_b, g)
    owner = np.searchsorted(starts, t, side="right") - 1
    t0, X0, Y0, VX, VY0, theta, omega = (rows[owner, c] for c in range(7))
    tau = t - t0
    X, Y = X0 + VX * tau, Y0 + VY0 * tau - 0.5 * g * tau * tau
    VY = VY0 - g * tau
    cos, sin = np.cos(theta + omega * tau), np.sin(theta + omega * tau)
    want = [col for a in (arm_a, arm_b) for col in (
        X + a * cos, Y + a * sin, VX - omega * a * sin + 0.0 * tau, VY + omega * a * cos)]
    for c in range(8):
        assert np.array_equal(got[c], want[c]), c
    assert np.array_equal(got[8], omega)


def test_the_compiled_searches_give_the_floats_of_their_source_run_by_python(textbook):
    # The same kernels interpreted by Python (numba disabled): math.cos, math.sqrt and float
    # arithmetic in the source's order. Compiling must not change one bit of an impact, in 1D
    # or for the rigid dumbbell.
    rigid = load_scene(SCENES / "rigid-2d.toml")
    code = ("import json; from dumbbell.model.scene import load_scene; "
            "from dumbbell.solvers.exact import segments; "
            "from dumbbell.solvers.exact_rigid import flight; "
            "from tests.test_exact import _hexed; "
            f"print(json.dumps([_hexed(segments(load_scene({str(textbook.source)!r}), 2.5)), "
            f"_hexed(flight(load_scene({str(rigid.source)!r}), 4.0))]))")
    interpreted = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                 check=True, cwd=Path(__file__).parent.parent,
                                 env={**os.environ, "NUMBA_DISABLE_JIT": "1"}).stdout
    compiled = [_hexed(segments(textbook, 2.5)), _hexed(flight(rigid, 4.0))]
    assert len(compiled[0]) > 8 and len(compiled[1]) > 8
    assert json.loads(interpreted) == compiled


def _hexed(found):
    """Segments, impacts and verdict of a search as exact strings (floats in hex)."""
    segs, events, verdict = found
    return ([[x.hex() for x in vars(g).values()] for g in segs]
            + [[i.t.hex(), i.body, i.v_before.hex(), i.v_after.hex(), repr(i.heat)]
               for i in events]
            + [str(verdict)])
