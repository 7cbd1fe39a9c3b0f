"""Where everything goes on a frame: computed once per animation, frozen.

Lengths are in units of ``u``, the frame's size over the 640 x 360 reference (so a larger GIF
scales everything alike), or shares of the frame's width W or height H. The world-to-pixel
mapping keeps the aspect ratio: 1 m is as long in x as in y.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .frames import Frames

if TYPE_CHECKING:  # for the annotations only: a recording does not read scenes
    from ..model.scene import Scene

#: No public names: a piece of the painter behind :func:`dumbbell.animation.render.render_gif`
#: and :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

#: Layout of a frame, in units of ``u`` (the frame's size over the 640 x 360 reference, so a
#: larger GIF scales everything alike), or as shares of the frame's width W or height H.
TOP_MARGIN = 34          # above the scene: the time label and the ruler's title
FLOOR_BAND = 18          # below the scene: the floor's band
RULER = 36               # left of the scene: the height ruler
RULER_GAP = 8            # between the ruler and the world's left edge
SCENE_RIGHT_PAD = 30     # right of the scene, before the energy panel
SCENE_MIN_WIDTH = 150    # the scene panel is at least this wide ...
SCENE_MIN_SHARE = 0.3    # ... and at least this share of W ...
SCENE_MAX_SHARE = 0.55   # ... and at most this share of W
PANEL_GAP = 10           # between the scene and the energy panel
EDGE = 8                 # between a panel and the frame's edge
BARS_SHARE = 0.52        # the energy bars' panel ends at this share of H when a strip follows
STRIP_TOP_SHARE = 0.59   # the strip starts at this share of H ...
STRIP_LEFT = 34          # ... this far right of the bars' panel (its value axis) ...
STRIP_RIGHT = 16         # ... and stops this far from the right edge ...
STRIP_BOTTOM = 22        # ... and this far from the bottom (its time axis)
WORLD_PAD = 0.05         # margin around everything the particles reach, a share of its span
RULER_INSET = 4          # the ruler's line, this far left of the ruler's room


#: The reference frame (px) that the lengths above are given on.
REFERENCE = (640, 360)


def unit(width: int, height: int) -> float:
    """The length unit ``u`` of a ``width`` x ``height`` frame (px per reference px): fonts
    and lines scale with the smaller of the two ratios, so nothing overflows."""
    return min(width / REFERENCE[0], height / REFERENCE[1])


@dataclass(frozen=True)
class Layout:
    """Where everything goes on a ``W`` x ``H`` frame, computed once per animation: the length
    unit ``u`` (px), the world's scale ``s`` (px per m) and origin (``ox``, ``oy``, px), the
    world window (m) and the panels' boxes (px, left-top-right-bottom)."""

    W: int
    H: int
    u: float
    s: float
    ox: float
    oy: float
    world: tuple[float, float, float, float]
    ruler_x: int
    scene_w: int
    bars_box: tuple[int, int, int, int]
    strip_box: tuple[int, int, int, int]

    def px(self, x: float, y: float) -> tuple[float, float]:
        """Pixel position of world point (x, y) in m."""
        return self.ox + x * self.s, self.oy - y * self.s


def layout(scene: Scene, runs: Sequence[Frames], size: tuple[int, int], strip: bool
           ) -> Layout:
    """The layout of the frames of ``runs`` of ``scene`` (one run, or runs shown together)
    on a frame of ``size`` (px): the world window holds every position the particles reach
    in any of them (and the floor), at one scale in x and y."""
    W, H = size
    u = unit(W, H)
    r = max(scene.system.A.radius, scene.system.B.radius)
    xs = np.concatenate([p[:, 0] for fr in runs for p in (fr.A, fr.B)])
    ys = np.concatenate([p[:, 1] for fr in runs for p in (fr.A, fr.B)])
    finite = np.isfinite(xs) & np.isfinite(ys)
    xs, ys = (xs[finite], ys[finite]) if finite.any() else (np.zeros(1), np.zeros(1))
    x0, x1 = float(xs.min()) - r, float(xs.max()) + r
    y0, y1 = float(ys.min()) - r, float(ys.max()) + r
    if scene.system.floor is not None:
        y0 = min(y0, 0.0)
    span = max(x1 - x0, y1 - y0, 1e-6)
    pad = WORLD_PAD * span
    x0, x1, y0, y1 = x0 - pad, x1 + pad, y0 - pad, y1 + pad
    top = round(TOP_MARGIN * u)
    bottom = round(FLOOR_BAND * u)
    ruler = round(RULER * u)
    avail_h = H - top - bottom
    want_w = ruler + (x1 - x0) * avail_h / (y1 - y0) + round(SCENE_RIGHT_PAD * u)
    scene_w = int(min(max(want_w, SCENE_MIN_WIDTH * u, SCENE_MIN_SHARE * W),
                      SCENE_MAX_SHARE * W))
    avail_w = scene_w - ruler - round(SCENE_RIGHT_PAD * u)
    s = min(avail_h / (y1 - y0), avail_w / max(x1 - x0, 1e-9))  # px per m
    ox = ruler + round(RULER_GAP * u) + avail_w / 2 - (x0 + x1) / 2 * s
    # World bottom on the panel's bottom: room left over (a wide world) goes to the sky.
    oy = H - bottom + y0 * s
    right = scene_w + round(PANEL_GAP * u)
    bars_box = (right, round(EDGE * u), W - round(EDGE * u),
                round(BARS_SHARE * H) if strip else H - round(EDGE * u))
    strip_box = (right + round(STRIP_LEFT * u), round(STRIP_TOP_SHARE * H),
                 W - round(STRIP_RIGHT * u), H - round(STRIP_BOTTOM * u))
    return Layout(W, H, u, s, ox, oy, (x0, x1, y0, y1), round(ruler - RULER_INSET * u), scene_w,
                  bars_box, strip_box)


#: A recorded space's frame, in units of u or shares of W and H: the picture panel takes
#: this share of W when there are energy bars, its view starting this far from the top
#: (under the time label); the bars' panel ends at this share of H when a strip follows,
#: which starts at this share of H, this far right of the bars' panel and this far from
#: the right edge.
SPACE_SCENE_SHARE = 0.56
SPACE_VIEW_TOP = 30
SPACE_BARS_SHARE = 0.55
SPACE_STRIP_TOP_SHARE = 0.62
SPACE_STRIP_RIGHT = 12

Box = tuple[int, int, int, int]


def space_layout(W: int, H: int, energy: bool, strip: bool
                 ) -> tuple[int, Box, Box, Box]:
    """Where the panels of a recorded space's ``W`` x ``H`` frame go (px): the picture
    panel's width, the area its view is drawn in (left, top, width, height), the energy
    bars' box and the strip's box (left, top, right, bottom)."""
    u = unit(W, H)
    scene_w = round(SPACE_SCENE_SHARE * W) if energy else W
    top = round(SPACE_VIEW_TOP * u)
    area = (round(EDGE * u), top, scene_w - round(2 * EDGE * u), H - top - round(EDGE * u))
    right = scene_w + round(PANEL_GAP * u)
    bars_box = (right, round(EDGE * u), W - round(EDGE * u),
                round(SPACE_BARS_SHARE * H) if strip else H - round(EDGE * u))
    strip_box = (right + round(STRIP_LEFT * u), round(SPACE_STRIP_TOP_SHARE * H),
                 W - round(SPACE_STRIP_RIGHT * u), H - round(STRIP_BOTTOM * u))
    return scene_w, area, bars_box, strip_box
