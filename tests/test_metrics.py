"""The measures of :mod:`dumbbell.analysis.metrics`, against runs with a known offset, and
compare and bench reporting the same ones."""

from __future__ import annotations

import math

import numpy as np
import pytest

import dumbbell
from dumbbell import compare
from dumbbell.analysis.metrics import energy_error, position_error, position_error_series
from dumbbell.model.scene import load_scene
from dumbbell.model.trajectory import Trajectory
from dumbbell.solvers import simulate
from tests.conftest import SCENES, make_scene

TILTED = SCENES / "tilted-2d.toml"


def _offset(truth: Trajectory, shift: dict[str, np.ndarray], n: int | None = None
            ) -> Trajectory:
    """A copy of ``truth``'s first ``n`` samples with ``shift`` (m) added to some columns."""
    n = len(truth.t) if n is None else n
    state = {c: v[:n] + shift[c][:n] if c in shift else v[:n].copy()
             for c, v in truth.state.items()}
    return Trajectory(scene=truth.scene, solver="offset", t=truth.t[:n].copy(), state=state)


@pytest.fixture(scope="module")
def tilted_truth() -> Trajectory:
    return simulate(load_scene(TILTED), "reference", dt=1e-3, t_end=1.0, every=1)


def test_2d_position_error_is_the_distance_not_a_coordinate(tilted_truth):
    # A moves off along (3, 4) by 5c t, B along x by c t: the error is A's distance 5c t, not
    # the largest coordinate difference 4c t.
    t, c = tilted_truth.t, 1e-3
    run = _offset(tilted_truth, {"xA": 3 * c * t, "yA": 4 * c * t, "xB": -c * t})
    assert np.allclose(position_error_series(run, tilted_truth), 5 * c * t, rtol=1e-9,
                       atol=1e-15)
    window = 0.5
    last = t[t <= window + 1e-12][-1]
    assert position_error(run, tilted_truth, window) == pytest.approx(5 * c * last, rel=1e-9)
    # B further off than A: the larger of the two counts.
    run = _offset(tilted_truth, {"xA": 0 * t + 1e-4, "yB": 0 * t - 2e-4})
    assert np.allclose(position_error_series(run, tilted_truth), 2e-4, rtol=1e-9)


def test_a_run_that_stops_inside_the_window_has_an_infinite_error(tilted_truth):
    run = _offset(tilted_truth, {}, n=100)  # stops at 0.099 s
    assert len(position_error_series(run, tilted_truth)) == 100
    assert position_error(run, tilted_truth, 0.05) == 0.0
    assert position_error(run, tilted_truth, 0.5) == math.inf


def test_runs_sampled_at_other_times_are_refused(tilted_truth):
    other = simulate(load_scene(TILTED), "reference", dt=2e-3, t_end=1.0, every=1)
    with pytest.raises(ValueError, match="sample times"):
        position_error_series(other, tilted_truth)


def test_1d_position_error_is_the_height_difference():
    scene = make_scene({"run.t_end": 1.0})
    ec = simulate(scene, "euler-cromer", dt=1e-4, t_end=1.0, every=10)
    ex = simulate(scene, "exact", dt=1e-4, t_end=1.0, every=10)
    expected = np.maximum(np.abs(ec["xA"] - ex["xA"]), np.abs(ec["xB"] - ex["xB"]))
    assert np.array_equal(position_error_series(ec, ex), expected)


def test_compare_reports_the_measures_bench_reports():
    scene = load_scene(TILTED)
    result = compare(scene, solvers=["euler-cromer-2d"], dts=[1e-4], window=0.5, t_end=0.5)
    row, truth = result.rows[0], result.truth
    # Independent: A's and B's distances from the truth, and E's drift from E(0).
    dist = np.maximum(np.hypot(row.traj["xA"] - truth["xA"], row.traj["yA"] - truth["yA"]),
                      np.hypot(row.traj["xB"] - truth["xB"], row.traj["yB"] - truth["yB"]))
    assert np.allclose(row.error, dist, rtol=1e-12, atol=0.0)
    assert row.window_error == pytest.approx(float(dist.max()), rel=1e-12)
    E = row.traj["E"]
    assert row.energy_error == pytest.approx(np.abs(E - E[0]).max() / abs(E[0]), rel=1e-12)
    bench = dumbbell.bench(scene, solvers=["euler-cromer-2d"], dts=[1e-4], window=0.5,
                           t_end=0.5, repeat=1, spacing=result.truth.t[1])
    point = bench.points[0]
    assert point.error == pytest.approx(row.window_error, rel=1e-9)
    assert point.energy_error == pytest.approx(row.energy_error, rel=1e-12)
    summary = result.summary()
    assert summary[1]["energy_error"] == row.energy_error
    # The truth's own drift is reported for it, as bench reports it.
    assert summary[0]["energy_error"] == energy_error(truth, None) < 1e-9
