"""Hostile input, signals and resource bounds (docs/hardening.md): each refusal is exit 2 (or
128+signal), one line naming what to fix, nothing left in the output folder, no process left."""

from __future__ import annotations

import importlib
import os
import re
import signal
import socket
import stat
import subprocess
import sys
import threading
import tracemalloc
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

import dumbbell
from dumbbell import DumbbellError, SceneError, load_scene
from dumbbell.model.scene import scene_from_dict
from tests.conftest import SCENES
from tests.hostile import (
    SHORT_SCENE,
    SRC,
    cli,
    end_group,
    files_in,
    finish,
    group_left,
    interruptible,
    marker_pipe,
    own_children,
    refused,
    run_group,
    short_scene,
    started,
    wait_gone,
    wait_mark,
)


@pytest.fixture
def work(tmp_path: Path) -> tuple[Path, Path]:
    """(a short scene in its own folder, an empty output folder)."""
    inputs, out = tmp_path / "in", tmp_path / "out"
    inputs.mkdir()
    out.mkdir()
    return short_scene(inputs), out


# --- 1. resource bounds before the work -----------------------------------------------------


def test_a_billion_samples_are_refused_at_once_without_allocating(work):
    scene, out = work
    tracemalloc.start()
    try:
        status, _, err = cli("simulate", scene, "--t-end", "1e4", "--dt", "1e-5", "--every", "1",
                             "-o", out / "x.csv")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    line = refused(status, err, out)
    # It says the count, the budget, and both ways to raise it.
    assert "1,000,000,001 samples" in line and "--every" in line and "--max-samples" in line
    assert peak < 20 * 2**20  # nothing near the 8 GB the samples would need


def test_the_sample_budget_is_exact_and_can_be_raised(work):
    scene, out = work
    # 0.05 s / 1e-4 s = 500 steps, every step kept: 501 samples.
    status, _, err = cli("simulate", scene, "--every", "1", "--max-samples", "500",
                         "-o", out / "x.csv")
    assert "501 samples" in refused(status, err, out)
    status, _, err = cli("simulate", scene, "--every", "1", "--max-samples", "501",
                         "-o", out / "x.csv", "-q")
    assert status == 0, err
    assert len((out / "x.csv").read_text().splitlines()) == 1 + 501


def test_the_sample_budget_binds_the_api_too():
    scene = load_scene(SCENES / "textbook-1d.toml")
    with pytest.raises(DumbbellError, match="max_samples"):
        dumbbell.simulate(scene, t_end=1e4, every=1)
    traj = dumbbell.simulate(scene, t_end=0.01, every=1, max_samples=1001)
    assert len(traj) == 1001


@pytest.mark.parametrize("flags,words", [
    (["--t-end", "1e4"], ["250,000 frames", "--max-frames"]),
    (["--t-end", "700", "--fps", "50"], ["35,000 frames", "--max-frames"]),
    (["--t-end", "2", "--max-frames", "49"], ["50 frames", "--max-frames"]),
])
def test_render_refuses_past_the_frame_budget_before_stepping(work, flags, words):
    scene, out = work
    status, _, err = cli("render", scene, *flags, "-o", out / "x.gif")
    line = refused(status, err, out)
    assert all(w in line for w in words), line


def test_run_refuses_a_gif_past_the_frame_budget_before_stepping(work):
    scene, out = work
    long = short_scene(scene.parent, "long.toml", '[outputs]\ncsv = true\n'
                       'gif = { fps = 25, t_end = 1e4 }\n')
    status, _, err = cli("run", long, "--out", out)
    assert "frames" in refused(status, err, out)


def test_compare_refuses_past_the_sample_budget_in_its_own_flags(work):
    scene, out = work
    status, _, err = cli("compare", scene, "--t-end", "1e5", "--out", out)
    line = refused(status, err, out)
    assert "--t-end" in line and "samples" in line and "--every" not in line


def _help_flags(command: str) -> set[str]:
    status, out, _ = cli(command, "--help")
    assert status == 0
    return set(re.findall(r"(?<![\w-])--[a-z][a-z-]*", out))


#: A budget per command that keeps samples or frames: (command, its arguments past SCENE;
#: SCENE is the short 1D scene, or "2D" for a shipped 2D one), and the way out it must name
#: (a flag, or a scene key where the command has no flag for it).
BUDGETS = [
    ("simulate", ["--t-end", "1e4", "--dt", "1e-5", "--every", "1"], ["--every", "--max-samples"]),
    ("run", ["@long-run"], ["run.every", "--max-samples"]),
    ("run", ["@long-gif"], ["outputs.gif.t_end", "outputs.gif.fps", "--max-frames"]),
    ("render", ["--t-end", "1e4"], ["--t-end", "--fps", "--max-frames"]),
    ("compare", ["--t-end", "1e5"], ["--t-end"]),
    ("bench", ["--t-end", "1e4", "--dts", "1e-3", "--window", "1e-3", "--sample-spacing",
               "1e-4"], ["--sample-spacing", "--t-end"]),
    ("restitution", ["2D", "--dt", "1e-9"], ["--dt"]),
    ("sweep", ["--grid", "k=lin:100:200:200", "--t-end", "9000"], ["--grid", "--t-end"]),
]


@pytest.mark.parametrize("command,flags,fixes", BUDGETS,
                         ids=[f"{c}-{i}" for i, (c, _, _) in enumerate(BUDGETS)])
def test_a_budget_refusal_names_flags_the_command_has(work, command, flags, fixes):
    scene, out = work
    extra = {"@long-run": SHORT_SCENE.replace("t_end = 0.05", "t_end = 1e4"),
             "@long-gif": SHORT_SCENE + "[outputs]\ncsv = true\ngif = { fps = 25, t_end = 1e4 }\n"}
    if flags and flags[0] in extra:
        (scene.parent / "budget.toml").write_text(extra[flags.pop(0)], encoding="utf-8")
        scene = scene.parent / "budget.toml"
    elif flags and flags[0] == "2D":
        flags, scene = flags[1:], SCENES / "tilted-2d.toml"
    where = ["-o", out / "x.gif"] if command == "render" else (
        ["-o", out / "x.csv"] if command == "simulate" else ["--out", out])
    status, _, err = cli(command, scene, *flags, *where)
    line = refused(status, err, out)
    assert "budget" in line or "at most" in line, line
    named = set(re.findall(r"(?<![\w-])--[a-z][a-z-]*", line.split("budget", 1)[-1]))
    assert named <= _help_flags(command), (line, named - _help_flags(command))
    assert all(f in line for f in fixes), line


def test_render_keeps_a_bounded_number_of_samples_whatever_fps_and_dt():
    """The samples a render keeps, t_end / dt / every + 1, stay under 2 * STRIP_SAMPLES + 1 for
    any frame rate and step; and they fall on frame times whenever a divisor of the frame
    interval (in steps) is within a factor 2 of the strip's target."""
    from dumbbell.animation.render import STRIP_RATE, STRIP_SAMPLES, sample_every

    for fps in range(1, 51):
        for dt in (1e-6, 7e-6, 1e-5, 3e-5, 1e-4, 1e-3, 0.013, 0.05):
            for t_end in (1.0, 37.0, 600.0):
                every = sample_every(dt, fps, t_end)
                samples = round(t_end / dt) // every + 1
                assert 1 <= every and samples <= 2 * STRIP_SAMPLES + 1, (fps, dt, t_end, every)
                per_frame = max(1, round(1 / (fps * dt)))
                target = max(1.0, 1 / (dt * STRIP_RATE), t_end / dt / STRIP_SAMPLES)
                near = [d for d in range(1, per_frame + 1)
                        if per_frame % d == 0 and target / 2 <= d <= target]
                if near:
                    assert every == max(near), (fps, dt, t_end, every)


def test_render_of_a_tiny_step_neither_hangs_nor_overflows(work, tmp_path):
    # dt = 1e-200 s: the frame interval is 4e198 steps, whose divisors cannot be searched.
    scene, out = work
    tiny = scene.parent / "tiny.toml"
    tiny.write_text(SHORT_SCENE.replace("t_end = 0.05", "t_end = 1e-195")
                    .replace("dt = 1e-4", "dt = 1e-200"), encoding="utf-8")
    status, _, err = cli("render", tiny, "-o", out / "x.gif", "-q")
    assert status == 0 and "Traceback" not in err, err
    assert files_in(out) == ["x.gif"]


def test_sweep_caps_workers_and_says_so_once(work):
    scene, out = work
    status, _, err = cli("sweep", scene, "--grid", "k=100,200,300", "--workers", "10000",
                         "--out", out, "-q")
    assert status == 0, err
    assert "Traceback" not in err
    lines = [line for line in err.splitlines() if "--workers" in line]
    cap = min(os.cpu_count() or 1, 3)
    assert len(lines) == 1 and f"{cap}" in lines[0] and "10000" in lines[0], err
    assert sorted(files_in(out)) == ["short-sweep.csv", "short-sweep.png"]
    assert not own_children()


def test_stability_refuses_a_case_past_the_step_cap_before_any_runs(work):
    scene, out = work
    cases = scene.parent / "cases"
    cases.mkdir()
    short_scene(cases, "quick.toml")
    short_scene(cases, "endless.toml").write_text(
        SHORT_SCENE.replace("t_end = 0.05", "t_end = 1e7"), encoding="utf-8")
    # The workers note would come first if the case were checked only when it runs.
    status, _, err = cli("stability", "--cases", cases, "--workers", "10000", "--out", out,
                         "--solvers", "euler-cromer")
    line = refused(status, err, out)
    assert "endless.toml" in line and "steps" in line


def test_the_worker_cap():
    from dumbbell.parallel import cap_workers

    cpus = os.cpu_count() or 1
    assert cap_workers(10_000, 3) == (min(cpus, 3), True)
    assert cap_workers(None, 3)[0] == min(cpus, 3)
    assert cap_workers(1, 3) == (1, False)
    assert cap_workers(5, 0) == (1, True)


