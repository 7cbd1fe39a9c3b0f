"""``dumbbell bench``: the work-precision numbers against independent computations."""

from __future__ import annotations

import csv
import json
import math
from dataclasses import replace

import numpy as np
import pytest

from dumbbell.analysis.bench import (
    CSV_COLUMNS,
    DEFAULT_DTS,
    BenchOptions,
    default_solvers,
    default_spacing,
    fit_order,
    run_bench,
)
from dumbbell.analysis.extended import extended_precision_exact
from dumbbell.cli import main
from dumbbell.io.bench import markdown, write_all
from dumbbell.model.scene import load_scene
from dumbbell.solvers import METHODS, simulate
from tests.conftest import SCENES, make_scene

TEXTBOOK = str(SCENES / "textbook-1d.toml")
#: The grid of the order fits: [0, 1 s] (two impacts), half-decades 1e-3..1e-5 s.
FIT_DTS = [1e-3, 3.16e-4, 1e-4, 3.16e-5, 1e-5]


@pytest.fixture(scope="module")
def one_second():
    """Euler-Cromer and verlet on the fit grid, 1 s simulated, window [0, 1 s]."""
    scene = make_scene({"run.t_end": 1.0})
    return run_bench(scene, BenchOptions(solvers=["euler-cromer", "verlet"], dts=FIT_DTS,
                                         window=1.0, repeat=1))


def test_defaults():
    assert DEFAULT_DTS == (1e-3, 3.16e-4, 1e-4, 3.16e-5, 1e-5, 3.16e-6, 1e-6)
    names = default_solvers(make_scene())
    assert {"euler-cromer", "verlet"} <= set(names) and "exact" not in names


def test_fitted_orders(one_second):
    # Euler-Cromer flips velocities up to a step late: first order. Verlet with located
    # impacts keeps its second order through the two impacts of the first second.
    assert 0.7 < one_second.fits["euler-cromer"].order < 1.4
    assert 1.7 < one_second.fits["verlet"].order < 2.3
    assert len(one_second.fits["verlet"].dts) == len(FIT_DTS)


def test_error_equals_an_independent_computation(one_second):
    dt = 1e-4
    point = next(p for p in one_second.points if p.solver == "euler-cromer" and p.dt == dt)
    assert point.every == 10  # samples every 1 ms, the textbook run's output
    ec = simulate(make_scene(), "euler-cromer", dt=dt, t_end=1.0, every=10)
    ex = simulate(make_scene(), "exact", dt=dt, t_end=1.0, every=10)
    expected = max(np.max(np.abs(ec["xA"] - ex["xA"])), np.max(np.abs(ec["xB"] - ex["xB"])))
    assert point.error == pytest.approx(expected, rel=1e-12)
    # Every step instead of every 10th: the sampled maximum misses little.
    ec1 = simulate(make_scene(), "euler-cromer", dt=dt, t_end=1.0, every=1)
    ex1 = simulate(make_scene(), "exact", dt=dt, t_end=1.0, every=1)
    every_step = max(np.max(np.abs(ec1[c] - ex1[c])) for c in ("xA", "xB"))
    assert expected <= every_step < 1.01 * expected
    # The impact times: Euler-Cromer flips at the end of the step that crossed the floor.
    late = max(abs(a.t - b.t) for a, b in zip(ec.events, ex.events, strict=False))
    assert point.impact_time_error == pytest.approx(late, rel=1e-12)
    assert point.impacts_truth == point.impacts_compared == 2
    assert 0 < late < dt  # late by up to one step (plus the drift of the motion)
    energy = np.abs(ec["E"] - ec["E"][0]).max() / abs(ec["E"][0])
    assert point.energy_error == pytest.approx(energy, rel=1e-12)


def test_sample_spacing_follows_the_spring():
    assert default_spacing(make_scene()) == 1e-3  # period 0.099 s
    stiff = make_scene({"spring.stiffness": 2e4})  # period 9.9 ms
    assert default_spacing(stiff) == pytest.approx(2 * math.pi / stiff.system.omega / 50)


def test_textbook_accuracy_over_two_seconds():
    # docs/physics.md: Euler-Cromer at dt = 1e-5 is about 2e-3 m off the exact solution by 2 s.
    result = run_bench(make_scene({"run.t_end": 2.0}),
                       BenchOptions(solvers=["euler-cromer"], dts=[1e-5], repeat=1))
    point = result.points[0]
    assert point.every == 100 and point.window == 2.0
    assert 1e-3 < point.error < 4e-3
    sp = result.speedups()
    assert sp["target_error"] == point.error and sp["seconds"]["euler-cromer"] == point.seconds
    exact = result.points[-1]
    assert exact.solver == "exact" and exact.dt is None
    assert exact.error < 1e-12 and exact.impact_time_error < 1e-14
    assert exact.seconds > 0 and math.isfinite(exact.seconds_median)


def test_extended_precision_check_sees_a_wrong_solution():
    traj = simulate(make_scene(), "exact", dt=1e-3, t_end=1.0)
    assert extended_precision_exact(traj, 1.0)[0] < 1e-12
    traj = replace(traj, state=dict(traj.state, xB=traj.state["xB"] + 1e-9 * (traj.t > 0.7)),
                   energy=None)
    assert extended_precision_exact(traj, 1.0)[0] == pytest.approx(1e-9, rel=1e-3)


