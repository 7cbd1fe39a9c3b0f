"""The notebook-friendly API: one-line repr, an HTML table, and pandas export."""

from __future__ import annotations

import sys

import numpy as np
import pytest

import dumbbell
from dumbbell.errors import MissingExtraError
from dumbbell.io.stability import markdown
from dumbbell.io.sweep import csv_text

from .conftest import SCENES


@pytest.fixture(scope="module")
def exact_run(textbook):
    return dumbbell.simulate(textbook, solver="exact", t_end=2.0, every=100)


@pytest.fixture(scope="module")
def unstable_run():
    scene = dumbbell.load_scene(SCENES / "extreme" / "stiff-wdt-2.1.toml")
    return dumbbell.simulate(scene, solver="euler-cromer")


def test_repr_is_one_line_with_the_summary(exact_run, unstable_run):
    for traj in (exact_run, unstable_run):
        text = repr(traj)
        assert "\n" not in text and len(text) < 300
        assert f"solver={traj.solver}" in text
        assert f"{len(traj)} samples" in text and f"{len(traj.events)} impacts" in text
        assert f"dt={traj.dt:g} s" in text
        assert f"t=0..{traj.t[-1]:g} s" in text
    assert repr(exact_run).endswith("verdict: ok>")
    assert "verdict: unstable at t = " in repr(unstable_run)


def test_html_shows_the_verdict_energies_and_impacts(exact_run, unstable_run):
    html = exact_run._repr_html_()
    assert "verdict:</b> ok" in html
    assert f"{exact_run['E'][0]:.6g}" in html and f"{exact_run['K_int'][-1]:.6g}" in html
    assert f"{exact_run.events[0].t:.6g}" in html
    bad = unstable_run._repr_html_()
    assert unstable_run.verdict.status == "unstable"
    assert "unstable at t = " in bad and "w*dt = 2.10" in bad


@pytest.mark.parametrize("scene_file, solver", [("textbook-1d.toml", "euler-cromer"),
                                                ("tilted-2d.toml", "verlet"),
                                                ("friction-2d.toml", "pymunk")])
def test_to_pandas_has_every_column_with_t_as_index(scene_file, solver):
    scene = dumbbell.load_scene(SCENES / scene_file)
    traj = dumbbell.simulate(scene, solver=solver, dt=1e-4, t_end=0.6, every=10)
    df = traj.to_pandas()
    assert df.index.name == "t"
    assert np.array_equal(df.index.to_numpy(), traj.t)
    assert list(df.columns) == traj.columns[1:]
    for name in traj.columns[1:]:
        assert np.array_equal(df[name].to_numpy(), traj[name]), name
    units = df.attrs["units"]
    assert units["t"] == "s" and units["xB"] == "m" and units["E"] == "J"
    assert set(units) == set(traj.columns)
    assert {units[c] for c in traj.columns} <= {"s", "m", "m/s", "J", "kg m^2/s"}


def test_to_pandas_without_pandas_names_the_extra(exact_run, monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)      # import pandas now fails
    with pytest.raises(MissingExtraError, match=r"pip install 'dumbbell\[pandas\]'"):
        exact_run.to_pandas()


def test_pandas_is_imported_only_by_to_pandas():
    import subprocess

    code = ("import sys, dumbbell; s = dumbbell.load_scene(sys.argv[1]);"
            "t = dumbbell.simulate(s, 'exact', t_end=0.5, every=100); repr(t); t._repr_html_();"
            "assert 'pandas' not in sys.modules; t.to_pandas(); assert 'pandas' in sys.modules")
    subprocess.run([sys.executable, "-c", code, str(SCENES / "textbook-1d.toml")], check=True)


def test_render_gif_without_a_path_returns_gif_bytes(textbook, tmp_path):
    import io

    from PIL import Image

    from dumbbell.animation.render import frame_count

    traj = dumbbell.simulate(textbook, solver="euler-cromer", t_end=1.2, every=100)
    options = {"fps": 10, "size": "320x180", "t_end": 1.2, "quiet": True}
    gif = dumbbell.render_gif(traj, **options)
    assert isinstance(gif, bytes) and gif[:6] == b"GIF89a"
    with Image.open(io.BytesIO(gif)) as image:
        assert image.format == "GIF" and image.size == (320, 180)
        assert image.n_frames == frame_count(1.2, 10) == 12
    # The same inputs give the same bytes, with or without a file.
    path = dumbbell.render_gif(traj, tmp_path / "a.gif", **options)
    assert path.read_bytes() == gif.data == bytes(gif)
    assert gif.save(tmp_path / "b.gif").read_bytes() == gif
    # A notebook shows it inline: the animation as HTML, its first frame as PNG.
    html = gif._repr_html_()
    assert html.startswith('<img src="data:image/gif;base64,')
    import base64

    assert base64.b64decode(html.split(",", 1)[1].split('"')[0]) == gif
    with Image.open(io.BytesIO(gif._repr_png_())) as first:
        assert first.format == "PNG" and first.size == (320, 180)
    assert "\n" not in repr(gif) and str(len(gif)) in repr(gif)


# --- the analyses from Python: typed, frozen results with to_pandas() -------------------------


def _frozen(result, field_name):
    import dataclasses

    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(result, field_name, None)


