"""Hostile input, third round (issue 30): a stop always stops, no output emptied or written
through a link, exit 0 only when the outputs exist, no traceback a CLI user sees, the
Python API's output paths, bounded messages and bounded scene reads.

Every test that needs a process in a given state waits for an event (a line on a marker pipe
written by the process when it gets there), never for a time; every process is started in
a session of its own and its whole group is killed on the way out, pass or fail
(:func:`tests.hostile.started`)."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

from tests.conftest import SCENES
from tests.hostile import (
    cli,
    files_in,
    finish,
    group_left,
    marker_pipe,
    one_line,
    refused,
    short_scene,
    started,
    wait_mark,
)

STOPS = [signal.SIGTERM, signal.SIGHUP, signal.SIGINT]


# --- 1. a stop always stops -----------------------------------------------------------------

#: Run before ``main`` in the child: the first floor callback pymunk makes in this process
#: (MARK_AT: the _FloorLog method, '_begin' or '_post_solve') either sends the process
#: MARK_SIGNAL itself (MARK_HOW=self: the signal arrives inside the callback for sure) or
#: writes a line on the marker pipe MARK_FD and sleeps inside the callback until the test's
#: signal ends the sleep (MARK_HOW=wait).
IN_CALLBACK = """
import os, time
from dumbbell.solvers import engine as _engine
_main = os.getpid()
_real = getattr(_engine._FloorLog, os.environ["MARK_AT"])
_done = []
def _marked(self, arbiter, space, data):
    if not _done and os.getpid() == _main:
        _done.append(1)
        if os.environ["MARK_HOW"] == "self":
            os.kill(_main, int(os.environ["MARK_SIGNAL"]))
        else:
            os.write(int(os.environ["MARK_FD"]), b"in a pymunk callback\\n")
            while True: time.sleep(0.01)
    return _real(self, arbiter, space, data)
setattr(_engine._FloorLog, os.environ["MARK_AT"], _marked)
"""


def _stopped_in_a_callback(argv: list[object], sig: int, how: str, at: str,
                           cwd: Path) -> tuple[int, str]:
    """Run ``dumbbell ARGV`` and stop it by ``sig`` inside pymunk's first floor callback
    ``at``; (exit status, stderr)."""
    with marker_pipe() as (r, w):
        env = {"MARK_FD": str(w), "MARK_AT": at, "MARK_HOW": how, "MARK_SIGNAL": str(int(sig))}
        with started(*argv, cwd=cwd, prelude=IN_CALLBACK, env=env, pass_fds=(w,)) as proc:
            if how == "wait":
                wait_mark(proc, r)
                proc.send_signal(sig)
            _, err = finish(proc)
            assert not group_left(proc), "a process of the command outlived it"
            return proc.returncode, err


def _old_outputs(folder: Path, names) -> dict[str, bytes]:
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        (folder / name).write_bytes(f"old {name}\n".encode())
    return {name: (folder / name).read_bytes() for name in names}


@pytest.mark.parametrize("sig", STOPS, ids=lambda s: signal.Signals(s).name)
@pytest.mark.parametrize("how,at", [("wait", "_post_solve"), ("self", "_post_solve"),
                                    ("self", "_begin")])
def test_a_stop_inside_a_pymunk_callback_stops_run(tmp_path, sig, how, at):
    """`dumbbell run scenes/topple-2d.toml --out r -q` stopped while pymunk ran a contact
    callback: cffi printed 'Exception ignored from cffi callback ... Stopped: 15', the run
    went on and exited 0, replacing the old GIF. Now: 128+N, the old outputs, nothing else."""
    old = _old_outputs(tmp_path / "r", ["topple-2d.gif", "topple-2d-topple.png"])
    status, err = _stopped_in_a_callback(
        ["run", SCENES / "topple-2d.toml", "--out", "r", "-q"], sig, how, at, tmp_path)
    assert status == 128 + sig, err
    line = one_line(err)
    assert signal.Signals(sig).name in line and "cffi" not in err, err
    assert {n: (tmp_path / "r" / n).read_bytes() for n in files_in(tmp_path / "r")} == old


@pytest.mark.parametrize("command", ["simulate", "render", "compare", "play"])
def test_a_stop_inside_a_pymunk_callback_stops_every_command(tmp_path, command):
    """The same for the other commands that step pymunk: the rigid drop of
    scenes/rigid-2d.toml (impacts, then contact) in simulate, render, compare and play."""
    out = tmp_path / "out"
    argv = {"simulate": ["simulate", SCENES / "rigid-2d.toml", "--solver", "pymunk", "-o",
                         out / "x.csv", "--events", out / "e.csv"],
            "render": ["render", SCENES / "rigid-2d.toml", "-o", out / "x.gif"],
            "compare": ["compare", SCENES / "rigid-2d.toml", "--solvers", "pymunk", "exact",
                        "--out", out],
            "play": ["play", SCENES / "rigid-2d.toml", "--solvers", "pymunk", "exact", "-o",
                     out / "x.html"]}[command]
    old = _old_outputs(out, ["x.csv", "x.gif", "x.html"])
    status, err = _stopped_in_a_callback(argv, signal.SIGTERM, "wait", "_begin", tmp_path)
    assert status == 128 + signal.SIGTERM, err
    assert "SIGTERM" in one_line(err)
    assert {n: (out / n).read_bytes() for n in files_in(out)} == old


@pytest.mark.parametrize("second", [False, True], ids=["alone", "then HUP"])
def test_a_stop_swallowed_by_python_code_still_stops(tmp_path, second):
    """A stop whose exception some code swallows (here a callback of the user's, in Python,
    that catches everything) is not forgotten: the command goes on but keeps nothing, and
    exits 128+N; a second signal meanwhile is not ignored (it stops the command at once)."""
    prelude = """
import os, time
from dumbbell.solvers import engine as _engine
_real = _engine._FloorLog._begin
_done = []
def _swallow(self, arbiter, space, data):
    if not _done:
        _done.append(1)
        try:
            os.write(int(os.environ["MARK_FD"]), b"ready\\n")
            while True: time.sleep(0.01)
        except BaseException:
            pass
        os.write(int(os.environ["MARK_FD"]), b"swallowed\\n")
        if os.environ["SECOND"]:
            while True: time.sleep(0.01)  # only a second signal ends this
    return _real(self, arbiter, space, data)