def test_failed_runs_are_kept_and_slow_steps_skipped(tmp_path):
    # k = 2e4 N/m: w = 632 rad/s, so dt = 4e-3 s is past w*dt = 2 and blows up.
    scene = make_scene({"spring.stiffness": 2e4, "run.t_end": 0.5})
    result = run_bench(scene, BenchOptions(solvers=["euler-cromer"], dts=[4e-3, 1e-3, 1e-4],
                                           window=0.5, repeat=1, budget=1e-9))
    rows = {p.dt: p for p in result.points if p.dt is not None}
    assert rows[4e-3].verdict == "unstable" and math.isinf(rows[4e-3].error)
    # The first point that ran sets the cost per step: stable (w*dt = 0.63) but its energy
    # swings past 0.1, so it is inaccurate, its errors measured like an ok point's.
    assert rows[1e-3].verdict == "inaccurate" and rows[1e-3].complete
    assert math.isfinite(rows[1e-3].error)
    # A skipped step has no verdict (it did not run); the tables print "skipped" for it.
    assert rows[1e-4].verdict is None and not rows[1e-4].ran and "budget" in rows[1e-4].reason
    assert rows[1e-4].status == "skipped" and rows[1e-3].status == "inaccurate"
    assert fit_order(result.points) is None
    write_all(result, tmp_path)
    table = markdown(result)
    assert "**unstable**" in table and "**skipped**" in table
    data = json.loads((tmp_path / "bench-test.json").read_text())
    assert data["points"][0]["error"] == "inf"
    stepped = ["unstable", "inaccurate", "skipped"]  # the three dt, in order; then the truth's
    assert [p["verdict"] for p in data["points"] if p["dt"] is not None] == stepped
    csv_rows = list(csv.DictReader((tmp_path / "bench-test.csv").read_text().splitlines()))
    assert [r["verdict"] for r in csv_rows if r["dt"]] == stepped


def test_cli_writes_every_output(tmp_path):
    out = tmp_path / "b"
    assert main(["bench", TEXTBOOK, "--out", str(out), "--solvers", "euler-cromer", "verlet",
                 "--dts", "1e-3", "1e-4", "--t-end", "0.6", "--window", "0.6",
                 "--repeat", "2", "-q"]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == [f"bench-textbook-1d{s}" for s in
                     ("-convergence.png", "-work-precision.png", ".csv", ".json", ".md")]
    rows = list(csv.DictReader((out / "bench-textbook-1d.csv").open()))
    assert tuple(rows[0]) == CSV_COLUMNS
    assert [r["solver"] for r in rows] == ["euler-cromer"] * 2 + ["verlet"] * 2 + ["exact"]
    for r in rows:
        assert float(r["seconds"]) > 0 and float(r["error"]) >= 0
        # The solver's own clock lies inside the timed call: min(own) <= min(call).
        assert float(r["seconds"]) <= float(r["seconds_median"])
        assert float(r["seconds"]) <= float(r["seconds_call"])
        assert r["verdict"] == "ok" and int(r["repeat"]) >= 2
    for png in out.glob("*.png"):
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("flags, message", [
    (["--solvers", "nosuch"], "nosuch"),
    (["--window", "5", "--t-end", "1"], "--window"),
    (["--dts", "-1"], "--dts"),
    (["--repeat", "0"], "--repeat"),
])
def test_bad_flags_write_nothing(tmp_path, capsys, flags, message):
    out = tmp_path / "b"
    try:
        status = main(["bench", TEXTBOOK, "--out", str(out), *flags, "-q"])
    except SystemExit as exc:  # argparse's own checks
        status = exc.code
    assert status == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_time_for_an_error_interpolates_in_log_log():
    from dumbbell.analysis.bench import time_for_error

    line = [(1.0, 1e-2), (10.0, 1e-4), (100.0, 1e-6)]
    assert time_for_error(line, 1e-3) == pytest.approx(10**0.5)
    assert time_for_error(line, 1e-2) == pytest.approx(1.0)
    assert time_for_error(line, 1e-7) is None


@pytest.mark.skipif("reference" not in METHODS, reason="needs the 2D reference solver")
def test_2d_scene_uses_the_reference_as_truth():
    scene = load_scene(SCENES / "tilted-2d.toml")
    result = run_bench(scene, BenchOptions(solvers=["verlet"], dts=[1e-3, 1e-4], window=0.5,
                                           t_end=0.5, repeat=1))
    assert result.truth == "reference"
    coarse, fine, truth = result.points
    assert truth.solver == "reference" and truth.truth == "self"
    assert 0 < truth.error < 1e-8  # its own estimate, from a run at 10x tighter tolerance
    assert 80 < coarse.error / fine.error < 120  # verlet stays second order in 2D
    assert fine.impacts_truth == fine.impacts_compared == 2


def test_every_csv_column_has_a_unit():
    from dumbbell.analysis.bench import CSV_UNITS

    assert set(CSV_UNITS) == set(CSV_COLUMNS)


def test_the_table_counts_its_runs_and_times_share_one_precision(one_second):
    """Issue 29: "at least 1 runs", and a JIT line that mixed precisions ("0.03 s; verlet
    0.0192 s"). The table and every line after it write times alike: three significant
    digits, trailing zeros kept, in the unit that suits them."""
    euler, verlet = (next(p for p in one_second.points if p.solver == name)
                     for name in ("euler-cromer", "verlet"))
    points = [replace(euler, compile_seconds=0.03), replace(verlet, compile_seconds=0.0192)]
    once = replace(one_second, points=points, repeat=1)
    table = markdown(once)
    assert "at least 1 run after a warm-up" in table and "1 runs" not in table
    assert "euler-cromer 30.0 ms; verlet 19.2 ms (the first numba solver" in table
    assert "at least 3 runs" in markdown(replace(once, repeat=3))
