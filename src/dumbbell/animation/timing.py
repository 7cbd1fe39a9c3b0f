"""A GIF's frame rate, size and frame delays: the checks and numbers that every animation
shares, the scene's (:mod:`.render`) and the recorder's (:mod:`.recording`), apart from what
draws either (so that a recording does not import the trajectory's renderer)."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from ..errors import UsageError
from ..model import args
from ..model.sizes import SIZE_RULE, pixel_size

#: No public names: pieces of :func:`dumbbell.animation.render.render_gif` and of
#: :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

#: Highest frame rate a GIF can show faithfully (delays of 10 ms or less are shown as 100 ms).
MAX_FPS = 50


def check_fps(fps: Any, where: str = "fps") -> int:
    """``fps`` as an int in 1..50, else a UsageError naming ``where`` and why."""
    if isinstance(fps, bool) or not isinstance(fps, int | np.integer) or not 1 <= fps <= MAX_FPS:
        raise UsageError(
            f"{where} = {args.show(fps)}: must be a whole number from 1 to {MAX_FPS} (GIF delays are "
            "stored in 10 ms units; browsers show delays of 10 ms or less as 100 ms)",
            param=where.lstrip("-") if isinstance(where, str) else None)
    return int(fps)


def check_size(size: str | tuple[int, int], where: str = "size") -> tuple[int, int]:
    """``'640x360'`` or (640, 360) as (width, height) px, else a UsageError."""
    text = size
    if isinstance(size, tuple | list) and len(size) == 2 and all(
            isinstance(v, int | np.integer) and not isinstance(v, bool) and 0 <= v < 10**6
            for v in size):  # (huge numbers are not spelt out: int -> str is quadratic)
        text = f"{size[0]}x{size[1]}"
    found = pixel_size(text)
    if found is None:
        raise UsageError(f"{where}: {args.show(size)}: {SIZE_RULE}",
                         param=where.lstrip("-") if isinstance(where, str) else None)
    return found


def delays_cs(n: int, fps: int) -> list[int]:
    """Delay of each of ``n`` frames in GIF units (10 ms): frame k starts at
    round(k * 100 / fps) units, so the animation keeps real time."""
    return _delays(args.whole(n, "n", "frames", lo=0, hi=10**7), check_fps(fps))


def _delays(n: int, fps: int) -> list[int]:
    """:func:`delays_cs` of values checked already."""
    starts = [math.floor(k * 100 / fps + 0.5) for k in range(n + 1)]
    return [b - a for a, b in itertools.pairwise(starts)]