# The exact solvers' work: impacts and the impact search, bounded before and during a run.


def _bouncer(dimensions: int, drop: float, elasticity: float = 1.0, k: float = 200.0,
             t_end: float = 2.0, spin: float = 0.0):
    """A dumbbell (1D spring, or 2D rigid rod, vertical) with B ``drop`` m above the floor;
    in 2D A moves sideways at ``spin`` m/s, which sets the rod turning."""
    data = {"title": "bouncer", "dimensions": dimensions,
            "bodies": {"A": {"mass": 0.1, "height": drop + 0.2},
                       "B": {"mass": 0.1, "height": drop}},
            "floor": {"elasticity": elasticity}, "gravity": {"g": 9.8},
            "run": {"t_end": t_end, "dt": 1e-3, "solver": "exact"}}
    if dimensions == 1:
        data["spring"] = {"stiffness": k, "rest_length": 0.2}
    else:
        data["tilt"] = 0.0
        data["bodies"]["A"] = {"mass": 0.1, "velocity": [spin, 0.0]}
        data["rigid"] = {"length": 0.2}
    return scene_from_dict(data, source="bouncer.toml")


@pytest.mark.parametrize("scene", [
    "textbook-1d", "rigid-2d", "1D 1 mm", "1D 10 um", "2D 1 mm", "1D stiff", "2D spinning"])
def test_the_impact_estimate_is_a_lower_bound(scene):
    """The estimate that refuses a run is a bound the run itself never beats: the impacts
    located are at least min_impacts (and the bound is not empty)."""
    from dumbbell.solvers.base import min_impacts
    from dumbbell.solvers.exact import vertical_energy

    made = {"1D 1 mm": lambda: _bouncer(1, 1e-3), "1D 10 um": lambda: _bouncer(1, 1e-5),
            "2D 1 mm": lambda: _bouncer(2, 1e-3), "1D stiff": lambda: _bouncer(1, 0.05, k=1e6),
            "2D spinning": lambda: _bouncer(2, 0.05, spin=3.0)}
    loaded = made[scene]() if scene in made else load_scene(SCENES / f"{scene}.toml")
    bound, _ = min_impacts(loaded, loaded.run.t_end, vertical_energy(loaded))
    traj = dumbbell.simulate(loaded, "exact", dt=1e-2)
    assert traj.verdict.ok and 1 <= bound <= len(traj.events), (bound, len(traj.events))


@pytest.mark.parametrize("command,scene,flags,fix", [
    ("simulate", "textbook-1d", ["--solver", "exact", "--t-end", "1e6", "--dt", "1", "-o",
                                 "OUT/x.csv"], "--t-end"),
    ("simulate", "rigid-2d", ["--solver", "exact", "--t-end", "1e6", "--dt", "1", "-o",
                              "OUT/x.csv"], "--t-end"),
    ("run", "@exact", ["--out", "OUT"], "run.t_end"),
    ("bench", "textbook-1d", ["--t-end", "2e5", "--dts", "1", "--window", "1",
                              "--sample-spacing", "1", "--out", "OUT"], "--t-end"),
    ("compare", "textbook-1d", ["--t-end", "2e5", "--dt", "1", "--out", "OUT"], "--t-end"),
])
def test_exact_refuses_a_run_past_its_impact_budget_before_any_work(work, monkeypatch,
                                                                     command, scene, flags,
                                                                     fix):
    def no_work(*args, **kwargs):
        raise AssertionError("the impact search started")

    for module, name in (("exact", "_segments"), ("exact_rigid", "_flight")):
        monkeypatch.setattr(importlib.import_module(f"dumbbell.solvers.{module}"), name,
                            no_work)
    _, out = work
    if scene == "@exact":
        path = out.parent / "exact.toml"
        path.write_text((SCENES / "textbook-1d.toml").read_text().replace(
            "t_end = 10.0", "t_end = 1e6").replace("dt = 1e-5", "dt = 1.0").replace(
            'solver = "euler-cromer"', 'solver = "exact"').split("[outputs]")[0]
            + "[outputs]\ncsv = true\n", encoding="utf-8")
    else:
        path = SCENES / f"{scene}.toml"
    status, _, err = cli(command, path, *[f.replace("OUT", str(out)) for f in flags])
    line = refused(status, err, out)
    assert "impacts" in line and "budget of 100,000" in line and fix in line, line
    named = set(re.findall(r"(?<![\w-])--[a-z][a-z-]*", line))
    assert named <= _help_flags(command), line


@pytest.mark.parametrize("dimensions", [1, 2])
def test_exact_stops_at_the_impact_budget_with_a_failed_verdict(work, monkeypatch,
                                                                dimensions):
    # Bouncing 10 um high on an elastic floor: hundreds of impacts a second, far more than
    # the energy's lower bound (which lets the run start), so the loop's budget must end it.
    monkeypatch.setattr(importlib.import_module("dumbbell.solvers.base"), "MAX_IMPACTS", 300)
    scene = _bouncer(dimensions, 1e-5)
    traj = dumbbell.simulate(scene, "exact", dt=1e-3)
    assert traj.verdict.status == "failed" and "impact budget" in traj.verdict.reason
    assert 300 <= len(traj.events) <= 302 and traj.t[-1] <= traj.verdict.t
    assert traj.verdict.t == pytest.approx(traj.events[-1].t)
    # The command line: exit 3, the samples up to there, one line saying why.
    _, out = work
    path = out.parent / "bouncer.toml"
    path.write_text(SHORT_SCENE.replace("height = 1.2", f"height = {0.2 + 1e-5}").replace(
        "height = 1.0", "height = 1e-5").replace('solver = "euler-cromer"', 'solver = "exact"')
        .replace("t_end = 0.05", "t_end = 2.0"), encoding="utf-8")
    status, _, err = cli("simulate", path, "-q")
    assert status == 3 and "impact budget" in err and len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("scene", ["1D stiff", "2D spinning"])
def test_exact_stops_at_the_search_budget_with_a_failed_verdict(monkeypatch, scene):
    # A stiff spring (w = 1e5 rad/s) or a fast spin makes the search's intervals short.
    monkeypatch.setattr(importlib.import_module("dumbbell.solvers.base"), "MAX_SEARCH_WORK",
                        300)
    loaded = (_bouncer(1, 0.05, k=1e9, t_end=1.0) if scene == "1D stiff"
              else _bouncer(2, 0.05, spin=300.0, t_end=1.0))
    traj = dumbbell.simulate(loaded, "exact", dt=1e-3)
    assert traj.verdict.status == "failed" and "search's budget" in traj.verdict.reason
    assert traj.t[-1] <= traj.verdict.t


# --- 2. arithmetic overflow -----------------------------------------------------------------


@pytest.mark.parametrize("flags,word", [
    (["--dt", "5e-324"], "steps"),
    (["--dt", "4.9e-324", "--t-end", "1e-300"], "steps"),
    (["--t-end", "1e300", "--dt", "1e-300"], "steps"),
    (["--t-end", "1.7e308", "--dt", "1e-5"], "steps"),
    (["--every", "1234567890123456789012345"], "--every"),
    (["--every", "9" * 5000], "--every"),
    (["--max-samples", "1e999"], "--max-samples"),
])
def test_simulate_overflow_is_one_line(work, flags, word):
    scene, out = work
    status, _, err = cli("simulate", scene, *flags, "-o", out / "x.csv")
    assert word in refused(status, err, out)


@pytest.mark.parametrize("command,flags", [
    ("render", ["--t-end", "1e300"]),
    ("render", ["--fps", "9" * 30]),
    ("compare", ["--t-end", "1e300", "--dt", "1e-300"]),
    ("compare", ["--dt", "5e-324"]),
    ("bench", ["--dts", "5e-324"]),
    ("bench", ["--repeat", "9" * 25]),
    ("sweep", ["--grid", "dt=5e-324,1e-4"]),
    ("sweep", ["--grid", "k=log:1e-300:1e300:3", "--t-end", "1e300"]),
    ("sweep", ["--grid", "k=lin:1:2:" + "9" * 25]),
])
def test_other_commands_overflow_is_one_line(work, command, flags):
    scene, out = work
    output = ["-o", out / "x.gif"] if command == "render" else ["--out", out]
    status, _, err = cli(command, scene, *flags, *output)
    refused(status, err, out)


@pytest.mark.parametrize("kwargs,word", [
    ({"t_end": 10**400}, "t_end"),
    ({"t_end": 1e300, "dt": 1e-300}, "steps"),
    ({"dt": 5e-324}, "steps"),
    ({"every": 2**70}, "every"),
    ({"every": 10**400}, "every"),
    ({"dt": -(10**400)}, "dt"),
])
def test_api_overflow_raises_a_dumbbell_error(kwargs, word):
    scene = load_scene(SCENES / "textbook-1d.toml")
    with pytest.raises(DumbbellError, match=word) as info:
        dumbbell.simulate(scene, **kwargs)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("key,value", [
    ("rigid.length", 1e200), ("rigid.length", 1e300), ("bodies.B.height", 1e300),
    ("bodies.B.x", -1e250), ("gravity.g", 1e308), ("bodies.A.mass", 1e-320),
    ("bodies.A.spin", 1e200), ("bodies.B.radius", 1e160),
])
def test_rigid_scene_magnitudes_are_checked_at_the_border(key, value):
    rigid = load_scene(SCENES / "rigid-2d.toml")
    with pytest.raises(SceneError, match=key.split(".")[-1]):
        rigid.with_values({key: value})


@pytest.mark.parametrize("key,value", [
    ("spring.stiffness", 1e308), ("spring.rest_length", 1e200), ("bodies.A.velocity", 1e200),
    ("bodies.A.mass", 1e300), ("bodies.A.height", 1e300),
])
def test_scene_magnitudes_are_checked_at_the_border(key, value):
    scene = load_scene(SCENES / "textbook-1d.toml")
    with pytest.raises(SceneError, match=key.split(".")[-1]):
        scene.with_values({key: value})


