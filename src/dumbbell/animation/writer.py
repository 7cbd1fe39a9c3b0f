"""Writing an animation's file: GIF or MP4, atomically (a stop signal removes the partial
file, as for every output: :mod:`dumbbell.files`)."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from ..errors import DumbbellError
from ..files import atomic_output
from .gif import write_frames
from .palette import palette
from .timing import _delays

#: No public names: the writer behind :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []


@contextlib.contextmanager
def binary_output(path: Path) -> Iterator[BinaryIO]:
    """The open binary file an animation is written to: ``path`` whole or not at all
    (:func:`dumbbell.files.atomic_output`). Every GIF, the scene's and the space's, is
    written through here."""
    with atomic_output(path) as tmp, open(tmp, "wb") as fh:
        yield fh


def save(path: Path, painter: Any, fps: int) -> dict[str, float]:
    """Write ``painter``'s frames (``W`` x ``H`` px, ``n`` of them, ``frame(k)`` and
    ``region(k)``) to ``path`` at ``fps``: a GIF, or an MP4 through imageio's ffmpeg plugin
    when the name ends in .mp4; atomically, a stop signal removing the partial file. Returns
    the seconds spent drawing and encoding (GIF only). A stop signal while the file is
    written removes the partial file (:mod:`dumbbell.files` does, for every output)."""
    stats: dict[str, float] = {}
    if path.suffix.lower() == ".mp4":
        _write_mp4(path, painter, fps)
    else:
        with binary_output(path) as fh:
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
