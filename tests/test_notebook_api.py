"""The notebook-friendly API: one-line repr, an HTML table, and pandas export."""

from __future__ import annotations

import sys

import numpy as np
import pytest

import dumbbell
from dumbbell.errors import MissingExtraError

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
    assert {units[c] for c in traj.columns} <= {"s", "m", "m/s", "J"}


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
