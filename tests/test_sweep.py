"""``dumbbell sweep``: grids, bounds, the blow-up boundary against w*dt = 2, and the same CSV
from every backend."""

from __future__ import annotations

import csv
import math

import pytest

from dumbbell.analysis.sweep import SweepOptions, parse_axis, plan, run_sweep
from dumbbell.cli import main
from dumbbell.errors import UsageError
from dumbbell.io.sweep import csv_text
from dumbbell.model.scene import load_scene
from tests.conftest import SCENES

TEXTBOOK = str(SCENES / "textbook-1d.toml")
STIFF = SCENES / "extreme" / "stiff-wdt-1.9.toml"


def _exit(argv: list[str]) -> int:
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code)


def test_axis_specs():
    a = parse_axis("k=log:1e2:1e7:6")
    assert a.key == "spring.stiffness" and a.spacing == "log"
    assert a.values == pytest.approx((1e2, 1e3, 1e4, 1e5, 1e6, 1e7), rel=1e-12)
    b = parse_axis("bodies.A.mass=lin:0.1:0.3:3")
    assert b.key == "bodies.A.mass" and b.values == pytest.approx((0.1, 0.2, 0.3))
    c = parse_axis("dt=1e-4,2e-4, 5e-4")
    assert c.key == "run.dt" and c.values == (1e-4, 2e-4, 5e-4) and c.spacing == "list"
    assert parse_axis("run.every=1,10").values == (1, 10)


@pytest.mark.parametrize("text", [
    "k", "k=", "=log:1:2:3", "k=log:1:2", "k=log:0:10:5", "k=log:1:10:1", "k=log:1:10:x",
    "k=lin:1:1:4", "k=log:1:nan:4", "k=1,,2", "k=1,1", "k..x=1,2", "k=log:1:10:100000",
])
def test_bad_axis_specs_are_one_line_errors(text):
    with pytest.raises(UsageError) as info:
        parse_axis(text)
    # The library names its parameter; the command line says --grid instead.
    assert str(info.value).startswith("grid") and info.value.param == "grid"
    assert "\n" not in str(info.value)


def test_stiff_sweep_blows_up_where_theory_says():
    """No floor, so only the spring counts: at every k the largest dt that stays stable and
    the smallest that fails straddle the theory's 2/w (grid steps of 12%). The stable points
    are ok or, where the step's swing passes run.inaccurate_energy, inaccurate."""
    scene = load_scene(STIFF)
    axes = [parse_axis("k=log:1e3:1e5:3"), parse_axis("dt=log:1e-4:1e-1:60")]
    result = run_sweep(scene, axes, SweepOptions("euler-cromer", t_end=1.0, workers=1))
    rows = result.boundary()
    assert len(rows) == 3
    for row in rows:
        assert row["largest_ok_dt"] < row["theory_dt"] <= row["first_failing_dt"]
        assert 1.7 < row["w_dt"] < 2.0
    for r in result.rows:
        assert (r.verdict in ("ok", "inaccurate")) == (r.w_dt < 2.0), r
        assert (r.verdict == "inaccurate") == (0.1 < r.max_rel_energy_error <= 100), r


def test_absurd_grid_is_refused_before_anything_runs(tmp_path, capsys):
    out = tmp_path / "out"
    code = _exit(["sweep", TEXTBOOK, "--grid", "dt=1e-9,1e-8", "--t-end", "10", "--out",
                  str(out), "-q"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "steps" in err and "1e+10" in err
    assert not out.exists()


def test_sweep_writes_csv_and_map(tmp_path):
    out = tmp_path / "out"
    assert main(["sweep", TEXTBOOK, "--grid", "k=log:1e2:1e5:4", "dt=log:1e-4:1e-2:4",
                 "--t-end", "0.5", "--out", str(out), "--workers", "1", "-q"]) == 0
    rows = list(csv.DictReader((out / "textbook-1d-sweep.csv").open()))
    assert len(rows) == 16
    assert list(rows[0])[:4] == ["spring.stiffness", "run.dt", "w_dt", "verdict"]
    for r in rows:
        w_dt = float(r["w_dt"])
        k, dt = float(r["spring.stiffness"]), float(r["run.dt"])
        assert w_dt == pytest.approx(math.sqrt(k / 0.05) * dt, rel=1e-12)
        if w_dt > 2.0:
            assert r["verdict"] == "unstable" and float(r["t_fail"]) < 0.5
    assert (out / "textbook-1d-sweep.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_same_csv_from_serial_pool_and_dask(tmp_path):
    """One process, a local pool of two and a Dask LocalCluster (through the command line, as
    a user would start it) write byte-identical CSVs."""
    pytest.importorskip("dask.distributed")
    scene = load_scene(TEXTBOOK)
    axes = [parse_axis("k=log:1e2:1e5:3"), parse_axis("dt=log:1e-4:3e-3:3")]
    serial = csv_text(run_sweep(scene, axes, SweepOptions("euler-cromer", 0.3, workers=1)))
    pooled = csv_text(run_sweep(scene, axes, SweepOptions("euler-cromer", 0.3, workers=2)))
    out = tmp_path / "dask"
    assert main(["sweep", TEXTBOOK, "--grid", "k=log:1e2:1e5:3", "dt=log:1e-4:3e-3:3",
                 "--t-end", "0.3", "--out", str(out), "-q", "--scheduler", "local",
                 "--workers", "2"]) == 0
    dask = (out / "textbook-1d-sweep.csv").read_text()
    assert serial == pooled == dask
    assert serial.count("\n") == 10 and ",unstable," in serial and ",ok," in serial


def test_missing_dask_is_one_line(tmp_path, capsys, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    out = tmp_path / "out"
    assert _exit(["sweep", TEXTBOOK, "--grid", "k=1e2,1e3", "--scheduler", "local", "--out",
                  str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "pip install 'dumbbell[dask]'" in err
    assert not out.exists()


@pytest.mark.parametrize("flags,word", [
    (["--grid", "k=log:1e2:1e7"], "--grid"),
    (["--grid", "nokey=1,2"], "nokey"),
    (["--grid", "k=-1,2"], "spring.stiffness"),
    (["--grid", "k=1,2", "dt=1,2", "bodies.A.mass=1,2"], "--grid"),
    (["--grid", "k=1,2", "k=3,4"], "same key"),
    (["--grid", "run.solver=exact,pymunk"], "--grid"),
    (["--grid", "k=1,2", "--workers", "0"], "--workers"),
    (["--grid", "k=1,2", "--t-end", "-1"], "--t-end"),
    (["--grid", "k=1,2", "--solver", "nope"], "nope"),
    (["--grid", "k=1,2", "--scheduler", "nowhere"], "--scheduler"),
    (["--grid", "k=1,2", "--scheduler", "tcp://x:1", "--workers", "2"], "--workers"),
])
def test_sweep_bad_flags(tmp_path, capsys, flags, word):
    out = tmp_path / "out"
    assert _exit(["sweep", TEXTBOOK, *flags, "--out", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and word in err
    assert not out.exists()


def test_plan_bounds_each_point():
    scene = load_scene(TEXTBOOK)
    with pytest.raises(UsageError, match="at most 1e\\+08"):
        plan(scene, [parse_axis("dt=1e-8,1e-3")], "euler-cromer", 10.0)
