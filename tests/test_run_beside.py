"""``dumbbell run`` makes its figures and CSVs in a forked process beside the GIF
(:mod:`dumbbell.cli.beside`): the same bytes as one process making all, one after the other;
the child's errors are the command's; a child that dies leaves its work to the parent; a stop
signal stops both and leaves nothing; the command imports neither pyplot nor scipy.linalg."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from tests.hostile import (
    SHORT_SCENE,
    SRC,
    files_in,
    finish,
    group_left,
    marker_pipe,
    refused,
    run_group,
    started,
    wait_mark,
)

#: A short run of the textbook scene with every output: three figures, the CSVs, a GIF.
SCENE = SHORT_SCENE.replace("t_end = 0.05\ndt = 1e-4", "t_end = 2.0\ndt = 1e-4") + """
[outputs]
figures = ["positions", "kinetic", "potential"]
csv = true
gif = { fps = 10, size = "320x180", strip = true, t_end = 1.0 }
"""

#: Runs ``dumbbell ARGV`` in a fresh process, the fork forced on or off (FORK=1/0), after
#: PATCH (Python code) and prints which of the modules named in CHECK were imported.
RUNNER = """
import os, sys
import dumbbell.cli.beside as beside
if os.environ.get("FORK"):
    beside.side_by_side = lambda: os.environ["FORK"] == "1"
exec(os.environ.get("PATCH", ""))
from dumbbell.cli import main
status = main(sys.argv[1:])
for name in os.environ.get("CHECK", "").split():
    print(name, name in sys.modules)