def test_a_rigid_scene_file_of_huge_length_is_one_line(tmp_path):
    text = (SCENES / "rigid-2d.toml").read_text().replace("length = 0.2", "length = 1e200")
    path = tmp_path / "huge.toml"
    path.write_text(text)
    status, _, err = cli("simulate", path, "--t-end", "0.01", "-o", tmp_path / "x.csv")
    assert "rigid.length" in refused(status, err, tmp_path, keep=("huge.toml",))


# --- 3. signals -----------------------------------------------------------------------------


#: Run before ``main`` in a child: at the point MARK names, the process writes a line on the
#: marker pipe MARK_FD and, where the work would otherwise end soon, waits there until the
#: test's signal comes. 'sweep': each pool worker, at its first point; 'frame': the GIF's
#: second frame (its temporary file is there); 'stepping': the first chunk of steps done.
AT_MARK = """
import os, time
def _mark(wait):
    os.write(int(os.environ["MARK_FD"]), b"marked\\n")
    if wait:
        while True: time.sleep(0.01)
_at = os.environ["MARK"]
if _at == "sweep":
    from dumbbell.analysis import sweep as _sweep
    _evaluate = _sweep._evaluate
    def _marked(*args):
        _mark(True)
        return _evaluate(*args)
    _sweep._evaluate = _marked
elif _at == "frame":
    from dumbbell.animation import painter as _painter
    _frame = _painter.Painter.frame
    def _marked(self, k):
        if k == 1:
            _mark(True)
        return _frame(self, k)
    _painter.Painter.frame = _marked
elif _at == "stepping":
    from dumbbell import progress as _progress
    _update = _progress._NoBar.update
    def _marked(self, n=1):
        if not self.n:
            _mark(False)
        return _update(self, n)
    _progress._NoBar.update = _marked
"""


@contextmanager
def at_mark(mark: str, *argv: object, cwd: Path | None = None):
    """``dumbbell ARGV`` started with :data:`AT_MARK` at ``mark``; yields it once it got
    there (its whole process group is killed on the way out, pass or fail)."""
    with marker_pipe() as (r, w), started(*argv, cwd=cwd, prelude=AT_MARK, pass_fds=(w,),
                                          env={"MARK": mark, "MARK_FD": str(w)}) as proc:
        wait_mark(proc, r)
        yield proc


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT])
def test_a_signal_stops_a_sweep_and_its_workers(tmp_path, sig):
    """Signalled once a worker is inside a point (each waits there for it): the run cannot
    have ended before the signal, however slow the machine."""
    scene = short_scene(tmp_path, "sweep-signal.toml")
    out = tmp_path / "out"
    with at_mark("sweep", "sweep", scene, "--grid", "k=log:1e2:1e3:16", "--t-end", "30",
                 "--workers", "2", "--out", out) as proc:
        proc.send_signal(sig)
        _, err = finish(proc)
        assert not wait_gone(str(scene)), "pool workers outlived the sweep"
        assert not group_left(proc)
    line = refused(proc.returncode, err, code=128 + sig)
    assert signal.Signals(sig).name in line
    assert not out.exists() or files_in(out) == []


def test_under_nohup_sighup_is_ignored_and_sigterm_still_stops(tmp_path):
    """`nohup dumbbell render ...`: the command keeps nohup's ignored SIGHUP ignored. Sent
    SIGHUP then SIGTERM while it writes the GIF (waiting there), it stops by SIGTERM: had
    SIGHUP acted, it would have stopped by it, the lower signal, delivered first."""
    scene = short_scene(tmp_path, "nohup.toml")
    out = tmp_path / "out"
    out.mkdir()
    nohup = lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN)
    with marker_pipe() as (r, w), started("render", scene, "--t-end", "60", "--fps", "10",
                                          "-o", out / "x.gif", prelude=AT_MARK,
                                          pass_fds=(w,), preexec_fn=nohup,
                                          env={"MARK": "frame", "MARK_FD": str(w)}) as proc:
        wait_mark(proc, r)
        proc.send_signal(signal.SIGHUP)
        proc.send_signal(signal.SIGTERM)
        _, err = finish(proc)
    line = refused(proc.returncode, err, out, code=128 + signal.SIGTERM)
    assert "SIGTERM" in line and "SIGHUP" not in line


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_while_the_gif_is_written_leaves_no_part_file(tmp_path, sig):
    scene = short_scene(tmp_path, "render-signal.toml")
    out = tmp_path / "out"
    out.mkdir()
    with at_mark("frame", "render", scene, "--t-end", "60", "--fps", "10", "-o",
                 out / "x.gif") as proc:
        assert any(".part" in n for n in os.listdir(out))  # the GIF is being written
        proc.send_signal(sig)
        _, err = finish(proc)
    refused(proc.returncode, err, out, code=128 + sig)


def test_sigterm_while_stepping_writes_nothing(tmp_path):
    scene = tmp_path / "simulate-signal.toml"
    # No floor: a long run that ends only when its 1e9 steps are done (or it is stopped).
    scene.write_text(SHORT_SCENE.replace("[floor]\nelasticity = 1.0\n", ""))
    out = tmp_path / "out"
    out.mkdir()
    with at_mark("stepping", "simulate", scene, "--t-end", "1e5", "--every", "1000000",
                 "-o", out / "x.csv", "--events", out / "e.csv") as proc:
        proc.send_signal(signal.SIGTERM)
        _, err = finish(proc)
    refused(proc.returncode, err, out, code=128 + signal.SIGTERM)


def test_pool_workers_take_the_default_signal_handlers():
    from dumbbell.parallel import worker_init

    old = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP)}
    try:
        signal.signal(signal.SIGTERM, lambda *a: None)
        worker_init()
        assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL
        assert signal.getsignal(signal.SIGHUP) == signal.SIG_DFL
        assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)


def test_main_restores_the_callers_signal_handlers(work):
    scene, out = work
    before = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGHUP, signal.SIGINT)}
    cli("simulate", scene, "-o", out / "x.csv", "-q")
    assert {s: signal.getsignal(s) for s in before} == before


# --- 4. outputs -----------------------------------------------------------------------------


def test_output_naming_the_scene_is_refused_and_the_scene_kept(work):
    scene, out = work
    before = scene.read_bytes()
    for spelling in (scene, scene.parent / ".." / scene.parent.name / scene.name):
        status, _, err = cli("simulate", scene, "-o", spelling)
        assert "-o" in refused(status, err, out)
        assert scene.read_bytes() == before


def test_output_through_a_symlink_to_the_scene_is_refused(work):
    scene, out = work
    (out / "link.csv").symlink_to(scene)
    before = scene.read_bytes()
    status, _, err = cli("simulate", scene, "-o", out / "link.csv")
    refused(status, err, out, keep=("link.csv",))
    assert scene.read_bytes() == before and (out / "link.csv").is_symlink()


@pytest.mark.parametrize("second", ["x.csv", "./x.csv", "sub/../x.csv"])
def test_two_outputs_on_one_file_are_refused(work, second, monkeypatch):
    scene, out = work
    (out / "sub").mkdir()
    monkeypatch.chdir(out)
    status, _, err = cli("simulate", scene, "-o", "x.csv", "--events", second)
    line = refused(status, err, out, keep=("sub",))
    assert "-o" in line and "--events" in line


def test_events_naming_the_scene_is_refused(work):
    scene, out = work
    status, _, err = cli("simulate", scene, "-o", out / "x.csv", "--events", scene)
    assert "--events" in refused(status, err, out)


def _char_device(folder: Path, name: str, minor: int) -> Path:
    """A private character device (1, minor): 3 is null, 7 is full. Skips if not permitted."""
    path = folder / name
    try:
        os.mknod(path, stat.S_IFCHR | 0o666, os.makedev(1, minor))
    except (PermissionError, OSError) as exc:
        pytest.skip(f"cannot make a device here: {exc}")
    return path


def test_a_device_output_is_written_not_replaced(work):
    scene, out = work
    null = _char_device(out, "null", 3)
    status, _, err = cli("simulate", scene, "-o", null, "--events", null, "-q")
    assert "--events" in refused(status, err, out, keep=("null",))  # still one file
    status, _, err = cli("simulate", scene, "-o", null, "-q")
    assert status == 0, err
    assert stat.S_ISCHR(null.stat().st_mode)
    assert files_in(out) == ["null"]


def test_a_full_device_output_is_one_line_naming_it(work):
    scene, out = work
    full = _char_device(out, "full", 7)
    status, _, err = cli("simulate", scene, "-o", full, "-q")
    line = refused(status, err, out, keep=("full",))
    assert str(full) in line and ".part" not in line
    assert stat.S_ISCHR(full.stat().st_mode)


def test_a_fifo_output_is_written_through(work):
    scene, out = work
    fifo = out / "pipe"
    os.mkfifo(fifo)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()))
    reader.start()
    status, _, err = cli("simulate", scene, "-o", fifo, "-q")
    reader.join(10)
    assert status == 0, err
    assert got and got[0].startswith(b"t,xA,vA")
    assert stat.S_ISFIFO(fifo.stat().st_mode) and files_in(out) == ["pipe"]


def test_dash_writes_to_stdout(work):
    scene, out = work
    status, text, err = cli("simulate", scene, "-o", "-", "--events", out / "e.csv", "-q")
    assert status == 0, err
    assert text.startswith("t,xA,vA") and len(text.splitlines()) == 1 + 51
    assert files_in(out) == ["e.csv"]


def test_a_failed_second_output_leaves_the_first_out_too(work, monkeypatch):
    scene, out = work
    import dumbbell.io.trajectory

    def fail(traj, path):
        from dumbbell.files import atomic_output

        with atomic_output(path) as tmp:
            raise PermissionError(13, "Permission denied", str(tmp))

    monkeypatch.setattr(dumbbell.io.trajectory, "write_events", fail)
    status, _, err = cli("simulate", scene, "-o", out / "x.csv", "--events", out / "e.csv")
    line = refused(status, err, out)
    assert str(out / "e.csv") in line and ".part" not in line