_engine._FloorLog._begin = _swallow
"""
    out = tmp_path / "out"
    old = _old_outputs(out, ["x.csv"])
    env = {"MARK_FD": "", "SECOND": "1" if second else ""}
    with marker_pipe() as (r, w):
        env["MARK_FD"] = str(w)
        with started("simulate", SCENES / "rigid-2d.toml", "-o", out / "x.csv", cwd=tmp_path,
                     prelude=prelude, env=env, pass_fds=(w,)) as proc:
            assert wait_mark(proc, r) == b"ready\n"
            proc.send_signal(signal.SIGTERM)
            assert wait_mark(proc, r) == b"swallowed\n"
            if second:
                proc.send_signal(signal.SIGHUP)
            _, err = finish(proc)
            assert not group_left(proc)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert "SIGTERM" in one_line(err)
    assert {n: (out / n).read_bytes() for n in files_in(out)} == old


def test_a_second_signal_during_the_cleanup_is_ignored_but_not_after():
    """The handler: a second stop while the first one's exception is being handled (its
    cleanup) does nothing; outside that (the first was swallowed) it raises again, for the
    first signal."""
    from dumbbell.cli import app

    with app._stop_signals():
        handler = signal.getsignal(signal.SIGTERM)
        with pytest.raises(app.Stopped) as first:
            handler(signal.SIGTERM, None)
        assert first.value.signum == signal.SIGTERM
        try:
            raise first.value
        except app.Stopped:
            handler(signal.SIGHUP, None)      # ignored: the cleanup goes on
            try:
                raise OSError("a cleanup's own error")
            except OSError:
                handler(signal.SIGHUP, None)  # still ignored: the stop is its context
        with pytest.raises(app.Stopped) as again:
            handler(signal.SIGHUP, None)      # the first was swallowed: it stops again
        assert again.value.signum == signal.SIGTERM
    assert signal.getsignal(signal.SIGTERM) is not handler


@pytest.mark.slow
def test_run_all_stops_inside_a_pymunk_callback(tmp_path):
    """`run --all` hit by HUP at 9 s (in a pymunk callback) was still running 30 s later:
    the lost stop had set every stop signal to ignored. It stops, the 21 showcase files
    stay old, nothing is left."""
    from dumbbell.cli.showcase import tracked

    old = _old_outputs(tmp_path / "r", sorted(tracked()))
    status, err = _stopped_in_a_callback(["run", "--all", "--out", "r", "-q"], signal.SIGHUP,
                                         "wait", "_post_solve", tmp_path)
    assert status == 128 + signal.SIGHUP, err
    assert "SIGHUP" in one_line(err)
    assert {n: (tmp_path / "r" / n).read_bytes() for n in files_in(tmp_path / "r")} == old


# --- 2. a figure named twice empties no file ------------------------------------------------


@pytest.mark.parametrize("scene,figures", [
    ("textbook-1d", ["positions", "positions"]),
    ("textbook-1d", ["kinetic", "positions", "kinetic"]),
    ("tilted-2d", ["energy", "rotation", "energy"]),
    ("textbook-1d", ["positions"] * 60_000),
])
def test_a_figure_named_twice_is_refused_at_load(tmp_path, scene, figures):
    """`figures = ["positions", "positions"]`: `run` exited 0 and an existing valid
    r/NAME-positions.png became 0 bytes (60,000 entries alike). Refused when the scene is
    read: one line naming the key and the figure, nothing written, the old file kept."""
    from dumbbell import SceneError, load_scene
    from tests.hostile import cli

    text = (SCENES / f"{scene}.toml").read_text()
    start = text.index("figures = [")
    text = text[:start] + "figures = [" + ", ".join(f'"{f}"' for f in figures) + "]" \
        + text[text.index("]", start) + 1:]
    path = tmp_path / "twice.toml"
    path.write_text(text)
    with pytest.raises(SceneError, match=rf"outputs\.figures .*'{figures[-1]}' more than once"):
        load_scene(path)
    with pytest.raises(SceneError, match="more than once"):
        load_scene(SCENES / f"{scene}.toml").with_values({"outputs.figures": figures})
    out = tmp_path / "r"
    out.mkdir()
    png = out / f"twice-{figures[-1]}.png"
    png.write_bytes(b"\x89PNG old")
    status, _, err = cli("run", path, "--out", out, "-q")
    line = refused(status, err, out, keep=(png.name,))
    assert "outputs.figures" in line and len(line) < 400, line
    assert png.read_bytes() == b"\x89PNG old"


def test_the_output_plan_refuses_two_outputs_on_one_path(tmp_path, monkeypatch):
    """Whatever builds the list: a plan naming one file twice is refused before the work,
    and a command that writes one file twice fails before its commit, the old file kept."""
    import dataclasses

    from dumbbell import DumbbellError, load_scene
    from dumbbell.cli import run as run_command
    from dumbbell.files import OutputTransaction, atomic_output, output_transaction
    from tests.hostile import cli

    out = tmp_path / "r"
    out.mkdir()
    with pytest.raises(DumbbellError, match="same file"):
        OutputTransaction().plan([out / "a.png", out / "." / "a.png"], f"--out {out}")
    # A scene built around the check (figures listed twice) reaches the plan: refused there.
    scene = load_scene(SCENES / "textbook-1d.toml")
    twice = dataclasses.replace(scene, outputs=dataclasses.replace(
        scene.outputs, figures=("positions", "kinetic", "positions")))
    monkeypatch.setattr("dumbbell.cli.app.read_scene", lambda *a, **k: twice)
    (out / "textbook-1d-positions.png").write_bytes(b"old")
    status, _, err = cli("run", SCENES / "textbook-1d.toml", "--out", out, "-q")
    line = refused(status, err, out, keep=("textbook-1d-positions.png",))
    assert "textbook-1d-positions.png" in line and "same file" in line, line
    assert run_command.outputs(twice, out).count(
        ("positions", out / "textbook-1d-positions.png")) == 2
    # Two writes of one file in one transaction: the second is refused, nothing committed.
    with pytest.raises(DumbbellError, match="written twice"), output_transaction():
        with atomic_output(out / "textbook-1d-positions.png") as tmp:
            tmp.write_bytes(b"new")
        with atomic_output(out / "./textbook-1d-positions.png") as tmp:
            tmp.write_bytes(b"")
    assert files_in(out) == ["textbook-1d-positions.png"]
    assert (out / "textbook-1d-positions.png").read_bytes() == b"old"


# --- 3. links planted in the output folder ---------------------------------------------------

#: A 1D scene whose `run` writes its CSVs, a GIF and a figure: out-1d.csv, out-1d-impacts.csv,
#: out-1d.gif, out-1d-positions.png.
OUT_1D_EXTRA = ('[outputs]\nfigures = ["positions"]\ncsv = true\n'
                'gif = { fps = 10, t_end = 0.02, size = "64x64" }\n')


@pytest.fixture
def planted(tmp_path):
    """(the scene out-1d.toml, the output folder r, a folder outside it holding victim)."""
    scene = short_scene(tmp_path, "out-1d.toml", OUT_1D_EXTRA)
    out, outside = tmp_path / "r", tmp_path / "outside"
    out.mkdir()
    outside.mkdir()
    (outside / "victim").write_text("victim\n")
    return scene, out, outside


def _untouched(outside: Path) -> None:
    assert files_in(outside) == ["victim"], files_in(outside)
    assert (outside / "victim").read_text() == "victim\n"


@pytest.mark.parametrize("name", ["out-1d.csv", "out-1d-impacts.csv", "out-1d.gif",
                                  "out-1d-positions.png"])
@pytest.mark.parametrize("how", ["absolute", "relative", "chain", "dangling"])
def test_a_link_out_of_the_folder_is_refused_before_the_work(planted, monkeypatch, name, how):
    """`ln -s OUTSIDE/victim r/out-1d.csv; dumbbell run out-1d.toml --out r` overwrote the
    file outside r; a link to nothing created its folders outside r. Refused before the run,
    one line naming the link and where it leads; nothing outside is touched or created."""
    from tests.test_hostile import _stepping_forbidden

    scene, out, outside = planted
    link = out / name
    if how == "absolute":
        link.symlink_to(outside / "victim")
    elif how == "relative":
        link.symlink_to(Path("..") / "outside" / "victim")
    elif how == "chain":  # a link in the folder, to a link in the folder, to outside
        (out / "step").symlink_to(outside / "victim")
        link.symlink_to("step")
    else:
        link.symlink_to(outside / "new" / "deep" / "victim")
    keep = tuple(files_in(out))
    _stepping_forbidden(monkeypatch)
    status, _, err = cli("run", scene, "--out", out, "-q")
    line = refused(status, err, out, keep=keep)
    assert name in line and "outside" in line and "link" in line, line
    _untouched(outside)


@pytest.mark.parametrize("argv", [["simulate", "SCENE", "-o", "OUT/x.csv"],
                                  ["simulate", "SCENE", "-o", "-", "--events", "OUT/x.csv"],
                                  ["render", "SCENE", "-o", "OUT/x.gif", "--t-end", "0.02"],
                                  ["play", "SCENE", "-o", "OUT/x.html", "--t-end", "0.02"]])
def test_a_file_flag_naming_a_link_out_of_its_folder_is_refused(planted, argv):
    scene, out, outside = planted
    name = Path(next(a for a in argv if a.startswith("OUT/"))).name
    (out / name).symlink_to(outside / "victim")
    status, _, err = cli(*[str(scene) if a == "SCENE" else a.replace("OUT", str(out))
                           for a in argv])
    line = refused(status, err, out, keep=(name,))
    assert name in line and "outside" in line, line
    _untouched(outside)


def test_run_all_refuses_a_link_out_of_the_folder_before_any_piece(tmp_path, monkeypatch):
    """`run --all` made `.victim.XXXX.part` beside a link's target (and replaced it)."""
    from tests.test_hostile import _stepping_forbidden

    out, outside = tmp_path / "r", tmp_path / "outside"
    out.mkdir()
    outside.mkdir()
    (outside / "victim").write_text("victim\n")
    (out / "rigid-2d.gif").symlink_to(outside / "victim")
    _stepping_forbidden(monkeypatch)
    status, _, err = cli("run", "--all", "--out", out, "-q")
    line = refused(status, err, out, keep=("rigid-2d.gif",))
    assert "rigid-2d.gif" in line and "outside" in line, line
    _untouched(outside)


