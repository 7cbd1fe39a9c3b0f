"""Writing an animation's file: GIF or MP4, atomically, a stop signal removing the partial
file first."""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import DumbbellError
from ..files import atomic_output
from ..parallel import STOP_SIGNALS
from .gif import write_frames
from .palette import palette
from .timing import _delays

#: No public names: the writer behind :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []


class _Stopped(BaseException):
    """A stop signal arrived while the file was being written."""


@contextlib.contextmanager
def signals_end_cleanly() -> Iterator[None]:
    """While the block runs (in the main thread), a SIGTERM or SIGHUP that would end the
    script outright raises instead, so the ``.part`` file is removed; after the block the
    signal is sent again, with the script's own handling back in place."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got: list[int] = []

    def stop(signum: int, frame: object) -> None:
        got.append(signum)
        raise _Stopped(signum)

    before = {}
    for name in STOP_SIGNALS:
        number = getattr(signal, name, None)
        if number is not None and signal.getsignal(number) is signal.SIG_DFL:
            before[number] = signal.SIG_DFL
            signal.signal(number, stop)
    try:
        yield
    except _Stopped:
        pass
    finally:
        for number, handler in before.items():
            signal.signal(number, handler)
    if got:
        os.kill(os.getpid(), got[0])


def save(path: Path, painter: Any, fps: int) -> dict[str, float]:
    """Write ``painter``'s frames (``W`` x ``H`` px, ``n`` of them, ``frame(k)`` and
    ``region(k)``) to ``path`` at ``fps``: a GIF, or an MP4 through imageio's ffmpeg plugin
    when the name ends in .mp4; atomically, a stop signal removing the partial file. Returns
    the seconds spent drawing and encoding (GIF only)."""
    stats: dict[str, float] = {}
    with signals_end_cleanly():
        if path.suffix.lower() == ".mp4":
            _write_mp4(path, painter, fps)
        else:
            with atomic_output(path) as tmp, open(tmp, "wb") as fh:
                stats["draw"], stats["encode"] = write_frames(
                    fh, (painter.W, painter.H), painter.frame, _delays(painter.n, fps),
                    region=painter.region)
    return stats


def mp4_problem() -> str | None:
    """Why an MP4 cannot be written here (the optional extra is missing), or None."""
    import importlib.util

    for module in ("imageio", "imageio_ffmpeg"):
        if importlib.util.find_spec(module) is None:
            return "MP4 needs the optional extra: pip install 'dumbbell[mp4]' (imageio-ffmpeg)"
    return None


def _write_mp4(path: Path, painter: Any, fps: int) -> None:
    problem = mp4_problem()
    if problem is not None:
        raise DumbbellError(f"{path}: {problem}")
    import imageio.v2 as imageio

    lut = np.frombuffer(palette()[0], dtype=np.uint8).reshape(256, 3)
    with atomic_output(path) as tmp:
        writer = imageio.get_writer(tmp, format="FFMPEG", mode="I", fps=fps, codec="libx264",
                                    pixelformat="yuv420p", macro_block_size=2,
                                    ffmpeg_log_level="error")
        try:
            # yuv420p needs even sizes: an odd edge gets one more row or column of itself.
            pad = ((0, painter.H % 2), (0, painter.W % 2), (0, 0))
            for k in range(painter.n):
                writer.append_data(np.pad(lut[np.asarray(painter.frame(k))], pad, mode="edge"))
        finally:
            writer.close()