sys.exit(status)
"""


def run(*argv: object, fork: bool | None = None, patch: str = "", check: str = "",
        cwd: Path | None = None) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": SRC, "CI": "1", "PATCH": patch, "CHECK": check,
           "FORK": "" if fork is None else str(int(fork))}
    return run_group([sys.executable, "-c", RUNNER, *argv], env=env, cwd=cwd, text=True)


@pytest.fixture
def scene(tmp_path):
    path = tmp_path / "beside.toml"
    path.write_text(SCENE)
    return path


def outputs_of(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


#: The modules whose import the runs below report (on stdout, after the command).
CHECKED = "matplotlib.pyplot scipy.linalg numba matplotlib"


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    """The command run once forked and once in one process (the same scene, every output),
    each reporting the modules :data:`CHECKED` it imported: {fork: (run, its folder)}.
    The tests below read these two runs instead of making them again each."""
    tmp = tmp_path_factory.mktemp("beside")
    path = tmp / "beside.toml"
    path.write_text(SCENE)
    return {fork: (run("run", path, "--out", tmp / name, fork=fork, check=CHECKED),
                   tmp / name)
            for fork, name in ((True, "forked"), (False, "alone"))}


def test_forked_and_one_process_write_the_same_bytes(both):
    (forked, forked_out), (alone, alone_out) = both[True], both[False]
    assert forked.returncode == alone.returncode == 0, (forked.stderr, alone.stderr)
    a, b = outputs_of(forked_out), outputs_of(alone_out)
    assert sorted(a) == ["beside-impacts.csv", "beside-kinetic.png", "beside-positions.png",
                         "beside-potential.png", "beside.csv", "beside.gif"]
    assert a == b
    # The same lines on stderr, in the order of the outputs.
    assert forked.stderr.replace("/forked/", "/alone/") == alone.stderr
    assert [line.split("/")[-1] for line in forked.stderr.splitlines()] == [
        "beside-positions.png", "beside-kinetic.png", "beside-potential.png", "beside.csv",
        "beside-impacts.csv", "beside.gif"]


def test_the_command_loads_neither_pyplot_nor_scipy_linalg(both):
    for fork in (True, False):
        done = both[fork][0]
        assert done.returncode == 0, done.stderr
        loaded = dict(line.split() for line in done.stdout.splitlines())
        assert loaded["matplotlib.pyplot"] == loaded["scipy.linalg"] == "False"
        assert loaded["numba"] == "True"
        # Forked, this process never draws: matplotlib stays in the child.
        assert loaded["matplotlib"] == str(not fork)


@pytest.mark.parametrize("fork", [True, False])
def test_an_error_drawing_a_figure_is_the_commands_own(scene, tmp_path, fork):
    patch = ("import dumbbell.cli.run as r\n"
             "from dumbbell.errors import UsageError\n"
             "def bad(name, traj): raise UsageError(f'cannot draw {name}')\n"
             "r._figure = bad\n")
    out = tmp_path / "out"
    done = run("run", scene, "--out", out, fork=fork, patch=patch)
    line = refused(done.returncode, done.stderr, code=2)
    assert line == "dumbbell run: error: cannot draw positions"
    assert not out.exists() or files_in(out) == []


def test_a_crash_in_the_child_is_raised_with_its_traceback(scene, tmp_path):
    patch = ("import dumbbell.cli.run as r\n"
             "def bad(name, traj): raise ZeroDivisionError('a bug in a figure')\n"
             "r._figure = bad\n")
    out = tmp_path / "out"
    done = run("run", scene, "--out", out, fork=True, patch=patch)
    assert done.returncode == 1
    assert "ZeroDivisionError: a bug in a figure" in done.stderr
    assert "in the process that drew the figures" in done.stderr
    assert not out.exists() or files_in(out) == []


def test_a_child_that_dies_leaves_its_work_to_the_parent(scene, tmp_path, both):
    # The child kills itself the moment it would draw: the parent draws instead.
    patch = ("import os, signal, dumbbell.cli.run as r, dumbbell.cli.beside as b\n"
             "draw = r._draw_figures\n"
             "def dying(files, traj, alive):\n"
             "    if b._IN_CHILD: os.kill(os.getpid(), signal.SIGKILL)\n"
             "    return draw(files, traj, alive)\n"
             "r._draw_figures = dying\n")
    died = run("run", scene, "--out", tmp_path / "died", fork=True, patch=patch)
    alone, alone_out = both[False]
    assert died.returncode == alone.returncode == 0, died.stderr
    assert outputs_of(tmp_path / "died") == outputs_of(alone_out)


#: The child waits in its first figure, the parent in the GIF's second frame, each after a
#: line on the marker pipe MARK_FD: the test signals once both are there.
BOTH_BUSY = """
import os, time
import dumbbell.cli.run as r, dumbbell.cli.beside as b
from dumbbell.animation import painter
def _mark(who):
    os.write(int(os.environ["MARK_FD"]), who.encode() + b"\\n")
    while True: time.sleep(0.01)
draw = r._draw_figures
def waiting(files, traj, alive):
    if b._IN_CHILD:
        _mark("child")
    return draw(files, traj, alive)
r._draw_figures = waiting
frame = painter.Painter.frame
def slow(self, k):
    if k == 1 and not b._IN_CHILD:
        _mark("parent")
    return frame(self, k)
painter.Painter.frame = slow
"""


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_stop_signal_stops_the_child_and_leaves_nothing(scene, tmp_path, sig):
    """Signalled while the child draws a figure and the parent writes the GIF (each waits
    there, after saying so): both stop, nothing is left, whatever the machine's load."""
    out = tmp_path / "out"
    forked = "import dumbbell.cli.beside as _b\n_b.side_by_side = lambda: True\n"
    with marker_pipe() as (r, w), started("run", scene, "--out", out, pass_fds=(w,),
                                          prelude=forked + BOTH_BUSY,
                                          env={"MARK_FD": str(w)}) as proc:
        marks = b""
        while marks.count(b"\n") < 2:
            marks += wait_mark(proc, r)
        assert sorted(marks.split()) == [b"child", b"parent"]
        proc.send_signal(sig)
        _, err = finish(proc)
        assert not group_left(proc), "the child outlived the command"
    line = refused(proc.returncode, err, out, code=128 + sig)
    assert signal.Signals(sig).name in line