@pytest.mark.parametrize("where", ["plain", "sticky"])
@pytest.mark.parametrize("how", ["real", "simulated"])
def test_another_users_link_is_never_written_through(planted, monkeypatch, where, how):
    """A link another user made (in a sticky folder, followed when root ran the command):
    never written through, even to a file inside the folder. 'real': the link handed to
    uid 12345 (root only); 'simulated': this user pretends to be another (os.geteuid)."""
    scene, out, _ = planted
    folder = out / "st" if where == "sticky" else out
    folder.mkdir(exist_ok=True)
    if where == "sticky":
        os.chmod(folder, 0o1777)
    (folder / "mine.csv").write_text("mine\n")
    link = folder / "e.csv"
    link.symlink_to(folder / "mine.csv")
    if how == "real":
        if os.geteuid() != 0:
            pytest.skip("needs root to hand a link to another user")
        os.lchown(link, 12345, 12345)
    else:
        me = os.geteuid()
        monkeypatch.setattr(os, "geteuid", lambda: me + 4321)
    keep = tuple(files_in(out))
    status, _, err = cli("simulate", scene, "-o", out / "x.csv", "--events", link)
    line = refused(status, err, out, keep=keep)
    assert "--events" in line and "another user" in line and "e.csv" in line, line
    assert (folder / "mine.csv").read_text() == "mine\n"


def test_the_users_own_link_inside_the_folder_is_written_through(planted):
    """The user's own link to a file inside the folder (a subfolder too): the file it names
    gets the output, the link stays, and the temporary file sat in the folder."""
    scene, out, outside = planted
    (out / "archive").mkdir()
    (out / "out-1d.csv").symlink_to(Path("archive") / "v2.csv")        # not there yet
    (out / "archive" / "v1.gif").write_bytes(b"old")
    (out / "out-1d.gif").symlink_to(out / "archive" / "v1.gif")
    status, _, err = cli("run", scene, "--out", out, "-q")
    assert status == 0, err
    assert (out / "out-1d.csv").is_symlink() and (out / "out-1d.gif").is_symlink()
    assert (out / "archive" / "v2.csv").read_text().startswith("t,xA,vA")
    assert (out / "archive" / "v1.gif").read_bytes()[:6] == b"GIF89a"
    _untouched(outside)


def test_a_link_planted_after_the_check_is_refused_at_the_write(planted, monkeypatch):
    """Between the check and the write (a run can take minutes) a link appears: the write
    refuses it too; nothing outside is written and the command keeps nothing."""
    from dumbbell.io import trajectory

    scene, out, outside = planted
    real = trajectory.write_events

    def plant_then_write(traj, path):
        Path(path).symlink_to(outside / "victim")
        return real(traj, path)

    monkeypatch.setattr(trajectory, "write_events", plant_then_write)
    status, _, err = cli("simulate", scene, "-o", out / "x.csv", "--events", out / "e.csv")
    line = refused(status, err, out, keep=("e.csv",))
    assert "e.csv" in line and "outside" in line, line
    _untouched(outside)


def test_the_python_api_refuses_a_link_out_of_the_folder(planted):
    import dumbbell
    from dumbbell import DumbbellError
    from dumbbell.io.trajectory import write_csv

    scene, out, outside = planted
    (out / "x.csv").symlink_to(outside / "victim")
    traj = dumbbell.simulate(scene, t_end=0.01)
    with pytest.raises(DumbbellError, match="outside") as info:
        write_csv(traj, out / "x.csv")
    assert len(str(info.value).splitlines()) == 1
    _untouched(outside)
    assert files_in(out) == ["x.csv"]


# --- 4. exit 0 only when every output exists ------------------------------------------------

#: Per command: its arguments (SCENE: a short 1D scene with every output of `run`; 2D: the
#: short 2D scene; CASES: a catalogue of one short scene), writing into the folder OUT.
STREAM_COMMANDS = {
    "compare": ["compare", "SCENE", "--t-end", "0.05", "--out", "OUT"],
    "restitution": ["restitution", "2D", "--theta", "30", "--stiffness", "2e4", "--out", "OUT"],
    "run": ["run", "SCENE", "--out", "OUT"],
    "render": ["render", "SCENE", "--t-end", "0.04", "-o", "OUT/x.gif"],
    "play": ["play", "SCENE", "--t-end", "0.04", "-o", "OUT/x.html"],
    "simulate": ["simulate", "SCENE", "-o", "OUT/x.csv", "--events", "OUT/e.csv"],
    # One solver: the others' timed runs (each point timed for half a second) take seconds
    # and print and write through the same lines.
    "bench": ["bench", "SCENE", "--dts", "1e-3", "--t-end", "0.05", "--window", "0.05",
              "--repeat", "1", "--solvers", "euler-cromer", "--out", "OUT"],
    "sweep": ["sweep", "SCENE", "--grid", "k=100,200", "--workers", "1", "--out", "OUT"],
    "stability": ["stability", "--cases", "CASES", "--solvers", "euler-cromer", "--workers",
                  "1", "--out", "OUT"],
}

