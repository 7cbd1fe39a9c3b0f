"""Verdicts on stiff and extreme scenes, against the theory: explicit spring steps are stable
iff w*dt < 2 (w = sqrt(k/mu)); pymunk lets a fast particle tunnel through the floor; an
inelastic floor brings a flip-rule solver to a stop with a verdict, not a hang."""

from __future__ import annotations

import csv
import math
import re
import shutil

import numpy as np
import pytest

from dumbbell.analysis.stability import find_cases, plan_cases, predict, rest_time
from dumbbell.cli import main
from dumbbell.model.scene import load_scene, scene_from_dict
from dumbbell.solvers import METHODS, simulate
from dumbbell.solvers.verdicts import seconds
from tests.conftest import SCENES, make_scene

EXTREME = SCENES / "extreme"
#: Solvers whose spring is an explicit step; each is tested once it is registered.
STEPPERS = ["euler-cromer", "pymunk", "verlet"]


def _need(solver: str) -> None:
    if solver not in METHODS:
        pytest.skip(f"solver {solver} is not registered yet")


def _stiff(ratio: float, w_dt: float):
    """The stiff no-floor case with mB/mA = ratio and dt set so that w*dt is ``w_dt``."""
    base = load_scene(EXTREME / "stiff-wdt-1.9.toml")
    mA = base.system.B.mass / ratio
    scene = base.with_values({"bodies.A.mass": mA})
    return scene.with_values({"run.dt": w_dt / scene.system.omega, "run.t_end": 400 * w_dt /
                              scene.system.omega})


@pytest.mark.parametrize("ratio", [1.0, 100.0])
@pytest.mark.parametrize("solver", STEPPERS)
def test_verdict_flips_between_wdt_1_9_and_2_1(solver, ratio):
    _need(solver)
    stable = simulate(_stiff(ratio, 1.9), solver)
    # Stable to the end, every sample kept; but the step swings the energy far past
    # run.inaccurate_energy, so the verdict says inaccurate, not ok.
    assert stable.verdict.status == "inaccurate", stable.verdict
    assert stable.verdict.complete and not stable.verdict.ok
    assert len(stable.t) == 401 and np.isfinite(stable["E"]).all()

    scene = _stiff(ratio, 2.1)
    blown = simulate(scene, solver)
    v = blown.verdict
    assert v.status == "unstable"
    # Stopped early, samples kept up to the failure, all of them finite.
    assert 0 < v.t < scene.run.t_end and len(blown.t) < 401
    assert blown.t[-1] <= v.t + 1e-12
    assert all(np.isfinite(col).all() for col in blown.state.values())
    limit = 2.0 / scene.system.omega
    assert "w*dt = 2.10 > 2" in v.reason
    assert f"stable only for dt < {seconds(limit)} s" in v.reason
    assert re.fullmatch(r"unstable at t = [0-9.e-]+ s: w\*dt = 2\.10 > 2 .*", str(v))


def test_the_stable_swing_is_the_theory_bound():
    """At w*dt = h < 2 Euler-Cromer's energy swings by up to h/(2-h) of the vibration energy,
    without growing: measured here from the stretched spring at rest."""
    for h in (1.0, 1.5, 1.9):
        traj = simulate(_stiff(1.0, h), "euler-cromer")
        E = traj["E"]
        swing = float(np.max(np.abs(E - E[0])) / E[0])
        assert swing == pytest.approx(METHODS["euler-cromer"].swing(h), rel=2e-3)


def test_default_threshold_names_the_swing_when_it_calls_a_stable_step_unstable():
    scene = _stiff(1.0, 1.9).with_values({"run.unstable_energy": 10.0})
    v = simulate(scene, "euler-cromer").verdict
    assert v.status == "unstable" and "w*dt = 1.90 < 2" in v.reason and "19" in v.reason


@pytest.mark.parametrize("solver,status", [("pymunk", "tunnelled"), ("exact", "ok"),
                                           ("euler-cromer", "ok")])