def test_one_cpu_or_another_thread_means_no_fork(monkeypatch):
    from dumbbell.cli import beside

    monkeypatch.setattr(beside, "_IN_CHILD", False)
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1})
    if sys.platform.startswith("linux") and threading.active_count() == 1:
        assert beside.side_by_side()
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0})
    assert not beside.side_by_side()
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1})
    stop = threading.Event()
    worker = threading.Thread(target=stop.wait)
    worker.start()
    try:
        assert not beside.side_by_side()
    finally:
        stop.set()
        worker.join()


def test_the_pipe_carries_a_trajectory_whole():
    from dumbbell.cli.beside import _receive, _send
    from dumbbell.model.scene import load_scene, packaged_scene
    from dumbbell.solvers import simulate

    traj = simulate(load_scene(packaged_scene()), "exact", t_end=1.0, every=10)
    r, w = os.pipe()
    sender = threading.Thread(target=_send, args=(w, traj))
    sender.start()
    got = _receive(r)
    sender.join()
    assert got.columns == traj.columns and got.events == traj.events
    assert got.verdict == traj.verdict and got.solver == traj.solver
    for name in traj.columns:
        assert np.array_equal(got[name], traj[name])
    # Nothing sent (the parent gave up): None.
    r, w = os.pipe()
    os.close(w)
    assert _receive(r) is None


def test_the_library_keeps_pyplot_and_the_command_does_without(tmp_path):
    """Outside the command a figure is pyplot's (a notebook shows it); within it, a bare
    Figure; saved, the two are the same bytes."""
    plt = pytest.importorskip("matplotlib.pyplot")
    from dumbbell import plot
    from dumbbell._install import command_line
    from dumbbell.io.figures import save_figure
    from dumbbell.model.scene import load_scene, packaged_scene
    from dumbbell.solvers import simulate

    traj = simulate(load_scene(packaged_scene()), "exact", t_end=2.0, every=100)
    ax = plot.kinetic(traj)
    assert ax.figure.number in plt.get_fignums()
    save_figure(ax.figure, tmp_path / "pyplot.png")
    assert ax.figure.number not in plt.get_fignums()  # closed once saved
    with command_line():
        bare = plot.kinetic(traj)
    assert bare.figure not in [plt.figure(n) for n in plt.get_fignums()]
    save_figure(bare.figure, tmp_path / "bare.png")
    assert (tmp_path / "pyplot.png").read_bytes() == (tmp_path / "bare.png").read_bytes()


def test_a_slow_first_use_says_it_compiles_once(monkeypatch, capsys):
    """The line shows when a kernel's first use outlasts a load from the cache, on a
    terminal only, once per solver and process. No clock: 'quick' is a block that ends
    before a wait of 600 s does, 'slow' one that waits, inside, until the timer (set to
    0 s) has done whatever it does."""
    import threading

    from dumbbell import _install, progress

    def slow() -> None:
        for thread in threading.enumerate():
            if thread.name == "dumbbell-compiling":
                thread.join()

    monkeypatch.setattr(_install, "_compiling_said", set())
    monkeypatch.delenv(_install._SAID, raising=False)
    watching = {"yes": True}
    monkeypatch.setattr(progress, "_progress_wanted", lambda quiet=False: watching["yes"]
                        and not quiet)
    monkeypatch.setattr(_install, "COMPILE_NOTE_AFTER", 600.0)
    with _install.compiling("the test solver's kernels", quiet=False):
        pass  # a load from the cache: quick
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(_install, "COMPILE_NOTE_AFTER", 0.0)
    with _install.compiling("the test solver's kernels", quiet=True):
        slow()  # slow, but -q
    assert capsys.readouterr().err == ""
    watching["yes"] = False
    with _install.compiling("the test solver's kernels", quiet=False):
        slow()  # slow, but not on a terminal (or CI)
    assert capsys.readouterr().err == ""
    watching["yes"] = True
    for _ in range(2):
        with _install.compiling("the test solver's kernels", quiet=False):
            slow()
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith("dumbbell: compiling the test solver's kernels with numba (the first "
                          "run after an install or upgrade")