#: How standard output and error are lost: closed when the process starts (`>&-`, `2>&-`),
#: or a pipe whose reader has gone before the first write.
STREAM_LOSSES = ["stdout closed", "stderr closed", "stdout reader gone", "stderr reader gone",
                 "both closed", "both readers gone"]


def _stream_cases():
    """Each way alone on `run` (which writes to both streams; both closed at once is
    `compare`'s and `restitution`'s case); both streams lost, each way, on `compare`; one way
    each on the other commands the issue names (`restitution` closed, `render` readers gone)
    and both readers gone on the rest. The streams are one piece of code (cli.app's sturdy
    streams) whatever the command: more cases would run the same lines again, a few seconds
    each."""
    return ([("run", how) for how in STREAM_LOSSES if how != "both closed"]
            + [("compare", "both closed"), ("compare", "both readers gone"),
               ("restitution", "both closed"), ("render", "both readers gone")]
            + [(c, "both readers gone") for c in STREAM_COMMANDS
               if c not in ("run", "compare", "restitution", "render")])


#: command -> the files it writes on a terminal (the reference run, made once).
_EXPECTED: dict[str, list[str]] = {}


@pytest.fixture
def stream_inputs(tmp_path):
    from tests.test_fuzz_cli import SHORT_2D

    inputs = tmp_path / "in"
    inputs.mkdir()
    scene = short_scene(inputs, "streams.toml", OUT_1D_EXTRA)
    two = inputs / "short2d.toml"
    two.write_text(SHORT_2D, encoding="utf-8")
    (inputs / "cases").mkdir()
    short_scene(inputs / "cases")
    return {"SCENE": str(scene), "2D": str(two), "CASES": str(inputs / "cases")}


def _argv(command: str, inputs: dict[str, str], out: Path) -> list[str]:
    return [inputs.get(a, a).replace("OUT", str(out)) for a in STREAM_COMMANDS[command]]


@pytest.mark.parametrize("command,how", _stream_cases())
def test_losing_the_terminal_loses_no_file(tmp_path, stream_inputs, command, how):
    """With stdout or stderr a closed descriptor or a pipe whose reader has gone, `compare`,
    `restitution`, `run`, `render` (and the others) exited 0 and wrote nothing (`run ...
    2>&-` exited 1). They write every file they write on a terminal, and exit 0."""
    import subprocess

    if command not in _EXPECTED:
        reference = tmp_path / "reference"
        status, _, err = cli(*_argv(command, stream_inputs, reference))
        assert status == 0, err
        _EXPECTED[command] = files_in(reference)
    expected = _EXPECTED[command]
    out = tmp_path / "out"
    streams, pipes, closed = {}, [], []
    for name, fd in (("stdout", 1), ("stderr", 2)):
        if how.startswith((name, "both")):
            if "closed" in how:
                closed.append(fd)
            else:
                r, w = os.pipe()
                os.close(r)  # the reader is gone before the first write
                streams[name] = w
                pipes.append(w)
    closing = (lambda: [os.close(fd) for fd in closed]) if closed else None
    with started(*_argv(command, stream_inputs, out), cwd=tmp_path,
                 preexec_fn=closing, **{"stdout": subprocess.DEVNULL,
                                        "stderr": subprocess.DEVNULL, **streams}) as proc:
        for w in pipes:
            os.close(w)
        assert proc.wait(timeout=600) == 0, (command, how, proc.returncode)
        assert not group_left(proc)
    assert files_in(out) == expected


def test_simulate_to_a_closed_stdout_is_refused(tmp_path, stream_inputs):
    """`simulate` writes its CSV to standard output: closed when it starts, that is a
    refusal before the run (exit 2), not a run into nothing."""
    import subprocess

    for argv in (["simulate", stream_inputs["SCENE"]],
                 ["simulate", stream_inputs["SCENE"], "-o", "-", "--events", "e.csv"]):
        with started(*argv, cwd=tmp_path, stdout=subprocess.DEVNULL,
                     preexec_fn=lambda: os.close(1)) as proc:
            _, err = finish(proc)
        assert proc.returncode == 2 and "standard output is closed" in one_line(err), err
        assert not (tmp_path / "e.csv").exists()


def test_a_stream_that_fails_later_is_dropped_not_fatal(tmp_path, stream_inputs, monkeypatch):
    """In-process: stdout that fails on the first write (EPIPE) and stderr that cannot
    encode the title: the command still writes its files and exits 0."""
    import io
    import sys

    from dumbbell.cli import main

    class Gone(io.StringIO):
        def write(self, text):
            raise BrokenPipeError(32, "Broken pipe")

    ascii_err = io.TextIOWrapper(io.BytesIO(), encoding="ascii")
    monkeypatch.setattr(sys, "stdout", Gone())
    monkeypatch.setattr(sys, "stderr", ascii_err)
    scene = Path(stream_inputs["SCENE"])
    scene.write_text(scene.read_text().replace('title = "short"', 'title = "Ünïcode ☃"'))
    assert main(["compare", str(scene), "--t-end", "0.05", "--out", str(tmp_path / "c")]) == 0
    assert len(files_in(tmp_path / "c")) == 6


#: The two pieces kept: a `run` with its GIF and figures, and `compare` (another command,
#: with figures of its own; the cheapest after it, some 9 s against restitution's 20).
KEPT = (("run", "textbook-1d"), ("compare", "textbook-1d"))
#: Run before ``main``: the showcase cut to the pieces :data:`KEPT`, and the shipped scene
#: they load cut to its first 0.5 s (of 10: the same outputs, the same lines that write
#: them), so that `run --all`'s own loop is tested in seconds, not the whole showcase's
#: minutes (each piece's command is tested alone above).
TWO_PIECES = f"""
from dumbbell.cli import showcase as _showcase
_showcase.PIECES = tuple(p for p in _showcase.PIECES if p.argv[:2] in {KEPT!r})
_load = _showcase.load_packaged
_showcase.load_packaged = lambda name: _load(name).with_values({{"run.t_end": 0.5}})
"""


def test_run_all_with_its_readers_gone_writes_the_showcase(tmp_path):
    import subprocess

    from dumbbell.cli.showcase import PIECES

    expected = {n for p in PIECES if p.argv[:2] in KEPT for n in p.writes}
    assert len(expected) == 7
    pipes = [os.pipe(), os.pipe()]
    for r, _ in pipes:
        os.close(r)
    with started("run", "--all", "--out", "r", cwd=tmp_path, prelude=TWO_PIECES,
                 stdout=pipes[0][1], stderr=pipes[1][1], stdin=subprocess.DEVNULL) as proc:
        for _, w in pipes:
            os.close(w)
        assert proc.wait(timeout=600) == 0
        assert not group_left(proc)
    written = files_in(tmp_path / "r")
    assert expected <= set(written), expected - set(written)
    assert not [n for n in written if ".part" in n or n.endswith(".old")]


