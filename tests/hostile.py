"""Helpers of the hostile-input tests: run the CLI in this process or as a real process, and
check what a refusal must look like (exit status, one line, nothing written, no process left)."""

from __future__ import annotations

import io
import os
import signal
import subprocess
import sys
import time
from contextlib import redirect_stderr, redirect_stdout
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


def spawn(*argv: object, cwd: Path | None = None) -> subprocess.Popen:
    """Start ``dumbbell ARGV`` as a real process (stderr and stdout piped)."""
    env = {**os.environ, "PYTHONPATH": SRC, "CI": "1"}
    code = "import sys; from dumbbell.cli import main; sys.exit(main())"
    return subprocess.Popen([sys.executable, "-c", code, *map(str, argv)], cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


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


def wait_gone(marker: str, timeout: float = 10.0) -> list[psutil.Process]:
    """Wait up to ``timeout`` s for every process naming ``marker`` to end; the survivors."""
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


def send_when(proc: subprocess.Popen, ready, sig: signal.Signals, timeout: float = 60.0
              ) -> None:
    """Send ``sig`` to ``proc`` as soon as ``ready()`` is true (polled)."""
    deadline = time.monotonic() + timeout
    while not ready():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the run never reached the state to signal"
        time.sleep(0.02)
    proc.send_signal(sig)
