"""Writing an animation's file: GIF or MP4, atomically (a stop signal removes the partial
file, as for every output: :mod:`dumbbell.files`)."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO

import numpy as np

from ..errors import DumbbellError
from ..files import atomic_output
from .palette import palette

if TYPE_CHECKING:  # for the annotations only
    from PIL import Image

#: No public names: the files behind :func:`dumbbell.animation.render.render_gif` and
#: :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []


@contextlib.contextmanager
def binary_output(path: Path) -> Iterator[BinaryIO]:
    """The open binary file an animation is written to: ``path`` whole or not at all
    (:func:`dumbbell.files.atomic_output`). Every GIF, the scene's and the space's, is
    written through here."""
    with atomic_output(path) as tmp, open(tmp, "wb") as fh:
        yield fh


def mp4_problem() -> str | None:
    """Why an MP4 cannot be written here (the optional extra is missing), or None."""
    import importlib.util

    for module in ("imageio", "imageio_ffmpeg"):
        if importlib.util.find_spec(module) is None:
            return "MP4 needs the optional extra: pip install 'dumbbell[mp4]' (imageio-ffmpeg)"
    return None


def write_mp4(path: Path, size: tuple[int, int], n: int,
              frame: Callable[[int], Image.Image], fps: int) -> None:
    """Write the ``n`` frames ``frame(k)`` (palette images of ``size`` px) to ``path`` as an
    MP4 at ``fps``, through imageio's ffmpeg plugin; atomically."""
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
            width, height = size
            pad = ((0, height % 2), (0, width % 2), (0, 0))
            for k in range(n):
                writer.append_data(np.pad(lut[np.asarray(frame(k))], pad, mode="edge"))
        finally:
            writer.close()