@pytest.mark.parametrize("target", ["fifo", "/dev/stdout"])
def test_a_pipe_output_whose_reader_leaves_keeps_the_other_outputs(tmp_path, stream_inputs,
                                                                  target):
    """`-o FIFO` or `-o /dev/stdout` (a pipe) whose reader leaves early: as for standard
    output (`| head`), what it did not read is dropped, `--events` is written, exit 0; and
    `/dev/stdout` through a pipe is a pipe, not a name under /dev to refuse."""
    import subprocess

    r, w = os.pipe()
    if target == "fifo":
        fifo = tmp_path / "fifo"
        os.mkfifo(fifo)
        output, stdout = str(fifo), subprocess.DEVNULL
    else:
        output, stdout = "/dev/stdout", w
    argv = ["simulate", stream_inputs["SCENE"], "--t-end", "0.05", "--every", "1", "-o",
            output, "--events", tmp_path / "e.csv"]
    with started(*argv, cwd=tmp_path, stdout=stdout) as proc:
        os.close(w)
        if target == "fifo":
            with open(fifo, "rb") as reader:  # opens once the command opens it to write
                assert reader.read(10) == b"t,xA,vA,xB"
        else:
            assert os.read(r, 10) == b"t,xA,vA,xB"
        os.close(r)  # the reader leaves after 10 bytes
        _, err = finish(proc)
    assert proc.returncode == 0, err
    assert (tmp_path / "e.csv").read_text().startswith("t,body")


@pytest.mark.parametrize("command,head", [("render", b"GIF89a"), ("play", b"<!DOCT")])
def test_a_fifo_gif_or_page_whose_reader_leaves_is_exit_0(tmp_path, stream_inputs, command,
                                                          head):
    """`render -o FIFO.gif` and `play -o FIFO.html` whose reader leaves after 6 bytes: what
    it did not read is dropped (exit 0), nothing is left beside the FIFO."""
    fifo = tmp_path / "out" / f"pipe.{'gif' if command == 'render' else 'html'}"
    fifo.parent.mkdir()
    os.mkfifo(fifo)
    with started(command, stream_inputs["SCENE"], "--t-end", "0.04", "-o", fifo, "-q",
                 cwd=tmp_path) as proc:
        with open(fifo, "rb") as reader:  # opens once the command opens it to write
            assert reader.read(6) == head
        _, err = finish(proc)
        assert not group_left(proc)
    assert proc.returncode == 0, err
    assert files_in(fifo.parent) == [fifo.name]


# --- 5. tracebacks a CLI user saw ------------------------------------------------------------

MATH_TITLES = ["price $\\frac{ and $ end", "$x^2$", "one $ alone", "$$", "a \\$ b $c$",
               "$\\alpha$ and $"]


def _unescaped_dollar(text: str) -> bool:
    """Whether matplotlib would read mathtext in ``text`` (a '$' without a backslash)."""
    import re

    return re.search(r"(?<!\\)\$", text) is not None


def _titled(tmp_path: Path, title: str, name: str = "math") -> Path:
    """The short scene with every figure of `run`, titled ``title`` (TOML-escaped)."""
    path = short_scene(tmp_path, f"{name}.toml",
                       '[outputs]\nfigures = ["positions", "kinetic", "potential", "energy"]\n')
    quoted = title.replace("\\", "\\\\").replace('"', '\\"')
    path.write_text(path.read_text().replace('title = "short"', f'title = "{quoted}"'))
    return path


# Two titles through the commands (the issue's, and dollars escaped beside mathtext): the
# commands draw every title through the same plot.style.plain, which the API's test below
# checks text by text; each run draws seven figures.
@pytest.mark.parametrize("title", [MATH_TITLES[0], MATH_TITLES[4]])
def test_a_title_with_dollars_is_text_in_run_and_compare(tmp_path, title):
    """A scene titled `price $\\frac{ and $ end` broke `run` and `compare` (exit 1,
    matplotlib's mathtext parser): a title is text, drawn as written."""
    from dumbbell import load_scene

    scene = _titled(tmp_path, title)
    assert load_scene(scene).title == title
    for argv in (["run", scene, "--out", tmp_path / "r", "-q"],
                 ["compare", scene, "--t-end", "0.05", "--out", tmp_path / "c", "-q"]):
        status, _, err = cli(*argv)
        assert status == 0 and "Traceback" not in err, err
    assert len(files_in(tmp_path / "r")) == 4 and len(files_in(tmp_path / "c")) == 6


@pytest.mark.parametrize("title", MATH_TITLES[:1])  # every text checked for a bare '$'
def test_a_title_with_dollars_is_text_in_every_figure_of_the_api(tmp_path, monkeypatch, title):
    """`plot.positions(t).figure.savefig()` raised too: every figure that shows a user's
    text (a title, a scene's file name, a solver name given to the figure) draws it as
    text; the title on the figure is the title, with no '$' left for mathtext.

    The figures' texts do not depend on how long the data took: the benchmark's points are
    timed once each (not for half a second), and the pymunk runs of the topple and the
    rigid drop are at dt = 1e-4 s over what their figures show (tests/test_figures.py's
    light inputs)."""
    import io

    import dumbbell
    from dumbbell import plot
    from dumbbell.analysis import bench as bench_module
    from dumbbell.analysis.contact import about_contact
    from dumbbell.analysis.topple import closed_form, measure

    monkeypatch.setattr(bench_module, "MIN_TIMED", 0.0)

    scene = dumbbell.load_scene(_titled(tmp_path, title, name="m$x$"))
    traj = dumbbell.simulate(scene)
    figures = [plot.positions(traj), plot.kinetic(traj), plot.potential(traj),
               plot.energy(traj)]
    result = dumbbell.compare(scene, t_end=0.05)
    figures += [plot.compare(result), plot.compare_energy(result),
                plot.compare_positions(result)]
    figures.append(plot.sweep_map(dumbbell.sweep(scene, {"k": [100.0, 200.0]}, t_end=0.05,
                                                 workers=1)))
    bench = dumbbell.bench(scene, dts=[1e-3], t_end=0.05, window=0.05, repeat=1)
    figures += [plot.work_precision(bench), plot.convergence(bench)]
    topple = dumbbell.simulate(SCENES / "topple-2d.toml", t_end=0.5, dt=1e-4, every=10)
    figures.append(plot.topple(closed_form(topple.scene), measure(topple), solver=title)[0])
    rigid = dumbbell.simulate(SCENES / "rigid-2d.toml", "pymunk", t_end=0.6, dt=1e-4)
    figures.append(plot.contact_momentum(about_contact(rigid), solver=title))
    for ax in figures:
        fig = ax.figure
        fig.savefig(io.BytesIO(), format="png")
        texts = [t.get_text() for t in fig.findobj(lambda a: hasattr(a, "get_text"))]
        # matplotlib's own tick labels on log axes are mathtext ($\mathdefault{10^{-3}}$).
        assert not any(_unescaped_dollar(t) for t in texts
                       if t and "\\mathdefault" not in t), texts
    drawn = " ".join(t.get_text() for t in figures[0].figure.texts)
    assert title.replace("$", "\\$") in drawn
    import matplotlib.pyplot as plt

    plt.close("all")