@pytest.mark.parametrize("flag,value", [
    ("--events", "{scene}/e.csv"),        # the folder is a file
    ("-o", "{out}"),                       # a folder given as the file
    ("--events", "{out}/none/\0/e.csv"),   # not a path at all
])
def test_unwritable_outputs_are_refused_before_stepping(work, flag, value):
    scene, out = work
    target = value.format(scene=scene, out=out)
    argv = ["simulate", scene, "--t-end", "1e3", "--dt", "1e-6", "--every", "100000"]
    other = ["-o", out / "x.csv"] if flag == "--events" else []
    status, _, err = cli(*argv, *other, flag, target)
    assert flag in refused(status, err, out)


def test_an_output_folder_that_is_a_file_is_refused(work):
    scene, out = work
    (out / "f").write_text("x")
    status, _, err = cli("sweep", scene, "--grid", "k=100,200", "--out", out / "f")
    assert "--out" in refused(status, err, out, keep=("f",))


# --- 5. inputs that are not files -----------------------------------------------------------


def test_dev_zero_as_the_scene_is_refused_at_once(tmp_path):
    status, _, err = cli("simulate", "/dev/zero", "-o", tmp_path / "x.csv")
    assert "/dev/zero" in refused(status, err, tmp_path)


def test_a_fifo_as_the_scene_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "scene.toml"
    os.mkfifo(fifo)
    status, _, err = cli("simulate", fifo, "-o", tmp_path / "x.csv")
    assert "regular file" in refused(status, err, tmp_path, keep=("scene.toml",))


def test_a_directory_as_the_scene_is_refused(tmp_path):
    status, _, err = cli("simulate", tmp_path)
    refused(status, err, tmp_path)


def test_a_scene_file_past_the_size_cap_is_refused(tmp_path):
    path = short_scene(tmp_path, extra="# " + "x" * 1_100_000 + "\n")
    status, _, err = cli("simulate", path, "-o", tmp_path / "x.csv")
    assert "1 MB" in refused(status, err, tmp_path, keep=("short.toml",))


@pytest.mark.parametrize("text", [
    "a = " + "[" * 5000 + "]" * 5000,
    "a = " + "{b = " * 3000 + "1" + "}" * 3000,
    "[" + ".".join(["a"] * 3000) + "]\nx = 1",
])
def test_deep_nesting_is_a_scene_error(tmp_path, text):
    path = tmp_path / "deep.toml"
    path.write_text(text)
    with pytest.raises(SceneError):
        load_scene(path)
    status, _, err = cli("simulate", path, "-o", tmp_path / "x.csv")
    refused(status, err, tmp_path, keep=("deep.toml",))


def test_a_deeply_nested_dict_is_a_scene_error():
    deep: dict = {}
    node = deep
    for _ in range(5000):
        node["a"] = {}
        node = node["a"]
    with pytest.raises(SceneError):
        scene_from_dict(deep)
    scene = load_scene(SCENES / "textbook-1d.toml")
    with pytest.raises(SceneError):
        scene.with_values({"outputs.gif": deep})


def _piped(stdin: bytes, *argv: object, cwd: Path) -> subprocess.CompletedProcess:
    """``dumbbell ARGV`` as a real process reading ``stdin``."""
    env = {**os.environ, "PYTHONPATH": SRC, "CI": "1"}
    code = "import sys; from dumbbell.cli import main; sys.exit(main())"
    return run_group([sys.executable, "-c", code, *argv], input=stdin, cwd=cwd, env=env)


def test_a_scene_from_stdin_runs_as_the_same_file_does(work):
    scene, out = work
    text = scene.read_bytes()
    piped = _piped(text, "simulate", "-", "-q", cwd=out)
    # The same file named, run here: what the piped process printed is its CSV.
    status, direct, err = cli("simulate", scene, "-q")
    assert status == 0, err
    assert piped.returncode == 0 and piped.stdout.decode() == direct and direct
    done = _piped(text, "render", "-", "-q", "--t-end", "0.04", cwd=out)
    assert done.returncode == 0, done.stderr
    done = _piped(text, "compare", "-", "-q", "--out", "c", cwd=out)
    assert done.returncode == 0, done.stderr
    assert "renders/stdin.gif" in files_in(out) and "c/stdin-compare.csv" in files_in(out)


@pytest.mark.parametrize("command", ["simulate", "render", "compare"])
@pytest.mark.parametrize("stdin,words", [
    (b"#" * 1_000_001, ["stdin", "1 MB"]),
    (b"[bodies\n", ["stdin", "TOML"]),
    (b"\xff\xfe", ["stdin", "UTF-8"]),
    (b"", ["stdin", "[bodies]"]),
], ids=["1 MB", "not TOML", "not UTF-8", "empty"])
def test_a_bad_scene_from_stdin_is_one_line(work, command, stdin, words):
    _, out = work
    done = _piped(stdin, command, "-", cwd=out)
    line = refused(done.returncode, done.stderr.decode(), out)
    assert all(w in line for w in words), line


# --- 6. external services -------------------------------------------------------------------


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def http_port():
    from http.server import HTTPServer, SimpleHTTPRequestHandler

    server = HTTPServer(("127.0.0.1", 0), SimpleHTTPRequestHandler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield server.server_address[1]
    server.shutdown()
    server.server_close()


@pytest.mark.parametrize("target", ["closed", "http"])
def test_a_scheduler_that_is_not_dask_is_one_line(work, target, request):
    pytest.importorskip("dask.distributed")
    scene, out = work
    port = _free_port() if target == "closed" else request.getfixturevalue("http_port")
    address = f"tcp://127.0.0.1:{port}"
    status, _, err = cli("sweep", scene, "--grid", "k=100,200", "--scheduler", address,
                         "--connect-timeout", "1", "--out", out)
    line = refused(status, err, out)
    assert address in line and "--connect-timeout" in line


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf", "1e999", "x"])
def test_connect_timeout_is_validated(work, value):
    scene, out = work
    status, _, err = cli("sweep", scene, "--grid", "k=100,200", "--scheduler", "tcp://h:1",
                         "--connect-timeout", value, "--out", out)
    assert "--connect-timeout" in refused(status, err, out)


# --- 7. the Python API ----------------------------------------------------------------------


def test_numpy_scalars_are_numbers():
    scene = load_scene(SCENES / "textbook-1d.toml")
    plain = dumbbell.simulate(scene, dt=float(np.float32(1e-4)), t_end=0.02, every=10)
    for kwargs in ({"dt": np.float32(1e-4), "t_end": np.float64(0.02), "every": np.int64(10)},
                   {"dt": np.float32(1e-4), "t_end": np.float16(0.02), "every": np.uint8(10)}):
        traj = dumbbell.simulate(scene, **kwargs)
        if kwargs["t_end"].dtype == np.float16:
            kwargs["t_end"] = float(kwargs["t_end"])
            plain = dumbbell.simulate(scene, dt=float(np.float32(1e-4)),
                                      t_end=kwargs["t_end"], every=10)
        assert np.array_equal(traj.t, plain.t) and np.array_equal(traj["E"], plain["E"])
    changed = scene.with_values({"spring.stiffness": np.float32(300.0),
                                 "run.every": np.int64(7)})
    assert changed.system.k == 300.0 and changed.run.every == 7


def test_a_path_is_accepted_where_a_scene_is_expected():
    path = SCENES / "textbook-1d.toml"
    by_scene = dumbbell.simulate(load_scene(path), t_end=0.01)
    for given in (path, str(path)):
        traj = dumbbell.simulate(given, t_end=0.01)
        assert np.array_equal(traj["E"], by_scene["E"])


@pytest.mark.parametrize("call,argument", [
    (lambda s: dumbbell.simulate(None), "scene"),
    (lambda s: dumbbell.simulate(42), "scene"),
    (lambda s: dumbbell.simulate(s, solver=["exact"]), "solver"),
    (lambda s: dumbbell.simulate(s, solver=3), "solver"),
    (lambda s: dumbbell.simulate(s, solver="nope"), "solver"),
    (lambda s: dumbbell.simulate(s, dt="1e-4"), "dt"),
    (lambda s: dumbbell.simulate(s, every=2.5), "every"),
    (lambda s: dumbbell.simulate(s, every=True), "every"),
    (lambda s: dumbbell.simulate(s, t_end=np.array([1.0, 2.0])), "t_end"),
    (lambda s: dumbbell.simulate(s, quiet="no"), "quiet"),
    (lambda s: dumbbell.simulate(s, max_samples=-1), "max_samples"),
    (lambda s: dumbbell.load_scene(None), "path"),
    (lambda s: dumbbell.load_scene(["a.toml"]), "path"),
    (lambda s: scene_from_dict(None), "data"),
    (lambda s: s.with_values(None), "values"),
    (lambda s: s.with_values({None: 1}), "values"),
    (lambda s: s.with_values(["k"]), "values"),
])
def test_wrong_types_raise_a_dumbbell_error_naming_the_argument(call, argument):
    scene = load_scene(SCENES / "textbook-1d.toml")
    with pytest.raises(DumbbellError, match=argument) as info:
        call(scene)
    assert "\n" not in str(info.value)


def test_analysis_functions_check_their_arguments():
    from dumbbell.analysis.compare import CompareOptions, compare
    from dumbbell.analysis.sweep import SweepOptions, run_sweep

    scene = load_scene(SCENES / "textbook-1d.toml")
    with pytest.raises(DumbbellError, match="solvers"):
        compare(scene, CompareOptions(solvers="nope"))
    with pytest.raises(DumbbellError, match="options"):
        compare(scene, {"solvers": ["exact"]})
    with pytest.raises(DumbbellError, match="scene"):
        compare(None, CompareOptions())
    with pytest.raises(DumbbellError, match="axes"):
        run_sweep(scene, None, SweepOptions("euler-cromer"))
    with pytest.raises(DumbbellError, match="solver"):
        run_sweep(scene, [], SweepOptions(3))


def test_trajectory_outputs_check_their_path(tmp_path):
    scene = load_scene(SCENES / "textbook-1d.toml")
    traj = dumbbell.simulate(scene, t_end=0.01)
    from dumbbell.io.trajectory import write_csv, write_events

    with pytest.raises(DumbbellError, match="path"):
        write_csv(traj, None)
    with pytest.raises(DumbbellError, match="path"):
        write_events(traj, 3)
    assert write_csv(traj, str(tmp_path / "x.csv")).is_file()


def test_a_step_count_past_the_floats_is_said_in_words():
    scene = load_scene(SCENES / "textbook-1d.toml")
    with pytest.raises(DumbbellError) as info:
        dumbbell.simulate(scene, t_end=1e10, dt=1e-300)
    assert "inf" not in str(info.value) and "nan" not in str(info.value)


@pytest.mark.parametrize("call,argument", [
    (lambda: dumbbell.compare(None), "scene"),
    (lambda: dumbbell.compare(SCENES / "textbook-1d.toml", solvers=[None]), "solvers"),
    (lambda: dumbbell.bench(SCENES / "textbook-1d.toml", dts=["1e-3"]), "dts"),
    (lambda: dumbbell.sweep(SCENES / "textbook-1d.toml", None), "grid"),
    (lambda: dumbbell.sweep(SCENES / "textbook-1d.toml", {"k": [1, 2]}, workers=[2]), "workers"),
    (lambda: dumbbell.stability(solvers=3), "solvers"),
    (lambda: dumbbell.render_gif(None), "traj"),
    (lambda: dumbbell.render_gif(dumbbell.simulate(SCENES / "textbook-1d.toml", t_end=0.1),
                                 t_end=10**400), "t_end"),
])
def test_the_public_entry_points_name_a_wrong_argument(call, argument):
    with pytest.raises(DumbbellError, match=argument) as info:
        call()
    assert "\n" not in str(info.value)


def test_render_gif_takes_numpy_scalars():
    traj = dumbbell.simulate(SCENES / "textbook-1d.toml", t_end=0.2)
    gif = dumbbell.render_gif(traj, fps=np.int64(10), t_end=np.float32(0.2),
                              max_frames=np.int64(3), size="64x64")
    assert bytes(gif[:6]) == b"GIF89a"


def test_dev_stdout_is_written_not_replaced(tmp_path):
    scene = short_scene(tmp_path, "stdout.toml")
    link = os.readlink("/dev/stdout") if os.path.islink("/dev/stdout") else None
    code = "import sys; from dumbbell.cli import main; sys.exit(main())"
    with open(tmp_path / "out.txt", "w") as fh:
        proc = run_group([sys.executable, "-c", code, "simulate", scene, "-o", "/dev/stdout",
                          "-q"], stdout=fh, text=True, env={**os.environ, "PYTHONPATH": SRC})
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "out.txt").read_text().startswith("t,xA,vA")
    assert (os.readlink("/dev/stdout") if link else None) == link


