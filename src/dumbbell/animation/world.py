"""The scene panel: the floor and the height ruler (drawn once), and per frame the dumbbell
(particles at their true radius, the spring as a zig-zag with a constant number of coils or a
rigid rod, the centre of mass, in 2D its axis and angle), and the time label's text (in 2D
the axis angle from vertical under it), as the picture panel of :mod:`.painter`."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from PIL import Image, ImageDraw

from .frames import Frames
from .glyphs import NOTE_PX, Stamps, fmt_tick, font, nice_step
from .layout import Layout
from .painter import SS, Clock, Painter, Patch, Rect
from .palette import BLACK, FLOOR, GREY, INK, LIGHT, SPRING, TERM_RGB, WHITE

if TYPE_CHECKING:  # for the annotations only: a recording does not read scenes
    from ..model.scene import System

#: No public names: a piece of the painter behind :func:`dumbbell.animation.render.render_gif`.
__all__: list[str] = []

#: Coils of the drawn spring; constant, so the spacing of the zig-zag shows the stretch.
COILS = 9
#: Straight leads at each end of the drawn spring, a share of its length.
LEAD = 0.12
#: Smallest drawn particle radius (px); smaller particles are drawn as markers of this size.
MIN_RADIUS_PX = 3.5
#: Radius of the centre-of-mass symbol (px at 640x360); the spring's zig-zag is wider.
CM_RADIUS = 3.0
#: Least distance (px at 640x360) of the 2D particle labels from the centre of mass: beyond
#: the angle's arc (:data:`ARC`) and vertical line (1.25 times as long) with room for the letter.
LABEL_CLEAR = 32.0
#: The scene panel, in units of u (px on the 640 x 360 reference frame).
FLOOR_LINE = 2        # width of the floor's edge
RULER_TICK = 4        # a ruler tick's length ...
RULER_LABEL = 6       # ... and its label's distance from the ruler
RULER_TITLE = (4, 5)  # the ruler's title: from the left edge, from the bottom edge
ZIGZAG_SHARE = 0.06   # the zig-zag's half-width: this share of the rest length ...
ZIGZAG_MAX = 8        # ... at most this, and at least CM_RADIUS + 1.5
ZIGZAG_LINE = 1.5     # the zig-zag's line width (at least 2 px at twice the size)
ROD_LINE = 3          # the rigid rod's width
OUTLINE = 0.8         # the particles' and centre of mass's outline (at least 1 px)
CROP_1D, CROP_2D = 8, 18  # a frame redraws this far around the particles beyond their size,
LABELS_2D = 34        # in 2D this much more for the letters beyond the particles,
LABELS_RIGHT = 16     # and this much more on the right for the 1D letters
IMPACT_CROP = 30      # an impact's mark and word: this far left and right of the particle,
IMPACT_WORD = 20      # this far under the floor,
IMPACT_MARK = 14      # the mark's half-length and
IMPACT_LINE = 3       # width,
IMPACT_GAP = 4        # the word under it
LETTER_GAP = 7        # a particle's letter beyond its edge (2D: also above the floor)
LETTER_GAP_1D = 4     # a particle's letter right of its edge (1D)
AXIS_REACH = 12       # the axis line reaches this far beyond half the length ...
AXIS_MIN = 24         # ... and at least this far from the centre of mass
ARC = 20              # radius of the angle's arc; its vertical line is 1.25 times as long
ARC_LINE = 1.3        # the arc's width (at least 1 px)
TIME_BOX = (4, 2)     # the time label's crop: from the left and top edges ...
TIME_BOTTOM_1D, TIME_BOTTOM_2D = 22, 34  # ... down to here (2D: the angle's line too)
# (Where the time label and the angle's line are drawn, TIME_AT and ANGLE_AT, are the
# painter's: it draws every animation's time label.)
#: The ruler's title, the word under an impact's mark, and the time and angle labels (the
#: time's format: its decimals; the angle's: the text around its value in degrees).
RULER_NAME = "height (m)"
IMPACT_WORD_TEXT = "impact"
TIME_DECIMALS = 2
ANGLE_TEXT = ("axis ", "° from vertical")


def axis_angle(pa: tuple[float, float], pb: tuple[float, float]) -> float:
    """Angle of the axis from B to A from vertical (degrees, positive towards +x, like the
    scene's ``tilt``), from pixel positions (pixel y points down)."""
    return math.degrees(math.atan2(pa[0] - pb[0], pb[1] - pa[1]))


def letter_at(p: tuple[float, float], r: float, other: tuple[float, float],
              axis: tuple[tuple[float, float], tuple[float, float]],
              room: tuple[float, tuple[float, float], float]) -> tuple[float, float]:
    """Centre (px) of a 2D particle's letter: beyond the particle ``p`` (radius ``r``) along
    the ``axis`` (the centre of mass, the unit vector pointing out from it), at least
    :data:`LABEL_CLEAR` from it, and above the floor. Pushed up from under the floor, the
    letter of a particle larger than the gap would land on the particle itself (the toppling
    dumbbell's B, standing on the floor): it goes beside the particle then, away from the
    ``other`` one. ``room``: the floor's pixel row, the letter's half width and half height
    (px), and ``u``."""
    (pc, out), (floor_y, half, u) = axis, room
    reach = max(math.hypot(p[0] - pc[0], p[1] - pc[1]) + r + LETTER_GAP * u, LABEL_CLEAR * u)
    lx, ly = pc[0] + out[0] * reach, min(pc[1] + out[1] * reach, floor_y - LETTER_GAP * u)
    if _letter_on_disc((lx, ly), half, p, r + u):
        side = 1.0 if p[0] >= other[0] else -1.0
        lx, ly = p[0] + side * (r + LETTER_GAP * u), min(p[1], floor_y - LETTER_GAP * u)
    return lx, ly


def _letter_on_disc(at: tuple[float, float], half: tuple[float, float],
                    centre: tuple[float, float], radius: float) -> bool:
    """Whether a letter's box (centre ``at``, half width and height in px) reaches into the
    disc."""
    dx = max(abs(at[0] - centre[0]) - half[0], 0.0)
    dy = max(abs(at[1] - centre[1]) - half[1], 0.0)
    return dx * dx + dy * dy < radius * radius


def zigzag(p0: tuple[float, float], p1: tuple[float, float], amp: float, coils: int
           ) -> list[tuple[float, float]]:
    """Points of a spring from ``p0`` to ``p1`` (px): straight leads of :data:`LEAD` at each
    end and ``coils`` zig-zags of half-width ``amp`` (px) between them: the spacing follows the
    length."""
    ax, ay = p1[0] - p0[0], p1[1] - p0[1]
    length = math.hypot(ax, ay)
    if length == 0:
        return [p0, p1]
    nx, ny = -ay / length * amp, ax / length * amp
    lead = LEAD
    pts = [p0, (p0[0] + ax * lead, p0[1] + ay * lead)]
    for i in range(2 * coils):
        f = lead + (1 - 2 * lead) * (i + 0.5) / (2 * coils)
        s = 1 if i % 2 == 0 else -1
        pts.append((p0[0] + ax * f + s * nx, p0[1] + ay * f + s * ny))
    pts += [(p0[0] + ax * (1 - lead), p0[1] + ay * (1 - lead)), p1]
    return pts


@dataclass(frozen=True)
class World:
    """The scene panel of one animation, as drawn: the ``layout``, the scene's
    ``dimensions``, each particle's drawn radius (px, at least :data:`MIN_RADIUS_PX` u:
    ``radius_px`` of A and B), A's share of the mass (``weight_a``: where the centre of mass
    sits between them), what joins them (``link``: "spring", "rod" or "none") and the
    spring's zig-zag half-width (``amp``, px), the floor (``floor_y``: the pixel row of its
    surface, a particle's drawn radius below the row where particle centres meet it, since
    the model's floor is where the centres touch it; None without a floor) and the height
    ruler's ticks ((pixel row, label), ...)."""

    layout: Layout
    dimensions: int
    radius_px: tuple[float, float]
    weight_a: float
    link: str
    amp: float
    floor_y: float | None
    ruler: tuple[tuple[float, str], ...]

    @classmethod
    def build(cls, system: System, layout: Layout) -> World:
        """The scene panel of the dumbbell ``system`` on ``layout``."""
        L, u = layout, layout.u
        ra = max(system.A.radius * L.s, MIN_RADIUS_PX * u)
        rb = max(system.B.radius * L.s, MIN_RADIUS_PX * u)
        rest = (system.spring.rest_length if system.spring else
                system.rigid.length if system.rigid else 0.0)
        amp = max((CM_RADIUS + 1.5) * u, min(ZIGZAG_SHARE * rest * L.s, ZIGZAG_MAX * u))
        link = "rod" if system.rigid is not None else "spring" if system.spring else "none"
        # Where the particle centres meet the floor is height 0; a disc of the drawn radius
        # resting there reaches that far below it (the larger disc, when the two differ:
        # no particle is ever drawn inside the floor).
        floor_y = L.px(0.0, 0.0)[1] + max(ra, rb) if system.floor is not None else None
        _, _, y0, y1 = L.world
        step = nice_step((y1 - y0) / 5)
        lo, hi = math.ceil(y0 / step - 1e-9), math.floor(y1 / step + 1e-9)
        ruler = tuple((L.px(0, k * step)[1], fmt_tick(k * step)) for k in range(lo, hi + 1))
        return cls(layout, system.dimensions, (ra, rb), system.A.mass / system.M, link, amp,
                   floor_y, ruler)

    def draw_static(self, d: ImageDraw.ImageDraw, S: int, fs) -> None:
        """The floor and the height ruler on a background ``S`` times the size."""
        L, u, H = self.layout, self.layout.u, self.layout.H
        if self.floor_y is not None:
            # The surface is the line's top edge: a particle resting on the floor touches it.
            fy, line = self.floor_y, round(FLOOR_LINE * u * S)
            d.rectangle([0, fy * S, L.scene_w * S, H * S], fill=FLOOR)
            d.line([(0, fy * S + line / 2), (L.scene_w * S, fy * S + line / 2)], fill=GREY,
                   width=line)
        rx = L.ruler_x * S
        d.line([(rx, self.ruler[0][0] * S), (rx, self.ruler[-1][0] * S)], fill=GREY, width=S)
        for y, label in self.ruler:
            d.line([(rx - RULER_TICK * u * S, y * S), (rx, y * S)], fill=GREY, width=S)
            d.text((rx - RULER_LABEL * u * S, y * S), label, font=fs, fill=GREY, anchor="rm")
        d.text((RULER_TITLE[0] * u * S, (H - RULER_TITLE[1] * u) * S), RULER_NAME, font=fs,
               fill=GREY, anchor="ls")

    def draw_dumbbell(self, frames: Frames, k: int, impact: bool,
                      patch: Callable[[Rect], Patch],
                      stamps: tuple[Stamps, Stamps]) -> None:
        """Frame ``k``'s dumbbell (``impact``: with the mark of an impact since the previous
        frame) on a crop from ``patch`` at :data:`SS` times the size; ``stamps`` (the letters,
        the small text) are fonts at that size."""
        L, u, S = self.layout, self.layout.u, SS
        letters, small = stamps
        (ax, ay), (bx, by) = frames.A[k].tolist(), frames.B[k].tolist()
        if not all(math.isfinite(v) for v in (ax, ay, bx, by)):
            return
        pa, pb = L.px(ax, ay), L.px(bx, by)
        (ra, rb), amp = self.radius_px, self.amp
        two_d = self.dimensions == 2
        m = max(ra, rb, amp) + (CROP_2D if two_d else CROP_1D) * u
        floor_y = self.floor_y
        impact = impact and floor_y is not None
        mx = m + (LABELS_2D * u if two_d else 0)
        x0, x1 = min(pa[0], pb[0]) - mx, max(pa[0], pb[0]) + mx + LABELS_RIGHT * u
        y0, y1 = min(pa[1], pb[1]) - mx, max(pa[1], pb[1]) + (mx if two_d else m)
        if impact:  # the mark on the floor and the word under it
            low = pa if pa[1] > pb[1] else pb
            x0, x1 = min(x0, low[0] - IMPACT_CROP * u), max(x1, low[0] + IMPACT_CROP * u)
            y1 = max(y1, floor_y + IMPACT_WORD * u)
        crop, (cx, cy), done = patch((x0, y0, x1, y1))
        d = ImageDraw.Draw(crop)

        def P(p: tuple[float, float]) -> tuple[float, float]:
            return ((p[0] - cx) * S, (p[1] - cy) * S)

        w = self.weight_a
        pc = (w * pa[0] + (1 - w) * pb[0], w * pa[1] + (1 - w) * pb[1])
        if two_d:
            self._angle(d, P, pa, pb, pc)
        if impact:
            low = pa if pa[1] > pb[1] else pb
            x, y = P((low[0], floor_y))
            d.line([(x - IMPACT_MARK * u * S, y), (x + IMPACT_MARK * u * S, y)], fill=BLACK,
                   width=round(IMPACT_LINE * u * S))
            small.draw(crop, (x, y + IMPACT_GAP * u * S), IMPACT_WORD_TEXT, INK, "mt")
        self._link(d, [P(pa), P(pb)],
                   [P(p) for p in zigzag(pb, pa, amp, COILS)] if self.link == "spring" else [])
        # Labels sit beyond each particle along the axis, clear of the spring; in 2D at least
        # LABEL_CLEAR from the centre of mass (clear of the angle's arc and vertical line when
        # the spring is compressed) and above the floor; in 1D (and when the particles
        # touch) to the right.
        dx, dy = pa[0] - pb[0], pa[1] - pb[1]
        dist = math.hypot(dx, dy)
        ex, ey = (dx / dist, dy / dist) if two_d and dist > 0 else (0.0, 0.0)
        floor_y = math.inf if floor_y is None else floor_y
        outline = max(1, round(OUTLINE * u * S))
        for p, r, name, sign in ((pa, ra, "A", 1), (pb, rb, "B", -1)):
            x, y = P(p)
            d.ellipse([x - r * S, y - r * S, x + r * S, y + r * S], fill=TERM_RGB[name],
                      outline=INK, width=outline)
            if ex or ey:
                other = pb if name == "A" else pa
                half = (letters.width(name) / (2 * S), letters.cap / (2 * S))
                lx, ly = letter_at(p, r, other, (pc, (sign * ex, sign * ey)), (floor_y, half, u))
                letters.draw(crop, P((lx, ly)), name, INK, "mm")
            else:
                letters.draw(crop, (x + (r + LETTER_GAP_1D * u) * S, y), name, INK, "lm")
        self._centre(d, P(pc), outline)
        done()

    def _centre(self, d: ImageDraw.ImageDraw, xy: tuple[float, float], outline: int) -> None:
        """Centre of mass at ``xy`` (px on the crop): the quartered-disc symbol, narrower than
        the spring's zig-zag so the coils still show beside it when the spring is fully
        compressed."""
        (x, y), rc = xy, CM_RADIUS * self.layout.u * SS
        bb = [x - rc, y - rc, x + rc, y + rc]
        d.ellipse(bb, fill=WHITE, outline=BLACK, width=outline)
        d.pieslice(bb, 180, 270, fill=BLACK)
        d.pieslice(bb, 0, 90, fill=BLACK)

    def _link(self, d: ImageDraw.ImageDraw, ends: list, coils: list) -> None:
        """The rod, the spring (its zig-zag ``coils``) or a faint line between the particles
        (``ends``, px on the crop)."""
        u, S = self.layout.u, SS
        if self.link == "rod":
            d.line(ends, fill=SPRING, width=round(ROD_LINE * u * S))
        elif self.link == "spring":
            d.line(coils, fill=SPRING, width=max(2, round(ZIGZAG_LINE * u * S)), joint="curve")
        else:
            d.line(ends, fill=LIGHT, width=S)

    def _angle(self, d: ImageDraw.ImageDraw, P, pa, pb, pc) -> None:
        """The axis through B and A, a vertical reference at the centre of mass and the arc
        between them (the angle's value is printed under the time)."""
        u, S = self.layout.u, SS
        dx, dy = pa[0] - pb[0], pa[1] - pb[1]
        length = math.hypot(dx, dy)
        if length == 0:
            return
        theta = axis_angle(pa, pb)
        ex, ey = dx / length, dy / length
        reach = max(length / 2 + AXIS_REACH * u, AXIS_MIN * u)
        d.line([P((pc[0] - ex * reach, pc[1] - ey * reach)),
                P((pc[0] + ex * reach, pc[1] + ey * reach))], fill=LIGHT, width=S)
        rv = ARC * u
        x, y = P(pc)
        d.line([(x, y), (x, y - rv * 1.25 * S)], fill=GREY, width=S)
        start, end = sorted((-90.0, -90.0 + theta))
        d.arc([x - rv * S, y - rv * S, x + rv * S, y + rv * S], start, end, fill=GREY,
              width=max(1, round(ARC_LINE * u * S)))

    def clock(self, frames: Frames) -> Clock:
        """The time label of ``frames``: the time and, in 2D, the axis angle from vertical
        under it, top left."""
        L, u = self.layout, self.layout.u
        two_d = self.dimensions == 2
        box = (round(TIME_BOX[0] * u), round(TIME_BOX[1] * u), L.scene_w - round(TIME_BOX[0] * u),
               round((TIME_BOTTOM_2D if two_d else TIME_BOTTOM_1D) * u))

        def angle(k: int) -> str | None:
            (ax, ay), (bx, by) = frames.A[k].tolist(), frames.B[k].tolist()
            if all(math.isfinite(v) for v in (ax, ay, bx, by)) and (ax, ay) != (bx, by):
                theta = axis_angle(L.px(ax, ay), L.px(bx, by))
                return f"{ANGLE_TEXT[0]}{theta:+.0f}{ANGLE_TEXT[1]}"
            return None

        return Clock(box, lambda k: f"t = {frames.t[k]:.{TIME_DECIMALS}f} s",
                     angle if two_d else None)


class ScenePanel:
    """The picture panel of a scene's frames (for :class:`~.painter.Painter`): the floor
    and the ruler under everything, and per frame the dumbbell of ``frames`` as ``world``
    draws it, every frame drawn whole on the background."""

    fresh_every_frame = True
    text_on_white = False

    def __init__(self, world: World, frames: Frames) -> None:
        self.world, self.frames = world, frames
        self.n = len(frames.t)
        self.width = world.layout.scene_w
        self.clock = world.clock(frames)
        t, impacts = frames.t, np.asarray(frames.impacts)
        # Frames after which an impact happened since the previous frame.
        self.impact_frames = {int(k) for k in np.searchsorted(t, impacts, side="left")
                              if 0 < k < len(t)}

    def draw_base(self, d: ImageDraw.ImageDraw, S: int) -> None:
        self.world.draw_static(d, S, font(round(NOTE_PX * self.world.layout.u) * S))

    def static_key(self, k: int) -> object:
        return 0  # one background for every frame

    def draw_static(self, img: Image.Image, k: int) -> None:
        pass  # everything static is in the base

    def draw(self, painter: Painter, img: Image.Image, k: int, fresh: bool
             ) -> list[Rect] | None:
        self.world.draw_dumbbell(self.frames, k, k in self.impact_frames,
                                 lambda box: painter.patch(img, box, SS),
                                 (painter.letters, painter.small))
        return None


def scene_painter(picture: Any, run: int = 0) -> Painter:
    """The painter of run ``run`` of ``picture`` (a :class:`~.picture.Picture`, which
    imports this module): its world, its bars and its strip, on its layout."""
    frames = picture.runs[run]
    L = picture.layout
    return Painter((L.W, L.H), ScenePanel(picture.world, frames), picture.bars, picture.strip,
                   frames)