SOLVERS_NO_JIT = [("textbook-1d", "euler-cromer"), ("textbook-1d", "verlet"),
                  ("textbook-1d", "exact"), ("tilted-2d", "euler-cromer-2d"),
                  ("tilted-2d", "verlet"), ("tilted-2d", "reference"), ("rigid-2d", "exact")]


def _simulate_argv(scene: str, solver: str, folder: Path, stem: str) -> list[str]:
    """`dumbbell simulate` of a case of :data:`SOLVERS_NO_JIT` (0.3 s at dt = 1e-4 s), its
    CSV and events into ``folder`` as STEM.csv and STEM-e.csv."""
    return ["simulate", str(SCENES / f"{scene}.toml"), "--solver", solver, "--t-end", "0.3",
            "--dt", "1e-4", "--every", "10", "-o", str(folder / f"{stem}.csv"), "--events",
            str(folder / f"{stem}-e.csv"), "-q"]


#: Run in one process with NUMBA_DISABLE_JIT=1, for each case (argv[1], JSON: scene,
#: solver, the command's argv): the command (its status and what it wrote on stderr), then
#: the Python API (its energies); all of it as JSON on stdout.
NO_JIT = """
import contextlib, io, json, sys
import dumbbell
from dumbbell.cli import main
out = []
for scene, solver, argv in json.loads(sys.argv[1]):
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        status = main(argv)
    t = dumbbell.simulate(scene, solver, t_end=0.3, dt=1e-4, every=10)
    out.append([status, err.getvalue(), repr(t["E"].tolist())])
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def without_jit(tmp_path_factory):
    """Every case of :data:`SOLVERS_NO_JIT` run as Python (NUMBA_DISABLE_JIT=1), in one
    process of its own (numba reads the variable when it is imported): (scene, solver) ->
    (the command's status, its stderr, the API's energies as repr, its folder)."""
    import json
    import sys

    from tests.hostile import SRC, run_group

    folder = tmp_path_factory.mktemp("nojit")
    cases = [(str(SCENES / f"{scene}.toml"), solver,
              _simulate_argv(scene, solver, folder, f"{scene}-{solver}"))
             for scene, solver in SOLVERS_NO_JIT]
    done = run_group([sys.executable, "-c", NO_JIT, json.dumps(cases)], cwd=folder, text=True,
                     env={**os.environ, "PYTHONPATH": SRC, "CI": "1", "NUMBA_DISABLE_JIT": "1"})
    assert done.returncode == 0 and done.stderr == "", done.stderr[-800:]
    return {case: (*ran, folder) for case, ran in zip(SOLVERS_NO_JIT, json.loads(done.stdout),
                                                     strict=True)}


@pytest.mark.parametrize("scene,solver", SOLVERS_NO_JIT)
def test_numba_disabled_gives_the_same_numbers(tmp_path, without_jit, scene, solver):
    """`NUMBA_DISABLE_JIT=1 dumbbell simulate` (euler-cromer, verlet) raised
    `NotImplementedError: <intrinsic to_fixed_tuple>`: the loops run as Python, the same
    samples and impacts byte for byte as compiled. (The runs without the JIT, every case's,
    are made in one process: :func:`without_jit`.)"""
    status, _, err = cli(*_simulate_argv(scene, solver, tmp_path, "jit"))
    assert status == 0, err
    nojit_status, nojit_err, nojit_energy, folder = without_jit[scene, solver]
    assert nojit_status == 0 and nojit_err == "", nojit_err
    for suffix in (".csv", "-e.csv"):
        assert (tmp_path / f"jit{suffix}").read_bytes() == \
            (folder / f"{scene}-{solver}{suffix}").read_bytes()
    # The Python API too.
    import dumbbell

    jit = dumbbell.simulate(SCENES / f"{scene}.toml", solver, t_end=0.3, dt=1e-4, every=10)
    assert nojit_energy == repr(jit["E"].tolist())


@pytest.mark.parametrize("example", ["pendulum", "slope", "newtons_cradle"])
def test_the_examples_run_without_docstrings(tmp_path, example):
    """`PYTHONOPTIMIZE=2 python -m dumbbell.examples.pendulum --help`: AttributeError
    (docstrings are None under -OO). --help works, and so does a short run."""
    import subprocess
    import sys

    from tests.hostile import SRC

    env = {**os.environ, "PYTHONPATH": SRC, "PYTHONOPTIMIZE": "2", "CI": "1"}
    for argv in (["--help"], ["--seconds", "0.2", "--fps", "10", "--out",
                              str(tmp_path / f"{example}.gif")]):
        done = subprocess.run([sys.executable, "-m", f"dumbbell.examples.{example}", *argv],
                              env=env, capture_output=True, text=True, timeout=600,
                              check=False, cwd=tmp_path)
        assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr[-800:]
    assert (tmp_path / f"{example}.gif").read_bytes()[:6] == b"GIF89a"


@pytest.mark.parametrize("encoding,argv", [
    ("ascii", ["compare", "SCENE", "--t-end", "0.05", "--out", "c"]),
    ("latin-1", ["run", "SCENE", "--out", "r"]),
    ("ascii", ["simulate", "no-such-☃.toml"]),
    ("latin-1", ["simulate", "no-such-☃.toml"]),
])
def test_a_unicode_title_on_a_narrow_terminal(tmp_path, encoding, argv):
    """`PYTHONIOENCODING=ascii dumbbell compare` on a Unicode title: UnicodeEncodeError.
    What the terminal cannot show is escaped; the files are written, the status is the
    command's. (Each encoding once on a command that writes files: the escaping is the
    streams' one piece of code, whatever the command.)"""
    scene = _titled(tmp_path, "Hantel ☃ – Ünïcödé", name="hantel-☃")
    with started(*[str(scene) if a == "SCENE" else a for a in argv], cwd=tmp_path,
                 env={"PYTHONIOENCODING": encoding}, encoding=encoding) as proc:
        out, err = finish(proc)
    assert "Traceback" not in err and "UnicodeEncodeError" not in err, err
    if argv[0] == "simulate":
        assert proc.returncode == 2 and "no such scene file" in one_line(err), err
        return
    assert proc.returncode == 0, err
    folder = tmp_path / argv[-1]
    assert len(files_in(folder)) == (6 if argv[0] == "compare" else 4)
    assert "\\u2603" in out + err  # the snowman, escaped; the rest as the terminal shows it


# --- 7. the Python API's output paths --------------------------------------------------------