def test_an_output_through_a_symlink_writes_its_target(work):
    scene, out = work
    target = out / "target.csv"
    target.write_text("old\n")
    (out / "link.csv").symlink_to(target)
    status, _, err = cli("simulate", scene, "-o", out / "link.csv", "-q")
    assert status == 0, err
    assert (out / "link.csv").is_symlink() and target.read_text().startswith("t,xA,vA")
    assert files_in(out) == ["link.csv", "target.csv"]


# --- 8. all-or-nothing outputs (second round) -----------------------------------------------
# Every output name a command will write is checked before the work; a commit renames them
# all or none; no temporary file survives any exit, in the CLI or in a script of the user's.


def _no_temporary(folder: Path) -> list[str]:
    """Temporary or backup files left under ``folder`` (none may be)."""
    return [n for n in files_in(folder) if ".part" in n or n.endswith(".old")]


def _stepping_forbidden(monkeypatch) -> None:
    """Make any run fail loudly: a refusal must come before the first step."""
    import dumbbell.solvers

    def no_run(*args, **kwargs):
        raise AssertionError("a run started before the outputs were checked")

    for name in ("simulate",):
        monkeypatch.setattr(dumbbell.solvers, name, no_run)
    monkeypatch.setattr(dumbbell.solvers.base.Solver, "solve", no_run, raising=False)


#: Per command: its arguments past SCENE (OUT is the output folder) and the names it writes
#: there ({name} is the scene's name): a folder of one of those names must stop it before
#: any run, naming that file.
PLANNED = [
    ("run", ["--out", "OUT"], ["{name}.csv", "{name}-impacts.csv", "{name}.gif",
                               "{name}-positions.png"]),
    ("render", [], ["renders/{name}.gif"]),
    ("play", [], ["renders/{name}.html"]),
    ("compare", ["--out", "OUT"], ["{name}-compare.csv", "{name}-compare-errors.csv",
                                   "{name}-compare-energy.png"]),
    ("bench", ["--out", "OUT", "--dts", "1e-3"], ["bench-{name}.json",
                                                  "bench-{name}-convergence.png"]),
    ("sweep", ["--out", "OUT", "--grid", "k=100,200"], ["{name}-sweep.csv",
                                                        "{name}-sweep.png"]),
    ("restitution", ["--out", "OUT", "--theta", "30"], ["{name}-restitution.png"]),
    ("stability", ["--out", "OUT", "--cases", "CASES"], ["stability.md",
                                                         "stability-map.png"]),
]


@pytest.mark.parametrize("command,flags,name", [(c, f, n) for c, f, names in PLANNED
                                                for n in names])
def test_a_folder_in_the_way_of_any_output_is_refused_before_the_run(tmp_path, monkeypatch,
                                                                     command, flags, name):
    from tests.test_fuzz_cli import SHORT_2D

    inputs, out = tmp_path / "in", tmp_path / "out"
    inputs.mkdir()
    if command == "restitution":
        scene = inputs / "short2d.toml"
        scene.write_text(SHORT_2D, encoding="utf-8")
    else:
        scene = short_scene(inputs, extra="[outputs]\nfigures = [\"positions\"]\ncsv = true\n"
                            "gif = { fps = 10 }\n" if command == "run" else "")
    cases = inputs / "cases"
    cases.mkdir()
    short_scene(cases)
    from dumbbell import load_scene

    blocked = name.format(name=load_scene(scene).name)
    root = tmp_path if command in ("render", "play") else out
    (root / blocked).mkdir(parents=True)
    keep = set(files_in(tmp_path))
    monkeypatch.chdir(tmp_path)
    _stepping_forbidden(monkeypatch)
    argv = [a.replace("OUT", str(out)).replace("CASES", str(cases)) for a in flags]
    status, _, err = cli(command, *([] if command == "stability" else [scene]), *argv)
    line = refused(status, err)
    assert str(root / blocked).endswith(blocked) and blocked in line, line
    assert set(files_in(tmp_path)) == keep


@pytest.mark.parametrize("flag", ["-o", "--events"])
@pytest.mark.parametrize("value", ["new/", "new//", "./", "new/.", "new/.."])
def test_a_file_flag_naming_a_folder_is_refused(work, flag, value, monkeypatch):
    scene, out = work
    monkeypatch.chdir(out)
    other = ["--events", "e.csv"] if flag == "-o" else ["-o", "x.csv"]
    status, _, err = cli("simulate", scene, flag, value, *other)
    line = refused(status, err, out)
    assert f"{flag} {value}" in line and "folder" in line, line


@pytest.mark.parametrize("where", ["--out", "-o", "--events"])
def test_a_dangling_link_on_the_way_is_refused_naming_it(work, where, monkeypatch):
    scene, out = work
    (out / "d").symlink_to(out / "nowhere" / "deeper")
    monkeypatch.chdir(out)
    if where == "--out":
        status, _, err = cli("run", scene, "--out", "d")
    else:
        other = ["--events", "e.csv"] if where == "-o" else ["-o", "x.csv"]
        status, _, err = cli("simulate", scene, where, "d/x.csv", *other)
    line = refused(status, err, out, keep=("d",))
    assert where in line and "does not exist" in line and "File exists" not in line, line


def test_a_dangling_link_as_the_output_file_writes_its_target(work):
    scene, out = work
    (out / "link.csv").symlink_to(out / "target.csv")
    status, _, err = cli("simulate", scene, "-o", out / "link.csv", "-q")
    assert status == 0, err
    assert (out / "link.csv").is_symlink() and (out / "target.csv").read_text().startswith("t,")


@pytest.mark.parametrize("argv", [
    ["simulate", "SCENE", "-o", "x.csv"],
    ["simulate", "SCENE", "-o", "-", "--events", "sub/e.csv"],
    ["run", "SCENE"],
    ["render", "SCENE"],
    ["play", "SCENE"],
    ["sweep", "SCENE", "--grid", "k=100,200"],
])
def test_a_deleted_working_folder_is_refused_naming_the_output(work, argv):
    scene, out = work
    gone = out / "gone"
    gone.mkdir()
    here = os.getcwd()
    os.chdir(gone)
    try:
        gone.rmdir()
        status, _, err = cli(*[str(scene) if a == "SCENE" else a for a in argv])
    finally:
        os.chdir(here)
    line = refused(status, err, out)
    assert "working folder" in line and ("--out" in line or "-o" in line
                                         or "--events" in line), line


def _foreign(path: Path, uid: int = 12345) -> None:
    """Make ``path`` another user's (needs root)."""
    if os.geteuid() != 0:
        pytest.skip("needs root to hand a file to another user")
    os.chown(path, uid, uid)


