"""Helpers of the hostile-input tests: run the CLI in this process or as a real process, and
check what a refusal must look like (exit status, one line, nothing written, no process left)."""

from __future__ import annotations

import io
import os
import select
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager, redirect_stderr, redirect_stdout
from pathlib import Path

import psutil

import dumbbell
from dumbbell.cli import main
from tests.test_scene import GOOD

#: The folder holding the package under test, so that a subprocess runs the same code.
SRC = str(Path(dumbbell.__file__).resolve().parent.parent)

#: A short textbook scene: 0.05 s at dt = 1e-4 s (500 steps), so that accepted runs are quick.
SHORT_SCENE = GOOD.replace('title = "ok"', 'title = "short"').replace(
    "t_end = 0.01\ndt = 1e-5\n", 't_end = 0.05\ndt = 1e-4\nsolver = "euler-cromer"\nevery = 10\n')


def short_scene(folder: Path, name: str = "short.toml", extra: str = "") -> Path:
    """Write :data:`SHORT_SCENE` (plus ``extra`` TOML) into ``folder``; return its path."""
    path = folder / name
    path.write_text(SHORT_SCENE + extra, encoding="utf-8")
    return path


def cli(*argv: object) -> tuple[int, str, str]:
    """Run ``dumbbell ARGV`` in this process: (exit status, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        try:
            status = main([str(a) for a in argv])
        except SystemExit as exc:  # argparse's own errors
            status = exc.code if isinstance(exc.code, int) else 1
    return status, out.getvalue(), err.getvalue()


def spawn(*argv: object, cwd: Path | None = None, prelude: str = "",
          **popen: object) -> subprocess.Popen:
    """Start ``dumbbell ARGV`` as a real process (stderr and stdout piped) in a session of
    its own (:func:`started` ends the whole group); ``prelude``: Python run before
    ``main`` (a test's hooks)."""
    env = {**os.environ, "PYTHONPATH": SRC, "CI": "1", **popen.pop("env", {})}
    code = f"{prelude}\nimport sys; from dumbbell.cli import main; sys.exit(main())"
    popen = {"stdout": subprocess.PIPE, "stderr": subprocess.PIPE, "text": True, **popen}
    popen["preexec_fn"] = interruptible(popen.get("preexec_fn"))
    return subprocess.Popen([sys.executable, "-c", code, *map(str, argv)], cwd=cwd, env=env,
                            start_new_session=True, **popen)


#: The stop signals the tests send a child.
SENT = (signal.SIGINT, signal.SIGHUP, signal.SIGTERM)


def interruptible(then=None):
    """A ``preexec_fn`` giving the child the default action of every stop signal the tests
    send (:data:`SENT`), then calling ``then``: a test run in the background by a shell
    without job control (``pytest ... &`` in a script) has SIGINT ignored, one run under
    ``nohup`` has SIGHUP ignored, and children inherit both; the command keeps an ignored
    signal ignored, as it must under ``nohup`` (tested, with ``then`` ignoring it again), so
    the tests that send these signals mean a process that has them."""
    def child() -> None:
        for sig in SENT:
            signal.signal(sig, signal.SIG_DFL)
        if then is not None:
            then()

    return child


#: Generous bound on one subprocess of a test (s): only a hang reaches it; the tests wait
#: for events (a line, a marker, the process's end), never for a time, so a loaded 2-core
#: machine makes them slower, not wrong.
HANG_S = 600.0

#: A child that waits for the test's signal does so in a loop of short sleeps (``while True:
#: time.sleep(0.01)``), never in one long ``time.sleep``: Python's C-level handler only sets
#: a flag, so a signal that lands between the interpreter's last look at that flag and the
#: start of the sleep is not acted on until the sleep ends. On a loaded machine the child is
#: preempted in that window often enough (once in a suite beside two CPU burners: an hour's
#: sleep, and the test's 600 s bound). A short sleep looks at the flag again each time.


def end_group(proc: subprocess.Popen) -> None:
    """Kill ``proc``'s whole process group (its pool workers, its forked figure process;
    spawned in a session of its own), whatever state it is in, and reap it."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    try:
        proc.wait(timeout=HANG_S)
    except subprocess.TimeoutExpired:  # pragma: no cover - the kernel reaps a killed group
        pass
    for stream in (proc.stdin, proc.stdout, proc.stderr):
        if stream is not None:
            stream.close()


@contextmanager
def started(*argv: object, cwd: Path | None = None, prelude: str = "", **popen: object
            ) -> Iterator[subprocess.Popen]:
    """:func:`spawn` for the block; on the way out (a failed assertion too) its whole
    process group is killed, so that no test leaves a process behind."""
    proc = spawn(*argv, cwd=cwd, prelude=prelude, **popen)
    try:
        yield proc
    finally:
        end_group(proc)


def run_group(cmd: list[object], *, input: bytes | str | None = None,
              timeout: float = HANG_S, **popen: object) -> subprocess.CompletedProcess:
    """``subprocess.run(cmd, capture_output=True)`` in a session of its own, bounded by
    ``timeout`` only against a hang, and its whole process group killed on the way out, pass
    or fail (``subprocess.run`` kills only the process it started, not what that forked)."""
    popen.setdefault("stdout", subprocess.PIPE)
    popen.setdefault("stderr", subprocess.PIPE)
    if input is not None:
        popen["stdin"] = subprocess.PIPE
    proc = subprocess.Popen([str(c) for c in cmd], start_new_session=True, **popen)
    try:
        out, err = proc.communicate(input, timeout=timeout)
        return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)
    finally:
        end_group(proc)


def group_left(proc: subprocess.Popen, timeout: float = HANG_S) -> list[int]:
    """Processes of ``proc``'s process group (its session: pool workers, the forked figure
    process) still running after it ended, once those that end by themselves have: the
    multiprocessing resource tracker, say, which ends when it sees its parent gone. Waits
    for them (the event), at most ``timeout`` s against a hang; none may be left."""
    members = []
    for p in psutil.process_iter(["pid"]):
        try:
            if os.getpgid(p.pid) == proc.pid and p.status() != psutil.STATUS_ZOMBIE:
                members.append(p)
        except (ProcessLookupError, psutil.NoSuchProcess):
            pass
    _, alive = psutil.wait_procs(members, timeout=timeout)
    return [p.pid for p in alive]


def finish(proc: subprocess.Popen, timeout: float = HANG_S) -> tuple[str, str]:
    """``proc.communicate()``, bounded by ``timeout`` only against a hang."""
    return proc.communicate(timeout=timeout)


@contextmanager
def marker_pipe() -> Iterator[tuple[int, int]]:
    """(read end, write end) of a pipe: the write end goes to a child (``pass_fds``) that
    writes a line when it reaches the state a test waits for; :func:`wait_mark` reads it."""
    r, w = os.pipe()
    try:
        yield r, w
    finally:
        for fd in (r, w):
            try:
                os.close(fd)
            except OSError:
                pass


def wait_mark(proc: subprocess.Popen, fd: int, timeout: float = HANG_S) -> bytes:
    """The first line the child writes on the marker pipe ``fd``: waits for that event (the
    child's end, or :data:`HANG_S`, fails the test instead)."""
    got = b""
    deadline = time.monotonic() + timeout
    while not got.endswith(b"\n"):
        ready, _, _ = select.select([fd], [], [], 1.0)
        if ready:
            chunk = os.read(fd, 4096)
            assert chunk, "the marker pipe closed before the mark"
            got += chunk
        elif proc.poll() is not None:
            raise AssertionError(f"the process ended ({proc.returncode}) before the mark: "
                                 f"{proc.communicate()}")
        assert time.monotonic() < deadline, "the process never reached the mark"
    return got


def one_line(err: str) -> str:
    """The only line of ``err``; fails when there are more, none, or a traceback."""
    assert "Traceback" not in err, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def files_in(folder: Path) -> list[str]:
    """Every file and folder under ``folder`` (relative names, sorted), hidden ones included."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def own_children() -> list[psutil.Process]:
    """Processes this test process started that are still running (zombies excluded), but
    not multiprocessing's resource tracker: an in-process Dask or pool test (test_sweep.py)
    starts that one helper for the whole interpreter, which keeps it until it exits."""
    alive = []
    for p in psutil.Process().children(recursive=True):
        try:
            if p.status() != psutil.STATUS_ZOMBIE and \
                    "multiprocessing.resource_tracker" not in " ".join(p.cmdline()):
                alive.append(p)
        except psutil.NoSuchProcess:
            pass
    return alive


def processes_naming(marker: str) -> list[psutil.Process]:
    """Running processes whose command line contains ``marker`` (a test's unique path): a
    process pool's workers share their parent's command line, even once orphaned."""
    found = []
    for p in psutil.process_iter(["cmdline", "pid"]):
        try:
            if p.pid != os.getpid() and marker in " ".join(p.info["cmdline"] or []) \
                    and p.status() != psutil.STATUS_ZOMBIE:
                found.append(p)
        except psutil.NoSuchProcess:
            pass
    return found


def wait_gone(marker: str, timeout: float = HANG_S) -> list[psutil.Process]:
    """Wait for every process naming ``marker`` to end (at most ``timeout`` s, against a
    hang: it returns as soon as they are gone); the survivors, killed."""
    deadline = time.monotonic() + timeout
    while (left := processes_naming(marker)) and time.monotonic() < deadline:
        time.sleep(0.05)
    for p in left:  # do not leak them into the rest of the suite
        try:
            p.kill()
        except psutil.NoSuchProcess:
            pass
    return left


def refused(status: int, err: str, folder: Path | None = None, keep: tuple[str, ...] = (),
            code: int = 2) -> str:
    """Assert a clean refusal: ``code`` (2, or 128+signal), one line on stderr without a
    traceback, nothing in ``folder`` but ``keep``, no process of ours left. Returns the line."""
    assert status == code, (status, err)
    line = one_line(err)
    if folder is not None:
        assert files_in(folder) == sorted(keep), files_in(folder)
    assert not own_children()
    return line