def test_compare_from_python(textbook):
    from dumbbell.analysis.compare import CompareOptions
    from dumbbell.analysis.compare import compare as analysis_compare

    result = dumbbell.compare(SCENES / "textbook-1d.toml", solvers=["euler-cromer", "verlet"],
                              dts=1e-4, window=1.0, t_end=1.2)
    _frozen(result, "rows")
    df = result.to_pandas()
    assert list(df.index) == ["exact", "euler-cromer", "verlet"]
    assert df.attrs["units"]["window_error"] == "m" and df.attrs["units"]["dt"] == "s"
    for row in result.rows:
        assert df.loc[row.label, "window_error"] == row.window_error
        assert df.loc[row.label, "impacts"] == len(row.traj.events)
        assert df.loc[row.label, "dt"] == 1e-4
    # Verlet is second order through impacts, Euler-Cromer first: far apart at the same dt.
    assert df.loc["verlet", "window_error"] < df.loc["euler-cromer", "window_error"] / 10
    assert np.isnan(df.loc["exact", "window_error"]) and np.isnan(df.loc["exact", "dt"])
    assert df.loc["exact", "verdict"] == "ok"
    impacts = result.impacts_to_pandas()
    assert list(impacts["truth_t"]) == [e.t for e in result.truth.events]
    # The analysis function takes the options as one record, and gives the same table.
    old = analysis_compare(textbook, CompareOptions(["euler-cromer", "verlet"], [1e-4], 1.0, 1.2))
    timing = ["wall_time", "steps_per_s", "warm_up"]
    assert old.to_pandas().drop(columns=timing).equals(df.drop(columns=timing))


def test_bench_from_python(textbook):
    result = dumbbell.bench(textbook, solvers=["euler-cromer"], dts=[1e-3, 1e-4], repeat=1,
                            t_end=1.0, window=1.0)
    _frozen(result, "points")
    df = result.to_pandas()
    assert len(df) == len(result.points) == 3          # two steps, then the truth
    assert list(df["solver"]) == ["euler-cromer", "euler-cromer", "exact"]
    for i, point in enumerate(result.points):
        assert df["error"][i] == point.error or np.isnan(point.error)
        assert df["seconds"][i] == point.seconds
    errors = df[df.solver == "euler-cromer"].set_index("dt")["error"]
    assert errors[1e-4] < errors[1e-3] / 3                # it converges
    assert df.attrs["units"]["error"] == "m" and df.attrs["units"]["seconds"] == "s"


def test_sweep_from_python(textbook):
    grid = {"k": [200.0, 5e4], "dt": "lin:1e-3:2.1e-3:2"}
    result = dumbbell.sweep(textbook, grid, t_end=0.3)
    _frozen(result, "rows")
    df = result.to_pandas()
    assert list(df.columns) == result.columns and len(df) == 4
    assert list(df["spring.stiffness"]) == [200.0, 200.0, 5e4, 5e4]
    # w = sqrt(k/mu) = 1000 rad/s at k = 5e4: dt = 2.1e-3 is past w*dt = 2.
    w_dt = df["w_dt"].to_numpy()
    assert np.allclose(w_dt[2:], [1.0, 2.1])
    assert df["verdict"][3] == "unstable" and df["verdict"][0] == "ok"
    same = dumbbell.sweep(textbook, ["k=200.0,50000.0", "dt=lin:1e-3:2.1e-3:2"], t_end=0.3)
    assert csv_text(same) == csv_text(result)
    with pytest.raises(dumbbell.UsageError, match="grid"):
        dumbbell.sweep(textbook, "k=1,2")


def test_stability_from_python(tmp_path):
    import shutil

    for name in ("stiff-wdt-1.9.toml", "stiff-wdt-2.1.toml"):
        shutil.copy(SCENES / "extreme" / name, tmp_path / name)
    result = dumbbell.stability(tmp_path, solvers=["euler-cromer", "exact"], workers=1)
    _frozen(result, "rows")
    df = result.to_pandas()
    assert len(df) == 4 and set(df["solver"]) == {"euler-cromer", "exact"}
    verdicts = dict(zip(zip(df["case"], df["solver"]), df["verdict"]))
    assert verdicts[("stiff-wdt-2.1", "euler-cromer")] == "unstable"
    assert verdicts[("stiff-wdt-1.9", "euler-cromer")] == "inaccurate"  # stable, 19x its energy
    assert verdicts[("stiff-wdt-2.1", "exact")] == "ok"
    assert result.disagreements == []
    row = next(r for r in result.rows if (r.case, r.solver) == ("stiff-wdt-2.1", "euler-cromer"))
    _frozen(row, "verdict")
    assert row.verdict == "unstable" and row.predicted == "unstable" and row.agrees
    assert "stiff-wdt-2.1" in markdown(result) and df.attrs["units"]["t_fail"] == "s"


def test_the_solvers_package_is_not_shadowed_by_a_function():
    # ``import dumbbell.solvers.exact`` must leave dumbbell.solvers.exact reachable.
    import dumbbell.solvers.exact

    assert dumbbell.solvers.exact.NAME == "exact"
    assert dumbbell.available_solvers() == list(dumbbell.solvers.METHODS)