@pytest.mark.parametrize("how", ["real", "simulated"])
def test_another_users_file_in_a_sticky_folder_is_refused_before_the_run(work, how,
                                                                         monkeypatch):
    """A sticky folder (mode 1777) lets anyone create files but replace only their own:
    checked before the work, not found at the rename. 'real' runs as the user nobody
    (setpriv, as root, in a folder everyone can reach); 'simulated' pretends to be another
    user (os.geteuid patched)."""
    import shutil
    import tempfile

    scene, out = work
    if how == "real":
        if os.geteuid() != 0 or not shutil.which("setpriv"):
            pytest.skip("needs root and setpriv to run as the user nobody")
        out = Path(tempfile.mkdtemp(prefix="dumbbell-sticky-"))
        os.chmod(out, 0o777)
        scene = Path(shutil.copy(scene, out / "scene.toml"))
        os.chmod(scene, 0o644)
    sticky = out / "st"
    sticky.mkdir()
    os.chmod(sticky, 0o1777)
    (sticky / "e.csv").write_text("old\n")
    keep = sorted(files_in(out))
    try:
        if how == "real":
            code = "import sys; from dumbbell.cli import main; sys.exit(main())"
            proc = run_group(
                ["setpriv", "--reuid", "65534", "--regid", "65534", "--clear-groups",
                 sys.executable, "-c", code, "simulate", str(scene), "-o",
                 str(out / "a.csv"), "--events", str(sticky / "e.csv")],
                env={**os.environ, "PYTHONPATH": SRC, "HOME": "/"}, text=True)
            if proc.returncode not in (0, 2):
                pytest.skip(f"the user nobody cannot run this Python: {proc.stderr[-200:]}")
            status, err = proc.returncode, proc.stderr
        else:
            monkeypatch.setattr(os, "geteuid", lambda: 54321)
            status, _, err = cli("simulate", scene, "-o", out / "a.csv", "--events",
                                 sticky / "e.csv")
        line = refused(status, err, out, keep=tuple(keep))
        assert "--events" in line and "sticky" in line and ".part" not in line, line
        assert (sticky / "e.csv").read_text() == "old\n"
    finally:
        if how == "real":
            shutil.rmtree(out)


def _fail_rename(monkeypatch, nth: int) -> list[str]:
    """Make the ``nth`` rename into place of a commit fail (0: the first); returns the log."""
    from dumbbell import files

    calls: list[str] = []
    real = os.replace

    def replace(src, dst):
        if ".part" in os.fspath(src):
            calls.append(os.fspath(dst))
            if len(calls) == nth + 1:
                raise PermissionError(13, "Permission denied", os.fspath(dst))
        return real(src, dst)

    monkeypatch.setattr(files.os, "replace", replace)
    return calls


@pytest.mark.parametrize("nth", [0, 1])
@pytest.mark.parametrize("existing", [True, False])
def test_a_failed_rename_while_committing_restores_every_output(work, monkeypatch, nth,
                                                                existing):
    scene, out = work
    if existing:
        (out / "x.csv").write_text("old x\n")
        (out / "e.csv").write_text("old e\n")
    before = {n: (out / n).read_text() for n in files_in(out)}
    _fail_rename(monkeypatch, nth)
    status, _, err = cli("simulate", scene, "-o", out / "x.csv", "--events", out / "e.csv")
    line = refused(status, err, out, keep=tuple(before))
    assert {n: (out / n).read_text() for n in files_in(out)} == before
    assert not _no_temporary(out) and ".part" not in line
    assert str(out / ("x.csv" if nth == 0 else "e.csv")) in line, line


def test_a_commit_without_hard_links_moves_the_old_file_aside_and_back(work, monkeypatch):
    from dumbbell import files

    scene, out = work
    for n in ("x.csv", "e.csv"):
        (out / n).write_text(f"old {n}\n")

    def no_link(src, dst):
        raise OSError(1, "Operation not permitted")

    monkeypatch.setattr(files.os, "link", no_link)
    _fail_rename(monkeypatch, 1)
    status, _, err = cli("simulate", scene, "-o", out / "x.csv", "--events", out / "e.csv")
    refused(status, err, out, keep=("e.csv", "x.csv"))
    assert (out / "x.csv").read_text() == "old x.csv\n"
    assert (out / "e.csv").read_text() == "old e.csv\n"
    monkeypatch.undo()
    monkeypatch.setattr(files.os, "link", no_link)
    status, _, err = cli("simulate", scene, "-o", out / "x.csv", "--events", out / "e.csv",
                         "-q")
    assert status == 0 and (out / "x.csv").read_text().startswith("t,"), err
    assert files_in(out) == ["e.csv", "x.csv"]


def test_every_output_a_command_writes_was_checked_before_the_work(tmp_path, monkeypatch):
    """The planned names are the written ones: an output the command forgot to check first
    would show up in the transaction's ``unplanned``."""
    from dumbbell import files
    from tests.test_fuzz_cli import SHORT_2D

    seen: list[files.OutputTransaction] = []
    real = files.OutputTransaction.__init__

    def record(self, *args, **kwargs):
        real(self, *args, **kwargs)
        seen.append(self)

    monkeypatch.setattr(files.OutputTransaction, "__init__", record)
    # The outputs do not depend on how long the benchmark times a point: once is enough.
    from dumbbell.analysis import bench

    monkeypatch.setattr(bench, "MIN_TIMED", 0.0)
    scene = short_scene(tmp_path, extra="[outputs]\nfigures = [\"positions\"]\ncsv = true\n"
                        "gif = { fps = 10, t_end = 0.02 }\n")
    two = tmp_path / "short2d.toml"
    two.write_text(SHORT_2D, encoding="utf-8")
    cases = tmp_path / "cases"
    cases.mkdir()
    short_scene(cases)
    monkeypatch.chdir(tmp_path)
    for argv in (["run", scene, "--out", "o1"], ["render", scene, "--t-end", "0.02"],
                 ["play", scene, "--t-end", "0.02", "-o", "o7/x.html"],
                 ["compare", scene, "--out", "o2"], ["sweep", scene, "--grid", "k=100,200",
                                                     "--out", "o3", "--workers", "1"],
                 ["bench", scene, "--dts", "1e-3", "--t-end", "0.05", "--window", "0.05",
                  "--repeat", "1", "--out", "o4"],
                 ["simulate", scene, "-o", "x.csv", "--events", "e.csv"],
                 ["restitution", two, "--theta", "30", "--stiffness", "2e4", "--out", "o5"],
                 ["stability", "--cases", cases, "--solvers", "euler-cromer", "--out", "o6",
                  "--workers", "1"]):
        seen.clear()
        status, _, err = cli(*argv, "-q")
        assert status in (0, 3), (argv, err)
        assert seen and seen[-1].unplanned == [], (argv, seen[-1].unplanned)
        assert seen[-1].committed, argv
    assert not _no_temporary(tmp_path)


_SCRIPT = """
import os, signal, sys, time
from pathlib import Path
from dumbbell.files import atomic_output, output_transaction
how, out = sys.argv[1], Path(sys.argv[2])
if how == "handler":
    def handler(signum, frame):
        raise SystemExit(7)
    signal.signal(signal.SIGTERM, handler)
if how == "transaction":
    with output_transaction():
        with atomic_output(out / "a.csv") as tmp:
            tmp.write_text("a")
        with atomic_output(out / "b.csv") as tmp:
            tmp.write_text("b")
            print("ready", flush=True)
            while True: time.sleep(0.01)
elif how == "exit":
    manager = atomic_output(out / "a.csv")
    tmp = manager.__enter__()
    tmp.write_text("never finished")
    print("ready", flush=True)
    sys.exit(0)  # the block never ends: the interpreter's exit removes the file
else:
    with atomic_output(out / "a.csv") as tmp:
        tmp.write_text("a")
        print("ready", flush=True)
        while True: time.sleep(0.01)
"""


@pytest.mark.parametrize("how,sig,code", [
    ("default", signal.SIGTERM, -signal.SIGTERM),
    ("default", signal.SIGHUP, -signal.SIGHUP),
    ("default", signal.SIGINT, -signal.SIGINT),  # KeyboardInterrupt, then re-raised
    ("handler", signal.SIGTERM, 7),            # the script's own handler is kept
    ("transaction", signal.SIGTERM, -signal.SIGTERM),
    ("exit", None, 0),
])
def test_no_temporary_file_survives_a_signal_in_a_users_script(tmp_path, how, sig, code):
    out = tmp_path / "out"
    out.mkdir()
    proc = subprocess.Popen([sys.executable, "-c", _SCRIPT, how, str(out)],
                            env={**os.environ, "PYTHONPATH": SRC}, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=interruptible())  # noqa: PLW1509 - no thread forks here
    try:
        # Waits for the line (an event); the script then sleeps until the signal comes.
        assert proc.stdout.readline().strip() == "ready", proc.stderr.read()
        assert _no_temporary(out) or how == "exit"
        if sig is not None:
            proc.send_signal(sig)
        finish(proc)
    finally:
        end_group(proc)  # its sleep(60) must not outlive a failed test
    assert proc.returncode == code, proc.returncode
    assert files_in(out) == [], files_in(out)


def test_the_signal_handlers_come_back_after_a_write():
    from dumbbell.files import atomic_output

    before = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGHUP)}
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        import tempfile as tf

        with tf.TemporaryDirectory() as folder:
            with atomic_output(Path(folder) / "x.csv") as tmp:
                tmp.write_text("x")
                assert signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL
            assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL
    finally:
        for s, handler in before.items():
            signal.signal(s, handler)


# --- 9. any install, any user, any environment ----------------------------------------------


def _read_only_install(tmp_path: Path) -> tuple[Path, Path]:
    """A copy of the package that cannot be written (as pip --target would leave it after
    chmod -R a-w) and a HOME that cannot be written: (the copy's folder, HOME)."""
    import shutil

    pkg = tmp_path / "pkg"
    shutil.copytree(Path(SRC) / "dumbbell", pkg / "dumbbell",
                    ignore=shutil.ignore_patterns("__pycache__"))
    home = tmp_path / "home"
    home.mkdir()
    for root, dirs, names in os.walk(pkg):
        for n in names:
            os.chmod(os.path.join(root, n), 0o444)
        os.chmod(root, 0o555)
    os.chmod(home, 0o555)
    if os.geteuid() == 0:
        # Root ignores permissions; without its capabilities it keeps only the owner's, so
        # the copy and HOME go to another user.
        for root, dirs, names in os.walk(pkg):
            for n in [*dirs, *names]:
                os.lchown(os.path.join(root, n), 65534, 65534)
        os.lchown(pkg, 65534, 65534)
        os.chown(home, 65534, 65534)
    return pkg, home


