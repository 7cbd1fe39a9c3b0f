"""What an animation's frames show: the samples the painter draws, one per frame."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: No public names: a piece of the painter behind :func:`dumbbell.animation.render.render_gif`.
__all__: list[str] = []


@dataclass(frozen=True)
class Frames:
    """What the frames show. Per frame: time ``t`` (s), positions of A and B (m, (n, 2) arrays
    of x and height), every energy column (J), and in ``lo``/``hi`` the least and largest value
    of each column since the previous frame (J; what happened between two frames, an impact for
    example, stays visible). ``series_t``/``series`` are the samples the strip draws;
    ``impacts`` the impact times (s); ``contacts`` the lasting contacts with the floor as
    (body, start s, end s); ``t_end`` the end of the animation (s)."""

    t: np.ndarray
    A: np.ndarray
    B: np.ndarray
    energy: dict[str, np.ndarray]
    lo: dict[str, np.ndarray]
    hi: dict[str, np.ndarray]
    series_t: np.ndarray
    series: dict[str, np.ndarray]
    impacts: tuple[float, ...]
    t_end: float
    L_cm: np.ndarray | None = None  # angular momentum about the centre of mass (kg m^2/s), 2D
    contacts: tuple[tuple[str, float, float], ...] = ()
