"""The piecewise-analytic solution against independent truth."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from dumbbell import simulate
from dumbbell.solvers.exact import segments
from tests.conftest import make_scene


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