def _api_writers(traj):
    """Every way the Python API writes a file: name -> call(path)."""
    import dumbbell
    from dumbbell.io.figures import save_figure
    from dumbbell.io.tables import write_text
    from dumbbell.io.trajectory import write_csv, write_events

    gif = dumbbell.render_gif(traj, size="64x64", t_end=0.04, fps=25)
    return {"to_csv": traj.to_csv, "write_csv": lambda p: write_csv(traj, p),
            "write_events": lambda p: write_events(traj, p),
            "write_text": lambda p: write_text(p, "x\n"),
            "render_gif": lambda p: dumbbell.render_gif(traj, p, size="64x64", t_end=0.04),
            "Gif.save": gif.save,
            "Player.save": lambda p: dumbbell.player(traj, size="64x64", t_end=0.04).save(p),
            "save_figure": lambda p: save_figure(dumbbell.plot.positions(traj).figure, p)}


@pytest.fixture(scope="module")
def short_traj(tmp_path_factory):
    import dumbbell

    return dumbbell.simulate(short_scene(tmp_path_factory.mktemp("traj")))


BAD_OUTPUTS = {
    "a folder": ("{d}/adir", "is a folder"),
    "the working folder": (".", "names a folder"),
    "the parent folder": ("..", "names a folder"),
    "under a file": ("{d}/afile/x.{ext}", "is a file, not a folder"),
    "under /proc": ("/proc/x.{ext}", "/proc"),
    "under /proc/self": ("/proc/self/x.{ext}", "/proc"),
    "under /dev": ("/dev/dumbbell-{u}.{ext}", "/dev"),
    "under /sys": ("/sys/x.{ext}", "cannot write in /sys"),
    "a new folder": ("{d}/newdir/", "ends in '/'"),
    "a new folder, two slashes": ("{d}/newdir//", "ends in '/'"),
    "an existing folder/": ("{d}/adir/", "ends in '/'"),
}


@pytest.mark.parametrize("writer", ["to_csv", "write_csv", "write_events", "write_text",
                                    "render_gif", "Gif.save", "Player.save", "save_figure"])
@pytest.mark.parametrize("case", list(BAD_OUTPUTS))
def test_an_api_output_path_that_cannot_be_a_file_is_one_error(tmp_path, monkeypatch,
                                                              short_traj, writer, case):
    """`to_csv` on a folder, on ".", under a file, under /proc raised IsADirectoryError,
    OSError, FileExistsError, FileNotFoundError; `render_gif(t, "/proc/x.gif")` failed only
    after the work; `to_csv("newdir/")`, `render_gif(t, "newdir/")`, `Gif.save("g/")` wrote
    a file named without the slash (and so did `dumbbell.player(t).save("newdir/")`). One
    DumbbellError naming the argument, before the
    work, and nothing written."""
    from dumbbell import DumbbellError

    if case == "under /sys" and not os.path.isdir("/sys"):
        pytest.skip("no /sys here")
    (tmp_path / "adir").mkdir()
    (tmp_path / "afile").write_text("")
    ext = {"render_gif": "gif", "Gif.save": "gif", "save_figure": "png",
           "Player.save": "html"}.get(writer, "csv")
    text, words = BAD_OUTPUTS[case]
    # A name of this test's own under /dev: a file another run left there would be written
    # (an existing entry is written directly) and hide the refusal.
    path = text.format(d=tmp_path, ext=ext, u=f"{os.getpid()}-{tmp_path.name}")
    assert not path.startswith("/dev/") or not os.path.exists(path)
    call = _api_writers(short_traj)[writer]
    from dumbbell.animation import world

    def no_drawing(*args, **kwargs):
        raise AssertionError("the drawing started before the path was checked")

    monkeypatch.setattr(world, "scene_painter", no_drawing)
    before = files_in(tmp_path)
    with pytest.raises(DumbbellError) as info:
        call(path)
    message = str(info.value)
    assert message.startswith("path = ") and words in message, message
    assert len(message.splitlines()) == 1 and len(message) < 400, message
    assert files_in(tmp_path) == before
    assert not os.path.exists(path.rstrip("/")) or os.path.isdir(path.rstrip("/")) \
        or path.startswith(("/proc", "/sys"))


@pytest.mark.parametrize("writer", ["to_csv", "render_gif", "Gif.save", "Player.save",
                                    "save_figure"])
def test_an_api_output_in_a_new_folder_is_written(tmp_path, short_traj, writer):
    """What is a file name still writes, folders made on the way (and nothing else)."""
    ext = {"render_gif": "gif", "Gif.save": "gif", "save_figure": "png",
           "Player.save": "html"}.get(writer, "csv")
    path = tmp_path / "new" / "deeper" / f"x.{ext}"
    assert _api_writers(short_traj)[writer](str(path)) == path
    assert files_in(tmp_path) == ["new", "new/deeper", f"new/deeper/x.{ext}"]


# --- 9. messages: every echo bounded ---------------------------------------------------------

SPACED = " ".join(["word"] * 16_000)  # 80,000 characters, no word longer than 4


@pytest.mark.parametrize("where", ["key", "table", "nested key", "body", "inline table key",
                                   "array of tables"])
def test_a_key_with_spaces_is_echoed_short(tmp_path, where):
    """A scene key or table name with spaces gave an 80,000-character line (the clipping
    shortened single words only). Every echo is bounded, in the library's error and on the
    command line."""
    from dumbbell import SceneError, load_scene

    base = (SCENES / "textbook-1d.toml").read_text()
    text = {"key": base + f'\n"{SPACED}" = 1\n',
            "table": base + f'\n["{SPACED}"]\nx = 1\n',
            "nested key": base.replace("[gravity]", f'[gravity]\n"{SPACED}" = 1'),
            "body": base.replace("[bodies.A]", f'[bodies."{SPACED}"]\nmass = 1\n[bodies.A]'),
            "inline table key": base.replace("[gravity]",
                                             f'[gravity]\nx = {{ "{SPACED}" = 1 }}'),
            "array of tables": base + f'\n[["{SPACED}"]]\nx = 1\n'}[where]
    path = tmp_path / "spaced.toml"
    path.write_text(text)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert len(str(info.value)) <= 600, len(str(info.value))
    status, _, err = cli("simulate", path, "-o", tmp_path / "x.csv")
    assert len(refused(status, err, tmp_path, keep=("spaced.toml",))) <= 1100


@pytest.mark.parametrize("call", ["with_values", "with_values table", "with_values nested",
                                  "load_scene_bytes", "scene_from_dict", "load_scene",
                                  "sweep", "simulate", "stability"])
def test_the_api_echoes_a_spaced_value_short(call):
    import dumbbell
    from dumbbell import DumbbellError
    from dumbbell.model.scene import load_scene_bytes, scene_from_dict

    scene = dumbbell.load_scene(SCENES / "textbook-1d.toml")
    calls = {"with_values": lambda: scene.with_values({SPACED: 1}),
             "with_values table": lambda: scene.with_values({SPACED + ".x": 1}),
             "with_values nested": lambda: scene.with_values({"spring." + SPACED: 1}),
             "load_scene_bytes": lambda: load_scene_bytes(b"x", SPACED),
             "scene_from_dict": lambda: scene_from_dict({**scene.to_dict(), SPACED: 1}),
             "load_scene": lambda: dumbbell.load_scene(SPACED),
             "sweep": lambda: dumbbell.sweep(scene, {SPACED: [1.0, 2.0]}),
             "simulate": lambda: dumbbell.simulate(scene, solver=SPACED),
             # a folder name past the system's limit gave a raw OSError of 80,000 characters
             "stability": lambda: dumbbell.stability(cases=SPACED)}
    with pytest.raises(DumbbellError) as info:
        calls[call]()
    assert len(str(info.value)) <= 600 and len(str(info.value).splitlines()) == 1, \
        len(str(info.value))