def _as_user(argv: list[str], pkg: Path, home: Path, tmpdir: Path, cwd: Path,
             code: str | None = None, env: dict | None = None) -> subprocess.CompletedProcess:
    """``dumbbell ARGV`` from the read-only copy, HOME unwritable; as root without its
    capabilities (setpriv), so that permissions apply as they do to any user."""
    import shutil

    prefix: list[str] = []
    if os.geteuid() == 0:
        if not shutil.which("setpriv"):
            pytest.skip("needs setpriv to drop root's capabilities")
        prefix = ["setpriv", "--inh-caps=-all", "--bounding-set=-all"]
    site = [p for p in sys.path if p.endswith("site-packages")]
    code = code or "import sys; from dumbbell.cli import main; sys.exit(main())"
    environment = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "HOME": str(home),
                   "TMPDIR": str(tmpdir), "PYTHONPATH": os.pathsep.join([str(pkg), *site]),
                   "PYTHONDONTWRITEBYTECODE": "1", "CI": "1", **(env or {})}
    return run_group([*prefix, sys.executable, "-c", code, *argv], cwd=cwd,
                     env=environment, text=True)


@pytest.fixture
def read_only(tmp_path):
    pkg, home = _read_only_install(tmp_path)
    tmpdir, cwd = tmp_path / "tmp", tmp_path / "cwd"
    tmpdir.mkdir()
    cwd.mkdir()
    short_scene(cwd)
    os.chmod(cwd, 0o777)
    os.chmod(tmpdir, 0o1777)
    yield pkg, home, tmpdir, cwd
    for root, dirs, _ in os.walk(tmp_path):
        for d in dirs:
            os.chmod(os.path.join(root, d), 0o755)


def test_the_kernels_run_from_a_read_only_install_without_a_home(read_only):
    """The docker --user set-up: a read-only install, HOME not writable. numba caches in a
    private temporary folder, says so once, and the second run is silent and the same."""
    pkg, home, tmpdir, cwd = read_only
    first = _as_user(["simulate", "short.toml", "-o", "a.csv", "-q"], pkg, home, tmpdir, cwd)
    assert first.returncode == 0, first.stderr
    line = one_line_of(first.stderr)
    assert "numba cannot cache" in line and str(tmpdir) in line and "s a solver" in line
    second = _as_user(["simulate", "short.toml", "-o", "b.csv", "-q"], pkg, home, tmpdir, cwd)
    assert second.returncode == 0 and second.stderr == "", second.stderr
    assert (cwd / "a.csv").read_bytes() == (cwd / "b.csv").read_bytes()
    status, text, err = cli("simulate", cwd / "short.toml", "-q")
    assert status == 0 and text.encode() == (cwd / "a.csv").read_bytes(), err


def one_line_of(err: str) -> str:
    assert "Traceback" not in err, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_the_kernels_run_uncached_when_nothing_can_be_written(read_only):
    pkg, home, tmpdir, cwd = read_only
    os.chmod(tmpdir, 0o555)
    if os.geteuid() == 0:
        os.chown(tmpdir, 65534, 65534)
    # The temporary folder itself cannot be written (tempfile would fall back to /tmp).
    code = (f"import sys, tempfile; tempfile.tempdir = {str(tmpdir)!r}; "
            "from dumbbell.cli import main; sys.exit(main())")
    done = _as_user(["simulate", "short.toml", "--solver", "verlet", "-o", "v.csv", "-q"],
                    pkg, home, tmpdir, cwd, code=code)
    assert done.returncode == 0, done.stderr
    line = one_line_of(done.stderr)
    assert "cannot cache anywhere" in line and "every run" in line, line
    assert os.listdir(tmpdir) == []
    status, text, err = cli("simulate", cwd / "short.toml", "--solver", "verlet", "-q")
    assert status == 0 and text.encode() == (cwd / "v.csv").read_bytes(), err


@pytest.fixture(scope="module")
def numba_cache(tmp_path_factory):
    """One numba cache for the tests below, writable by anyone (they compile once)."""
    folder = tmp_path_factory.mktemp("numba-cache")
    os.chmod(folder, 0o1777)
    os.chmod(folder.parent, 0o755)
    return folder


@pytest.mark.parametrize("backend", ["nonsense", "module://no.such.backend"])
def test_any_mplbackend_leaves_the_figures_alone(read_only, numba_cache, backend):
    """The command writes files only: Agg, whatever MPLBACKEND says; with HOME unwritable
    matplotlib gets a private folder instead of its two-line warning."""
    pkg, home, _, cwd = read_only
    with open(cwd / "short.toml", "a", encoding="utf-8") as fh:
        fh.write('[outputs]\nfigures = ["positions"]\n')
    os.chmod(cwd / "short.toml", 0o644)
    # The shared temporary folder keeps matplotlib's private folder (its font cache).
    done = _as_user(["run", "short.toml", "--out", "r", "-q"], pkg, home, numba_cache, cwd,
                    env={"MPLBACKEND": backend, "NUMBA_CACHE_DIR": str(numba_cache)})
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert files_in(cwd / "r") == ["short-positions.png"]


def test_every_compiled_loop_takes_njit_from_the_install_module():
    """numba's njit used directly would fail from a read-only install: every module that
    compiles imports dumbbell._install.njit."""
    root = Path(dumbbell.__file__).parent
    direct = [str(p.relative_to(root)) for p in root.rglob("*.py")
              if p.name != "_install.py"
              and re.search(r"from numba import .*njit|numba\.njit|numba\.jit|from numba import jit",
                            p.read_text())]
    assert direct == []


# --- 10. work bounded before it starts (second round) ---------------------------------------


@pytest.mark.parametrize("flags,words", [
    (["--stiffness", *[str(200 + i) for i in range(2000)]], ["runs", "--stiffness", "--theta"]),
    (["--theta", "0:89:91", "--stiffness", *[str(200 + i) for i in range(10)]],
     ["1,001 runs", "--theta"]),
    (["--stiffness", "1e75"], ["--stiffness", "steps"]),
    (["--theta", "30", "--stiffness", "1e12"], ["--stiffness", "steps"]),
    (["--theta", "0:89:91", "--dt", "1e-7"], ["--theta", "--dt", "steps"]),
])
def test_restitution_caps_the_product_of_its_axes_before_any_run(tmp_path, monkeypatch,
                                                                 flags, words):
    from tests.test_fuzz_cli import SHORT_2D

    scene = tmp_path / "short2d.toml"
    scene.write_text(SHORT_2D, encoding="utf-8")
    out = tmp_path / "out"
    _stepping_forbidden(monkeypatch)
    status, _, err = cli("restitution", scene, *flags, "--out", out)
    line = refused(status, err)
    assert all(w in line for w in words) and "budget" in line, line
    assert "every =" not in line
    named = set(re.findall(r"(?<![\w-])--[a-z][a-z-]*", line))
    assert named <= _help_flags("restitution"), line
    assert not out.exists()


def test_restitution_fixes_are_the_ones_that_help(tmp_path, monkeypatch):
    """One tilt: 'fewer tilts' is no way out; soft springs step at dt: 'smaller
    stiffnesses' is none either."""
    from tests.test_fuzz_cli import SHORT_2D

    scene = tmp_path / "short2d.toml"
    scene.write_text(SHORT_2D, encoding="utf-8")
    _stepping_forbidden(monkeypatch)
    status, _, err = cli("restitution", scene, "--theta", "30", "--stiffness", "1e12",
                         "--out", tmp_path / "o")
    assert "--theta" not in refused(status, err)
    status, _, err = cli("restitution", scene, "--theta", "0:89:91", "--dt", "1e-7",
                         "--stiffness", "200", "--out", tmp_path / "o")
    line = refused(status, err)
    assert "--dt" in line and "--stiffness" not in line.split("budget")[-1], line


@pytest.mark.parametrize("command,flags,fix", [
    ("compare", ["--dt", *[f"{1e-3 / (1 + i * 1e-4):.10g}" for i in range(600)]], "--dt"),
    ("compare", ["--dt", "1e-9", "2e-9", "--t-end", "10"], "--t-end"),
    ("compare", ["--solvers", "pymunk", "euler-cromer", "verlet", "--dt",
                 *[f"{1e-3 / (1 + i * 1e-4):.10g}" for i in range(400)]], "--solvers"),
    ("bench", ["--dts", *[f"{1e-3 / (1 + i * 1e-4):.10g}" for i in range(600)]], "--dts"),
    # Memory: the runs a result keeps whole, all together, hold at most one run's samples.
    ("compare", ["--dt", "1e-3", "5e-4", "2.5e-4", "--t-end", "2000"], "--t-end"),
    ("bench", ["--dts", "1e-4", "5e-5", "--sample-spacing", "1e-4", "--t-end", "400",
               "--window", "1"], "--sample-spacing"),
])
def test_steps_times_solvers_are_capped_before_any_run(work, monkeypatch, command, flags, fix):
    scene, out = work
    _stepping_forbidden(monkeypatch)
    status, _, err = cli(command, scene, *flags, "--out", out)
    line = refused(status, err, out)
    assert "budget" in line and fix in line, line
    assert set(re.findall(r"(?<![\w-])--[a-z][a-z-]*", line)) <= _help_flags(command)


@pytest.mark.parametrize("many", ["cases", "solvers"])
def test_stability_caps_cases_times_solvers_before_any_run(tmp_path, monkeypatch, many):
    # 300 cases x 4 solvers, or 1,001 cases x 1 solver: past the 1,000 runs of the budget.
    cases = tmp_path / "cases"
    cases.mkdir()
    for i in range(300 if many == "solvers" else 1001):
        short_scene(cases, f"c{i:04d}.toml")
    solvers = ["euler-cromer", "verlet", "pymunk", "exact"] if many == "solvers" else ["verlet"]
    _stepping_forbidden(monkeypatch)
    status, _, err = cli("stability", "--cases", cases, "--solvers", *solvers,
                         "--out", tmp_path / "o")
    line = refused(status, err)
    assert "runs" in line and "budget" in line and "--cases" in line, line
    # Several solvers: fewer of them is a way out; one solver: it is not.
    assert ("--solvers" in line) is (many == "solvers")


