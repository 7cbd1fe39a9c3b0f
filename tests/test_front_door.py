"""The conventions a user expects at the front door: a cheap ``import dumbbell`` with lazy
submodules, ``python -m dumbbell``, ``--version``, one default output folder, refusals that
name what the user can change, warm run times in ``compare``, and one GIF per scene whichever
command draws it."""

from __future__ import annotations

import argparse
import csv
import importlib.metadata
import math
import re
import subprocess
import sys

import pytest

from dumbbell.cli import main
from dumbbell.cli.app import DEFAULT_OUT, build_parser, subcommands
from tests.conftest import SCENES
from tests.hostile import run_group

HEAVY = ("numpy", "matplotlib", "pymunk", "numba", "scipy", "pandas", "PIL", "imageio", "dask")


def _python(code: str, *flags: str) -> subprocess.CompletedProcess:
    done = run_group([sys.executable, *flags, "-c", code], text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    return done


def test_import_dumbbell_is_cheap_and_loads_nothing_heavy():
    # What `import dumbbell` loads, not how long it takes (a time is the machine's load: speed
    # lives in the benchmarks): nothing heavy, and a handful of modules (7 today, 2 of them
    # dumbbell's own).
    done = _python("import sys\nbefore = set(sys.modules)\nimport dumbbell\n"
                   f"print(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r})))\n"
                   "print(len(set(sys.modules) - before))")
    heavy, count = done.stdout.splitlines()
    assert heavy == "[]" and int(count) <= 20, done.stdout


def test_submodules_load_on_first_use():
    done = _python(
        "import sys, dumbbell\n"
        "assert 'dumbbell.plot' not in sys.modules and 'matplotlib' not in sys.modules\n"
        "assert callable(dumbbell.plot.kinetic) and callable(dumbbell.io.trajectory.write_csv)\n"
        "assert callable(dumbbell.spaces.energy) and 'pymunk' not in sys.modules\n"
        "assert dumbbell.analysis.compare.compare is not None\n"
        "assert dumbbell.simulate is dumbbell.solvers.simulate\n"
        "assert dumbbell.available_solvers()[0] == 'euler-cromer'\n"
        "names = dir(dumbbell)\n"
        "assert {'plot', 'io', 'spaces', 'analysis', 'simulate', '__version__'} <= set(names)\n"
        "assert set(dumbbell.__all__) <= set(names)\n"
        "assert 'trajectory' in dir(dumbbell.io) and 'bench' in dir(dumbbell.analysis)\n"
        "for bad in ('nope', 'Plot'):\n"
        "    try:\n"
        "        getattr(dumbbell, bad)\n"
        "    except AttributeError as exc:\n"
        "        assert bad in str(exc)\n"
        "    else:\n"
        "        raise SystemExit(bad)\n"
        "print('ok')")
    assert done.stdout.strip() == "ok"


def test_python_m_dumbbell_and_version():
    version = importlib.metadata.version("dumbbell")
    done = run_group([sys.executable, "-m", "dumbbell", "--version"], text=True)
    assert (done.returncode, done.stdout.strip()) == (0, f"dumbbell {version}")
    done = run_group([sys.executable, "-m", "dumbbell"], text=True)
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    import dumbbell

    assert dumbbell.__version__ == version


def test_every_output_folder_defaults_to_renders():
    folders = {}
    for name, sub in subcommands(build_parser()).items():
        for action in sub._actions:
            if action.dest == "out":
                folders[name] = action.default
                assert f"default: {DEFAULT_OUT}" in action.help
            if action.dest == "output" and name == "render":
                assert f"default: {DEFAULT_OUT}/" in action.help
    assert DEFAULT_OUT == "renders"
    assert set(folders) == {"run", "compare", "bench", "stability", "sweep", "restitution"}
    assert set(folders.values()) == {"renders"}
    assert isinstance(build_parser(), argparse.ArgumentParser)


@pytest.mark.parametrize("flags,flag", [(["--max-frames", "10"], "--max-frames"),
                                        (["--max-samples", "10"], "--max-samples"),
                                        (["--all", "--max-frames", "10"], "--max-frames")])
def test_a_packaged_scene_is_refused_naming_only_flags(tmp_path, capsys, flags, flag):
    from dumbbell.model.scene import packaged_scene

    assert main(["run", "--out", str(tmp_path), *flags]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the packaged scene textbook-1d" in err and flag in err
    # Not the file inside the installation, nor its keys: the user cannot edit them there.
    assert str(packaged_scene()) not in err and "site-packages" not in err
    assert "outputs.gif" not in err and "run.every" not in err
    assert list(tmp_path.iterdir()) == []


def test_compare_times_warm_runs_and_reports_the_warm_up_apart(tmp_path, monkeypatch):
    from dumbbell.analysis.compare import MAX_TIMED_RUNS, timed_run
    from dumbbell.model.scene import load_scene

    scene = load_scene(SCENES / "textbook-1d.toml")
    first, timing = timed_run(scene, "exact", dt=1e-3, t_end=2.0, every=1)
    # A quick run is timed again; the warm time is the fastest later run, never the first's.
    assert 2 <= timing.runs <= 1 + MAX_TIMED_RUNS
    assert 0 < timing.seconds and timing.warm_up >= first.wall_time - timing.seconds - 1e-12
    out = tmp_path / "c"
    assert main(["compare", str(SCENES / "textbook-1d.toml"), "--t-end", "1", "--solvers",
                 "euler-cromer", "--out", str(out), "-q"]) == 0
    rows = list(csv.DictReader((out / "textbook-1d-compare.csv").open()))
    assert list(rows[0])[-1] == "warm_up_s" and list(rows[0])[2] == "run_time_s"
    assert [r["solver"] for r in rows] == ["exact", "euler-cromer"]
    assert all(float(r["warm_up_s"]) >= 0 and float(r["run_time_s"]) > 0 for r in rows)
    # A run not timed again (here: every run, as if each took long) has no measured warm-up
    # unless its solver compiles something, which is timed by itself.
    import dumbbell.analysis.compare

    monkeypatch.setattr(dumbbell.analysis.compare, "TIME_AGAIN_BELOW", 0.0)
    for solver, measured in (("pymunk", False), ("euler-cromer", True)):
        _, timing = timed_run(scene, solver, dt=1e-3, t_end=0.1, every=1)
        assert timing.runs == 1 and (timing.warm_up >= 0 if measured
                                     else math.isnan(timing.warm_up))
    # A step-free solver's first run may load its compiled code: it is timed again anyway.
    _, timing = timed_run(scene, "exact", dt=1e-3, t_end=0.1, every=1)
    assert timing.runs >= 2 and timing.warm_up >= 0


def _scene_file(tmp_path, name: str, **lines: str) -> str:
    """The textbook scene with whole lines replaced: key -> new line (first match)."""
    text = (SCENES / "textbook-1d.toml").read_text()
    for key, line in lines.items():
        text = re.sub(rf"^{key} = .*$", line, text, count=1, flags=re.MULTILINE)
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("lines", [
    # The scene's own samples (every 100 steps, 1 ms) serve the GIF; the GIF ends before
    # the run does.
    {"t_end": "t_end = 1.5", "gif": 'gif = { fps = 10, size = "320x180", t_end = 1.0 }'},
    # Every step kept: render thins to the strip's rate, and run draws from that run too.
    {"t_end": "t_end = 1.0", "every": "every = 1",
     "gif": 'gif = { fps = 10, size = "320x180" }'},
])
def test_run_and_render_write_the_same_gif(tmp_path, lines):
    scene = _scene_file(tmp_path, "same", **lines)
    assert main(["run", scene, "--out", str(tmp_path / "run"), "-q"]) == 0
    assert main(["render", scene, "-o", str(tmp_path / "render.gif"), "-q"]) == 0
    assert (tmp_path / "run" / "same.gif").read_bytes() == (tmp_path / "render.gif").read_bytes()


def test_render_keeps_the_scenes_samples_when_they_serve_the_gif():
    from dumbbell.animation.render import STRIP_RATE, sample_every

    # 1 ms samples at dt = 1e-5 s: 100 steps, which divide the 4,000 steps of a 25 fps frame.
    assert sample_every(1e-5, 25, 10.0, 100) == 100
    assert sample_every(1e-5, 25, 10.0) == round(1 / (1e-5 * STRIP_RATE)) == 200
    # Not dividing the frame interval, or sparser than the strip needs: the render's own.
    assert sample_every(1e-5, 25, 10.0, 300) == 200
    assert sample_every(1e-5, 25, 10.0, 1000) == 200