def _text_flags():
    from tests.test_fuzz_cli import COMMANDS, FLAGS

    return [(c, f.names[0]) for c in COMMANDS for f in FLAGS[c] if f.metavar]


@pytest.mark.parametrize("command,flag", _text_flags())
def test_every_flag_echoes_a_spaced_value_short(tmp_path, monkeypatch, command, flag):
    """Every flag of every command given 80,000 characters of short words (one value, or
    50 of them for the flags that take several): one line of at most 1,000 characters."""
    from dumbbell.cli.app import MAX_ECHO
    from tests.test_fuzz_cli import SHORT_2D

    scene = short_scene(tmp_path)
    if command == "restitution":
        scene.write_text(SHORT_2D, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    many = 50 if flag in ("--solvers", "--dts", "--dt", "--stiffness", "--grid") else 1
    positional = [] if command == "stability" else [scene]
    extra = ["--grid", "k=1,2"] if command == "sweep" and flag != "--grid" else []
    status, _, err = cli(command, *positional, *extra, flag, *[SPACED] * many)
    assert status == 2, (command, flag, err[:300])
    assert len(one_line(err)) <= 5 * MAX_ECHO, len(err)


@pytest.mark.parametrize("key,table,value", [
    ("every", "run", "9" * 5000), ("every", "run", "1_0" * 2200), ("fps", "outputs.gif",
                                                                    "9" * 4301),
    ("stiffness", "spring", "-" + "9" * 5000), ("mass", "bodies.A", "+" + "9" * 100_000),
    ("t_end", "run", "9" * 6000),
])
def test_a_5000_digit_integer_names_its_key(tmp_path, key, table, value):
    """A 5,000-digit `every` gave `not valid TOML: Exceeds the limit ... use
    sys.set_int_max_str_digits()`, naming no key. It names the key, and what it may be."""
    from dumbbell import SceneError, load_scene

    base = (SCENES / "textbook-1d.toml").read_text()
    start = base.index(f"[{table}]\n") if table != "outputs.gif" else base.index("gif = {")
    if table == "outputs.gif":
        text = base.replace("fps = 25", f"fps = {value}")
    else:
        line_start = base.index(f"\n{key} = ", start) + 1
        line_end = base.index("\n", line_start)
        text = base[:line_start] + f"{key} = {value}" + base[line_end:]
    path = tmp_path / "digits.toml"
    path.write_text(text)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = str(info.value)
    digits = len(value.strip("+-").replace("_", ""))
    assert f"{table}.{key} = a " in message and f"{digits:,} digits" in message, message
    assert "set_int_max_str_digits" not in message and len(message) < 400, message
    status, _, err = cli("simulate", path, "-o", tmp_path / "x.csv")
    assert f"{table}.{key}" in refused(status, err, tmp_path, keep=("digits.toml",))


def test_a_huge_integer_given_in_python_is_named_too():
    import dumbbell
    from dumbbell import DumbbellError

    scene = dumbbell.load_scene(SCENES / "textbook-1d.toml")
    with pytest.raises(DumbbellError, match=r"run\.every = a whole number of more than 4,300"):
        scene.with_values({"run.every": 10**5000})
    with pytest.raises(DumbbellError) as info:
        dumbbell.simulate(scene.with_values({"run.every": 10**4299}))
    assert len(str(info.value)) < 300


# --- 10. a scene is read no further than its size limit --------------------------------------


def _sparse(path: Path, size: int) -> Path:
    with open(path, "wb") as fh:
        fh.truncate(size)
    return path


def test_a_huge_packaged_scene_is_refused_from_its_size(tmp_path, monkeypatch):
    """A packaged scene replaced by a 3 GB sparse file made `run --all` read it whole
    (3.1 GB peak) before refusing it. Refused from its size, nothing read: in-process,
    the Python allocations of the refusal stay under 2 MB."""
    import tracemalloc

    from dumbbell.model import scene as scene_module

    sparse = _sparse(tmp_path / "rigid-2d.toml", 3 * 10**9)
    real = scene_module.packaged_scene
    monkeypatch.setattr(scene_module, "packaged_scene",
                        lambda name="textbook-1d": sparse if name == "rigid-2d" else real(name))
    out = tmp_path / "r"
    tracemalloc.start()
    try:
        status, _, err = cli("run", "--all", "--out", out)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    line = refused(status, err)
    assert "scenes/rigid-2d.toml" in line and "3,000,000,000 bytes" in line, line
    assert str(tmp_path) not in line  # named as the repository names it
    assert peak < 2 * 2**20, peak
    assert not out.exists()


@pytest.mark.parametrize("how", ["packaged", "path", "stdin", "grown"])
def test_a_scene_is_read_no_further_than_the_limit(tmp_path, monkeypatch, how):
    """Everywhere a scene is read (the showcase's packaged scenes, a path, standard input,
    a file that grows while it is read): at most the limit + 1 bytes are read."""
    import io
    import sys

    from dumbbell.model import scene as scene_module
    from dumbbell.model.scene import MAX_SCENE_BYTES

    big = _sparse(tmp_path / "big.toml", 50 * MAX_SCENE_BYTES)
    taken: list[int] = []
    real_fdopen = os.fdopen

    class Counting(io.BytesIO):
        def read(self, n=-1):
            data = super().read(n)
            taken.append(len(data))
            return data

    if how == "stdin":
        stream = Counting(b"#" * (50 * MAX_SCENE_BYTES))
        monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(stream))
        argv = ["simulate", "-", "-o", tmp_path / "x.csv"]
    else:
        class Reader:
            """The file object the scene is read through, counting what it returns."""

            def __init__(self, *args, **kwargs):
                self.fh = real_fdopen(*args, **kwargs)

            def read(self, n=-1):
                data = self.fh.read(n)
                taken.append(len(data))
                return data

            def __enter__(self):
                return self

            def __exit__(self, *exc):
                self.fh.close()

        monkeypatch.setattr(os, "fdopen", Reader)
        if how == "grown":  # the size looked small, then the file grew
            monkeypatch.setattr(scene_module.os, "fstat", lambda fd: os.stat_result(
                (0o100644, 0, 0, 1, 0, 0, 10, 0, 0, 0)))
        if how == "packaged":
            monkeypatch.setattr(scene_module, "packaged_scene", lambda name="x": big)
            argv = ["run", "--out", tmp_path / "r"]
        else:
            argv = ["simulate", big, "-o", tmp_path / "x.csv"]
    import tracemalloc

    tracemalloc.start()
    try:
        status, _, err = cli(*argv)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    line = refused(status, err)
    assert "1 MB" in line or "1,000,000 bytes" in line, line
    assert sum(taken) <= MAX_SCENE_BYTES + 1, sum(taken)
    assert peak < 8 * MAX_SCENE_BYTES, peak  # far below the 50 MB there are