def test_high_drop_tunnels_only_in_pymunk(solver, status):
    _need(solver)
    scene = load_scene(EXTREME / "high-drop.toml")
    traj = simulate(scene, solver)
    assert traj.verdict.status == status, traj.verdict
    fall = math.sqrt(2 * scene.system.B.height / scene.system.g)
    if status == "tunnelled":
        # It goes through at the first impact, and the run stops there.
        assert fall <= traj.verdict.t <= fall + 3 * scene.run.dt
        assert traj.t[-1] <= traj.verdict.t + 1e-12
        assert "below the floor" in traj.verdict.reason
    else:
        assert traj.first_impact("B").t == pytest.approx(fall, abs=scene.run.dt)
    assert predict(scene, solver, scene.run.dt, scene.run.t_end).status == status


def test_inelastic_floor_ends_with_failed_not_tunnelled():
    """The textbook's flip rule cannot hold a particle at rest: a clear 'failed', near the
    time a point mass would come to rest, with the samples before it kept."""
    scene = make_scene({"floor.elasticity": 0.8, "run.t_end": 6.0, "run.dt": 1e-4})
    for solver in ("euler-cromer", "exact"):
        traj = simulate(scene, solver, every=10)
        v = traj.verdict
        assert v.status == "failed" and ("came to rest" in v.reason or "stays on the floor" in v.reason)
        assert 0.6 * rest_time(scene) < v.t < 1.1 * rest_time(scene)
        assert traj.t[-1] <= v.t + 1e-12


def test_long_horizon_drain_is_named():
    """Over 1000 s at dt = 1e-4 s the textbook's impacts drain the elastic dumbbell's energy
    until B rests on the floor: a 'failed' verdict that says so, not a false 'tunnelled'."""
    scene = load_scene(EXTREME / "long-horizon.toml")
    traj = simulate(scene, "euler-cromer")
    v = traj.verdict
    assert v.status == "failed" and "drained the energy" in v.reason
    assert 500 < v.t < scene.run.t_end
    E = traj["E"]
    assert E[-1] < 0.5 * E[0]  # the drain the message reports is real
    assert predict(scene, "euler-cromer", scene.run.dt, scene.run.t_end).status == "ok"


def test_predictions_of_the_catalogue():
    expect = {"stiff-wdt-1.9": "inaccurate", "stiff-wdt-2.1": "unstable", "high-drop": "tunnelled",
              "inelastic-floor": "failed"}
    for name, status in expect.items():
        scene = load_scene(EXTREME / f"{name}.toml")
        solver = "pymunk" if name == "high-drop" else "euler-cromer"
        assert predict(scene, solver, scene.run.dt, scene.run.t_end).status == status
        assert predict(scene, "exact", scene.run.dt, scene.run.t_end).status == (
            "failed" if name == "inelastic-floor" else "ok")


def test_every_catalogue_scene_loads_and_says_what_it_tests():
    paths = find_cases(EXTREME)
    assert len(paths) >= 12
    for path in paths:
        scene = load_scene(path)
        assert path.read_text().startswith("# Tests:"), path.name
        assert scene.title
    runs, _ = plan_cases(paths, None)
    assert {cls.name for _, cls in runs} >= {"euler-cromer", "exact"}


