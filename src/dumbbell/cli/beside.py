"""Work done beside the main job: ``dumbbell run`` draws its figures in a forked process.

The figures (matplotlib) and the rest of a run's outputs (the solver's compiled kernels, the
CSVs, the GIF drawn with Pillow) are independent, and each side costs about as much as the
other, most of it imports. On a machine with more than one CPU for this process,
:func:`figures_beside` forks a child before the run: it imports matplotlib while this process
loads the solver, receives the trajectory through a pipe (pickled, its arrays sent as they lie
in memory), and draws each figure into the temporary file that this process made for it
(:func:`~dumbbell.files.atomic_output`). This process renames those with its other outputs
once the whole command has succeeded, all or none, as before. The child runs the same code on
the same data with matplotlib's same defaults, so the figures are the same bytes.

- Errors: the child sends back the exception it stopped with, and this process raises it as
  its own (the child's traceback as a note); a child that ended without a word (killed, out of
  memory) leaves the figures to this process, which draws them itself.
- Signals: the child ignores SIGINT (a Ctrl-C reaches the whole process group, and this
  process stops the child) and dies by SIGTERM and SIGHUP. Whenever this process leaves early
  (an error, a stop signal) it ends the child and waits for it before its temporary files are
  removed, so no figure is written after that; a child whose parent died without cleaning up
  (SIGKILL) writes nothing more.
- Not forked: one CPU for this process, no ``os.fork`` or not Linux (macOS's system
  libraries are not safe to fork), other threads running (a fork copies only the calling
  one), or no figure to draw: everything is then done here, figures first, as before.
"""

from __future__ import annotations

import contextlib
import gc
import os
import pickle
import signal
import struct
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

from ..parallel import STOP_SIGNALS

__all__: list[str] = []

#: Draws the figures of a trajectory into their files; ``alive()`` says whether to go on.
Draw = Callable[[Any, Callable[[], bool]], None]

#: The signals that stop a command (see :mod:`dumbbell.cli.app`).
_STOP = {getattr(signal, n) for n in STOP_SIGNALS if hasattr(signal, n)}
#: Set in a child, so that it never forks one of its own.
_IN_CHILD = False


def side_by_side() -> bool:
    """Whether work can be done in a forked process beside this one (see the module notes)."""
    if _IN_CHILD or not hasattr(os, "fork") or not sys.platform.startswith("linux"):
        return False
    try:
        cpus = len(os.sched_getaffinity(0))
    except OSError:
        cpus = os.cpu_count() or 1
    return cpus > 1 and threading.active_count() == 1


@contextlib.contextmanager
def beside(draw: Draw, prepare: Callable[[], object], fork: bool | None = None
           ) -> Iterator[Beside]:
    """A :class:`Beside` that draws with ``draw`` once given the trajectory: in a child forked
    now, which first calls ``prepare()`` (its imports), when ``fork`` (default: when
    :func:`side_by_side`); else here. Leaving the block early stops the child."""
    beside = Beside(draw)
    if side_by_side() if fork is None else fork:
        beside._fork(prepare)
    try:
        yield beside
    finally:
        beside._stop()