def test_a_solver_named_many_times_runs_once(textbook):
    result = dumbbell.compare(textbook, solvers=["verlet"] * 600, t_end=0.05)
    assert [r.label for r in result.rows] == ["verlet"]


def test_the_strip_is_drawn_in_pieces_that_match_the_whole_tape():
    """The strip's tape is drawn piece by piece as frames reach it: any window cut from it
    is what the whole tape held there, and no more than the pieces under one window stay
    in memory."""
    from PIL import Image

    from dumbbell.animation.picture import describe
    from dumbbell.animation.render import frames_of
    from dumbbell.animation.strip import TAPE_CHUNK
    from dumbbell.animation.world import scene_painter

    traj = dumbbell.simulate(SCENES / "textbook-1d.toml", t_end=6.0, every=20)
    frames = frames_of(traj, 10, 6.0)
    painter = scene_painter(describe(traj.scene, (frames,), (640, 360), True))
    painter.background(0)
    tape, strip = painter.strip_source, painter.strip
    whole = Image.new("P", (tape.width, tape.height))
    for c0 in range(0, tape.width, TAPE_CHUNK):
        whole.paste(tape.piece(c0), (c0, 0))
    assert tape.width > 2 * TAPE_CHUNK  # several pieces
    tape.pieces.clear()
    most = 0
    for t in frames.t:
        left, _ = strip.offset(float(t))
        box = (left, 0, left + strip.inner_w, tape.height)
        assert tape.crop(box).tobytes() == whole.crop(box).tobytes(), t
        most = max(most, len(tape.pieces))
    assert most <= strip.inner_w // TAPE_CHUNK + 2


def test_a_memory_error_is_one_line(work, monkeypatch):
    import dumbbell.io.trajectory

    scene, out = work

    def no_memory(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(dumbbell.io.trajectory, "write_csv", no_memory)
    status, _, err = cli("simulate", scene, "-o", out / "x.csv")
    assert "memory" in refused(status, err, out)


# --- 11. messages ---------------------------------------------------------------------------


def _huge_values() -> dict[str, str]:
    return {"digits": "9" * 5000, "list": ",".join(str(i % 90) for i in range(10_000)),
            "word": "x" * 5000, "range": "0:80:" + "9" * 5000, "grid": "k=" + "1," * 5000 + "2"}


def _flag_cases() -> list[tuple[str, str, str]]:
    from tests.test_fuzz_cli import COMMANDS, FLAGS

    return [(c, f.names[0], kind) for c in COMMANDS for f in FLAGS[c] if f.metavar
            for kind in _huge_values()]


@pytest.mark.parametrize("command,flag,kind", _flag_cases())
def test_a_huge_value_is_echoed_at_most_200_characters(tmp_path, monkeypatch, command, flag,
                                                      kind):
    """Every flag of every command, given a huge value (5,000 digits, 10,000 tilts, a
    5,000-character word): one line, no run of more than 200 characters of it."""
    from tests.test_fuzz_cli import SHORT_2D

    value = _huge_values()[kind]
    scene = short_scene(tmp_path)
    if command == "restitution":
        scene.write_text(SHORT_2D, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    many = 50 if flag in ("--solvers", "--dts", "--dt", "--stiffness") else 1
    positional = [] if command == "stability" else [scene]
    extra = ["--grid", "k=1,2"] if command == "sweep" and flag != "--grid" else []
    status, _, err = cli(command, *positional, *extra, flag, *[value] * many)
    assert status == 2, (command, flag, err[:300])
    line = one_line_of(err)
    longest = max((len(w) for w in re.split(r"[\s'\",]", line)), default=0)
    assert longest <= 200 and len(line) <= 800, (len(line), line[:400])


@pytest.mark.parametrize("argv", [
    ["simulate", "x" * 5000 + ".toml"],
    ["simulate", "SCENE", "-o", "d/" * 2100 + "x.csv"],
    ["stability", "--cases", "c" * 5000],
    ["run", "SCENE", "--out", "o" * 5000],
])
def test_a_huge_path_is_one_short_line(tmp_path, monkeypatch, argv):
    scene = short_scene(tmp_path)
    monkeypatch.chdir(tmp_path)
    status, _, err = cli(*[str(scene) if a == "SCENE" else a for a in argv])
    line = refused(status, err)
    assert len(line) <= 600 and "nested too deeply" not in line, line


def test_the_api_echoes_a_huge_value_short():
    scene = load_scene(SCENES / "textbook-1d.toml")
    for call in (lambda: dumbbell.simulate(scene, solver="n" * 5000),
                 lambda: dumbbell.simulate(scene, dt=10**5000),
                 lambda: dumbbell.sweep(scene, {"k": ["x" * 5000, 1.0]})):
        with pytest.raises(DumbbellError) as info:
            call()
        assert len(str(info.value)) <= 400, str(info.value)[:300]


def test_a_closed_stdin_is_one_line(tmp_path):
    code = "import sys; from dumbbell.cli import main; sys.exit(main())"
    done = run_group([sys.executable, "-c", code, "simulate", "-", "-o",
                      str(tmp_path / "x.csv")], env={**os.environ, "PYTHONPATH": SRC},
                     text=True, preexec_fn=lambda: os.close(0))
    line = refused(done.returncode, done.stderr, tmp_path)
    assert "stdin" in line and "closed" in line and "NoneType" not in line, line


@pytest.mark.parametrize("value", ["0.0001", "1E-4", "0.00010000000000000000000001"])
def test_a_decimal_step_is_a_number(value):
    from decimal import Decimal

    scene = load_scene(SCENES / "textbook-1d.toml")
    traj = dumbbell.simulate(scene, dt=Decimal(value), t_end=Decimal("0.01"), every=1)
    plain = dumbbell.simulate(scene, dt=float(Decimal(value)), t_end=0.01, every=1)
    assert np.array_equal(traj["E"], plain["E"])
    with pytest.raises(DumbbellError, match="rounds to 0"):
        dumbbell.simulate(scene, dt=Decimal("1e-400"))
    with pytest.raises(DumbbellError, match="finite"):
        dumbbell.simulate(scene, dt=Decimal("NaN"))


@pytest.mark.parametrize("e,theta", [(0.05, 0.0), (0.1, 29.7)])
def test_restitution_works_on_a_nearly_inelastic_floor(monkeypatch, e, theta):
    """Below about 0.1 the dumbbell keeps hopping in flights shorter than the cluster's gap:
    it was refused with 'run longer', which no flag can do. The truth now needs only its
    first impact, and a cluster that ends at rest (E above its least value on the floor
    too small for a flight of the gap: the rigid drop at 0.1 and 29.7 degrees) leaves the
    floor at 0."""
    from dumbbell import solvers
    from dumbbell.analysis.restitution import (
        CLUSTER_GAP,
        _settled,
        drop_duration,
        e_eff_rigid,
        restitution,
        rigid_q,
        tilted,
    )

    # The runs restitution() makes, kept: its rigid pymunk drop is the one checked below.
    made = []
    simulate = solvers.simulate

    def keep(*args, **kwargs):
        made.append((args, kwargs, simulate(*args, **kwargs)))
        return made[-1][2]

    monkeypatch.setattr(solvers, "simulate", keep)
    scene = load_scene(SCENES / "tilted-2d.toml").with_values({"floor.elasticity": e})
    result = restitution(scene, [theta], (2e4,))
    monkeypatch.undo()
    # The truth's first impact is the impulse law's closed form.
    assert result.truth == pytest.approx(e_eff_rigid(result.theta, e, rigid_q(scene)),
                                         abs=1e-6)
    assert result.pymunk == pytest.approx(result.truth, abs=0.01)
    assert np.all(np.isfinite(result.springs[2e4]["e_eff"]))
    # The rigid drop at this tilt in pymunk at dt = 1e-5 s to the end of the cluster's gap,
    # every step: the run restitution() made for its 'pymunk' column.
    [(options, rigid)] = [(options, traj) for (drop, solver), options, traj in made
                          if solver == "pymunk" and drop == tilted(scene, theta)]
    assert options == {"dt": 1e-5, "t_end": drop_duration(scene), "every": 1}
    if _settled(rigid, CLUSTER_GAP):
        # At rest on the floor: E above M g y_rest below the energy of a 0.1 s flight.
        s = rigid.scene.system
        assert rigid["E"][-1] - s.M * s.g * s.A.radius < s.M * (s.g * CLUSTER_GAP) ** 2 / 8


@pytest.mark.parametrize("e", ["0", "1e-12"])
def test_restitution_on_a_floor_the_truth_cannot_leave_is_refused_up_front(tmp_path,
                                                                         monkeypatch, e):
    _stepping_forbidden(monkeypatch)
    status, _, err = cli("restitution", SCENES / "tilted-2d.toml", "--elasticity", e,
                         "--out", tmp_path / "o")
    line = refused(status, err)
    assert line.count("--elasticity") == 2 and "at least" in line, line
    least = float(line.rsplit("at least", 1)[1])
    assert least < 1e-6  # a value the flag takes, and no more than the solver needs


def test_the_repr_of_a_big_result_is_short():
    from dumbbell.analysis.sweep import Axis, PointResult, SweepResult

    scene = load_scene(SCENES / "textbook-1d.toml")
    values = tuple(float(k) for k in range(1, 10_001))
    rows = [PointResult((("spring.stiffness", k),), 0.1, "ok", None, 1e-3, "")
            for k in values]
    result = SweepResult(scene, [Axis("spring.stiffness", "k=...", values, "list")],
                         "euler-cromer", 1.0, rows)
    assert len(repr(result)) <= 1_000