def test_stability_command_writes_table_csv_and_map(tmp_path, capsys):
    cases = tmp_path / "cases"
    cases.mkdir()
    for name in ("stiff-wdt-1.9", "stiff-wdt-2.1", "inelastic-floor"):
        shutil.copy(EXTREME / f"{name}.toml", cases)
    out = tmp_path / "out"
    assert main(["stability", "--cases", str(cases), "--solvers", "euler-cromer", "exact",
                 "--out", str(out), "--workers", "1", "-q"]) == 0
    rows = list(csv.DictReader((out / "stability.csv").open()))
    assert len(rows) == 6
    got = {(r["case"], r["solver"]): r for r in rows}
    assert got[("stiff-wdt-2.1", "euler-cromer")]["verdict"] == "unstable"
    assert float(got[("stiff-wdt-2.1", "euler-cromer")]["t_fail"]) < 0.05
    assert got[("stiff-wdt-1.9", "euler-cromer")]["verdict"] == "inaccurate"
    assert float(got[("stiff-wdt-1.9", "euler-cromer")]["inaccurate_energy"]) == 0.1
    assert float(got[("stiff-wdt-1.9", "euler-cromer")]["max_rel_energy_error"]) == (
        pytest.approx(19, rel=0.01))
    assert float(got[("stiff-wdt-2.1", "exact")]["max_rel_energy_error"]) < 1e-12
    assert all(r["agreement"] == "agrees" for r in rows)
    table = (out / "stability.md").read_text()
    assert table.startswith("| case |") and "w*dt = 2.10 > 2" in table
    assert (out / "stability-map.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(out.glob(".*part*"))


@pytest.mark.parametrize("flags,word", [
    (["--cases", "/nonexistent/dir"], "--cases"),
    (["--solvers", "nope"], "nope"),
    (["--workers", "0"], "--workers"),
])
def test_stability_bad_flags(tmp_path, capsys, flags, word):
    out = tmp_path / "out"
    assert _exit(["stability", *flags, "--out", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and word in err
    assert not out.exists()


def _exit(argv: list[str]) -> int:
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code)


@pytest.mark.parametrize("solver", sorted(METHODS))
def test_every_solver_ends_a_blow_up_with_a_verdict(solver):
    """Every registered solver, on the stiff case in 1D or 2D (whichever it runs) at
    w*dt = 2.1: a time-stepper stops early with 'unstable', keeping only finite samples up to
    the failure; a solver without a step limit stays ok."""
    from dumbbell.solvers import solver_class

    one_d = _stiff(1.0, 2.1).with_values({"run.t_end": 100 * 2.1e-3})
    raw = one_d.to_dict()
    del raw["bodies"]["A"]["height"]
    for body in raw["bodies"].values():  # a 1D velocity is the vertical one
        body["velocity"] = [0.0, body["velocity"]]
    two_d = scene_from_dict({**raw, "dimensions": 2, "tilt": 30.0}, source="stiff-2d.toml")
    scene = next((s for s in (one_d, two_d) if solver_class(solver).supports(s) is None),
                 None)
    if scene is None:
        pytest.skip(f"{solver} runs neither the 1D nor the 2D stiff case")
    traj = simulate(scene, solver)
    v = traj.verdict
    if solver in ("exact", "reference"):
        assert v.ok, v
        return
    assert v.status == "unstable" and "w*dt = 2.10 > 2" in v.reason, v
    assert len(traj.t) < 101 and traj.t[-1] <= v.t + 1e-12
    assert all(np.isfinite(col).all() for col in traj.state.values())


def test_every_report_column_has_a_unit():
    from dumbbell.analysis.stability import COLUMNS, UNITS

    assert set(UNITS) == set(COLUMNS)


@pytest.mark.parametrize("solver,scene", [
    ("euler-cromer", "textbook-1d"), ("verlet", "textbook-1d"), ("euler-cromer-2d", "tilted-2d"),
    ("verlet", "tilted-2d")])
def test_a_verdict_is_dated_at_its_step_whatever_the_sampling(solver, scene):
    """dt = 0.1 s is far past the step limit (w*dt = 6.3): the energy passes the scene's
    threshold within a few steps, long before the state overflows. Sampled every step, every
    7th, every 100th, or so sparsely that the state overflows before the first sample is
    kept, the verdict names the same step: the first whose energy error passes, computed
    here from the every-step run's own columns."""
    base = load_scene(SCENES / f"{scene}.toml").with_values({"run.dt": 0.1, "run.t_end": 30.0})
    full = simulate(base, solver, every=1)
    E = full["E"]
    err = np.abs(E - E[0]) / abs(E[0])
    first = int(np.flatnonzero(err > base.run.unstable_energy)[0])
    assert full.verdict.status == "unstable" and full.verdict.t == full.t[first]
    for every in (7, 100, 250):
        v = simulate(base, solver, every=every).verdict
        assert v.status == "unstable" and v.t == full.verdict.t, (every, v)
        assert v.reason == full.verdict.reason