class Beside:
    """Figures drawn beside this process, or here: :meth:`send` the trajectory, then
    :meth:`wait` for them."""

    def __init__(self, draw: Draw):
        self._draw = draw
        self._pid: int | None = None
        self._to_child: int | None = None
        self._from_child: int | None = None
        self._sender: threading.Thread | None = None
        self._traj: Any = None
        self._done = False

    # --- this process -----------------------------------------------------------------------

    @property
    def forked(self) -> bool:
        """Whether a child draws the figures."""
        return self._pid is not None

    def send(self, traj: Any) -> None:
        """Hand over the trajectory: to the child (written by a thread, so this process goes
        on with its own work meanwhile), or, without a child, draw the figures now."""
        self._traj = traj
        if self._pid is None:
            self._draw(traj, _always)
            self._done = True
            return
        fd, self._to_child = self._to_child, None
        self._sender = threading.Thread(target=_send, args=(fd, traj), daemon=True)
        self._sender.start()

    def wait(self) -> None:
        """Wait until the figures are drawn: raise the child's error as this process's, or
        draw them here if the child ended without a word."""
        if self._done:
            return
        if self._sender is not None:
            self._sender.join()
            self._sender = None
        assert self._from_child is not None
        reply = _read_all(self._from_child)
        os.close(self._from_child)
        self._from_child = None
        os.waitpid(self._pid, 0)  # type: ignore[arg-type]
        self._pid = None
        self._done = True
        try:
            status, error = pickle.loads(reply) if reply else (None, None)
        except Exception:  # noqa: BLE001 - a reply cut short: the child died writing it
            status, error = None, None
        if status == "error":
            raise error
        if status != "ok":
            self._draw(self._traj, _always)

    def _stop(self) -> None:
        """End the child, if there is still one, and wait for it (nothing it writes can land
        after this); close the pipes."""
        if self._pid is not None:
            with contextlib.suppress(ProcessLookupError):
                os.kill(self._pid, signal.SIGTERM)
            with contextlib.suppress(ChildProcessError):
                os.waitpid(self._pid, 0)
            self._pid = None
        if self._sender is not None:
            self._sender.join()  # the pipe is broken now: it ends
            self._sender = None
        for fd in (self._to_child, self._from_child):
            if fd is not None:
                with contextlib.suppress(OSError):
                    os.close(fd)
        self._to_child = self._from_child = None

    def _fork(self, prepare: Callable[[], object]) -> None:
        down_r, down_w = os.pipe()
        up_r, up_w = os.pipe()
        parent = os.getpid()
        sys.stdout.flush()
        sys.stderr.flush()
        # What both processes imported lives as long as they do: the garbage collector stops
        # looking at it (and the child's copies of it stay shared with this process's).
        gc.freeze()
        # The stop signals wait until the child has its own handlers: this process's would
        # unwind the child through this process's stack.
        held = signal.pthread_sigmask(signal.SIG_BLOCK, _STOP)
        try:
            pid = os.fork()
            if pid == 0:  # pragma: no cover - the child (its work is checked by its outputs)
                try:
                    os.close(down_w)
                    os.close(up_r)
                    self._child(down_r, up_w, parent, prepare, held)
                finally:
                    os._exit(1)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, held)
        os.close(down_r)
        os.close(up_w)
        self._pid, self._to_child, self._from_child = pid, down_w, up_r

    # --- the child ----------------------------------------------------------------------------

    def _child(self, down: int, up: int, parent: int, prepare: Callable[[], object],
               mask: set[int]) -> None:  # pragma: no cover - see _fork
        global _IN_CHILD
        _IN_CHILD = True
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        for name in ("SIGTERM", "SIGHUP"):
            if hasattr(signal, name):
                signal.signal(getattr(signal, name), signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        reply: tuple[str, BaseException | None] = ("ok", None)
        try:
            prepare()
            gc.freeze()  # matplotlib, imported for good
            traj = _receive(down)
            if traj is None:  # this process gave up before sending
                os._exit(0)
            self._draw(traj, lambda: os.getppid() == parent)
        except BaseException as exc:  # noqa: BLE001 - every error goes back to the parent
            from ..errors import DumbbellError

            if not isinstance(exc, DumbbellError):
                import traceback

                exc.add_note("in the process that drew the figures:\n"
                             + "".join(traceback.format_exception(exc)).rstrip())
            reply = ("error", exc)
        try:
            data = pickle.dumps(reply)
        except Exception:  # noqa: BLE001 - an error that cannot be pickled: its text
            error = reply[1]
            data = pickle.dumps(("error", RuntimeError(f"{type(error).__name__}: {error}")))
        with contextlib.suppress(OSError):
            _write_all(up, data)
        with contextlib.suppress(Exception):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(0)


def _always() -> bool:
    return True


# --- the pipe: a pickle whose buffers (the arrays' memory) follow it as they are ------------

_HEADER = struct.Struct("<QQ")  # pickle length, buffer count
_LENGTH = struct.Struct("<Q")


def _send(fd: int, obj: Any) -> None:
    """Write ``obj`` to ``fd`` (pickle protocol 5, numpy arrays out of band: no copy), then
    close it. A child that is gone (broken pipe) is left to :meth:`Beside.wait`."""
    try:
        buffers: list[pickle.PickleBuffer] = []
        data = pickle.dumps(obj, protocol=5, buffer_callback=buffers.append)
        views = [b.raw() for b in buffers]
        _write_all(fd, _HEADER.pack(len(data), len(views))
                   + b"".join(_LENGTH.pack(v.nbytes) for v in views) + data)
        for view in views:
            _write_all(fd, view)
    except OSError:
        pass
    finally:
        with contextlib.suppress(OSError):
            os.close(fd)


def _receive(fd: int) -> Any:
    """What :func:`_send` wrote to ``fd``; None if it was closed before anything came."""
    head = _read_exact(fd, _HEADER.size)
    if head is None:
        return None
    size, count = _HEADER.unpack(head)
    lengths = [_LENGTH.unpack(_read_exact(fd, _LENGTH.size) or b"")[0] for _ in range(count)]
    data = _read_exact(fd, size)
    buffers = [_read_exact(fd, n) for n in lengths]
    os.close(fd)
    return pickle.loads(data, buffers=buffers)  # type: ignore[arg-type]


def _read_exact(fd: int, n: int) -> bytearray | None:
    """``n`` bytes from ``fd`` (None at once at its end; EOFError past it)."""
    buf = bytearray(n)
    view = memoryview(buf)
    got = 0
    while got < n:
        k = os.readv(fd, [view[got:]])
        if k == 0:
            if got == 0:
                return None
            raise EOFError("the pipe closed in the middle of the trajectory")
        got += k
    return buf


def _read_all(fd: int) -> bytes:
    chunks = []
    while chunk := os.read(fd, 1 << 16):
        chunks.append(chunk)
    return b"".join(chunks)


def _write_all(fd: int, data: Any) -> None:
    view = memoryview(data).cast("B")
    while view:
        view = view[os.write(fd, view):]
