"""Offline recording of any pymunk space to a GIF (or MP4), with energy bars and a strip.

>>> with Recorder(space, "out.gif", fps=25) as rec:          # doctest: +SKIP
...     for _ in range(250):
...         step(space, 1 / 25, substeps=20)
...         rec.capture()

:class:`PaletteDrawOptions` is a ``pymunk.SpaceDebugDrawOptions``: ``space.debug_draw`` hands it
circles, segments and polygons, which it keeps as world-coordinate primitives; it adds the
constraints itself (springs as zig-zags with a constant number of coils, rotary springs as a
coil around the pivot, pins and grooves as lines, pivots as dots). Static shapes are drawn
once, from the first capture.

The recorder keeps primitives and energies per capture and draws the file when the ``with``
block ends (nothing is written if it raises), with the discipline of ``dumbbell render``: one
fixed palette (everything static drawn once, at twice the size then halved, and mapped to it
once; per frame only the moving shapes are drawn, on a crop, and mapped through the palette
that holds every ink's blends with white), a fixed world-to-pixel mapping and energy scale for
the whole file, and each GIF frame after the first holding only the rectangle that changed.
Same captures, same bytes. Frame k is shown at round(k * 100 / fps) x 10 ms; the GIF loops.

MP4 goes through imageio's ffmpeg plugin (the optional extra ``dumbbell[mp4]``).
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import Any, Self

import numpy as np
from PIL import Image, ImageDraw

from ..animation.backdrop import SS, Backdrop
from ..animation.bars import EnergyScale, bar_rows, draw_legend, draw_values
from ..animation.gif import write_frames
from ..animation.glyphs import Stamps, fmt_tick, font, nice_step
from ..animation.layout import unit
from ..animation.palette import (
    GREY,
    INK,
    LIGHT,
    SPRING,
    TERM_RGB,
    WHITE,
    blend,
    ink_index,
    palette,
    to_palette,
)
from ..animation.render import check_fps, check_size, delays_cs
from ..animation.strip import GRID
from ..animation.world import zigzag
from ..errors import DumbbellError, UsageError
from ..io.files import atomic_output

#: Inks of dynamic bodies, by their order in the space (then again from the start).
BODY_INKS = tuple(TERM_RGB[n] for n in ("A", "B", "K_rot", "K_spin", "U_g", "U_spring"))
#: Energy terms shown, with the palette colour of each.
TERMS = {"K_trans": TERM_RGB["K_cm"], "K_rot": TERM_RGB["K_rot"], "U_g": TERM_RGB["U_g"],
         "U_spring": TERM_RGB["U_spring"], "E": TERM_RGB["E"]}
HEAT_RGB = TERM_RGB["E_lost"]
STATIC_FILL = (232, 232, 232)
#: Height of an energy bar's row at most (px at 640x360): fewer terms than the animation's.
ROW_MAX = 26

__all__ = ["PaletteDrawOptions", "Recorder", "draw_options"]  # noqa: F822 - see __getattr__


@functools.cache
def _options_class() -> type:
    import pymunk
    from pymunk.space_debug_draw_options import SpaceDebugColor

    class PaletteDrawOptions(pymunk.SpaceDebugDrawOptions):
        """Collects a space's shapes (through ``space.debug_draw``) and constraints as
        primitives in world coordinates (m) for the project's palette painter: ``capture``
        returns the moving ones; ``static`` holds the static shapes of the first capture."""

        def __init__(self) -> None:
            super().__init__()
            self.flags = pymunk.SpaceDebugDrawOptions.DRAW_SHAPES
            self.items: list[tuple] = []
            self.static: list[tuple] | None = None
            self._ink: dict[int, int] = {}
            self._shape_ink = 0
            self._skip = False
            self._sink: list[tuple] = self.items

        def ink_of(self, body: Any) -> int:
            """Index into :data:`BODY_INKS` of a dynamic body; -1 for static/kinematic."""
            from ..model import args

            args.pymunk_object(body, "body", ("Body",))
            if body.body_type != pymunk.Body.DYNAMIC:
                return -1
            key = id(body)
            if key not in self._ink:
                self._ink[key] = len(self._ink) % len(BODY_INKS)
            return self._ink[key]

        def color_for_shape(self, shape: Any) -> Any:
            static = shape.body.body_type == pymunk.Body.STATIC
            self._skip = static and self.static is not None
            self._sink = self._static_sink if static else self.items
            self._shape_ink = self.ink_of(shape.body)
            return SpaceDebugColor(0, 0, 0, 255)

        def _emit(self, item: tuple) -> None:
            """Keep a shape's primitive, unless it is a static shape already kept."""
            if not self._skip:
                self._sink.append(item)

        def draw_circle(self, pos: Any, angle: float, radius: float, outline_color: Any,
                        fill_color: Any) -> None:
            self._emit(("circle", self._shape_ink, pos.x, pos.y, radius, angle))

        def draw_segment(self, a: Any, b: Any, color: Any) -> None:
            self._emit(("seg", self._shape_ink, a.x, a.y, b.x, b.y, 0.0))

        def draw_fat_segment(self, a: Any, b: Any, radius: float, outline_color: Any,
                             fill_color: Any) -> None:
            self._emit(("seg", self._shape_ink, a.x, a.y, b.x, b.y, radius))

        def draw_polygon(self, verts: Any, radius: float, outline_color: Any,
                         fill_color: Any) -> None:
            self._emit(("poly", self._shape_ink, tuple((v.x, v.y) for v in verts), radius))

        def draw_dot(self, size: float, pos: Any, color: Any) -> None:
            pass  # collision points are not drawn

        def capture(self, space: Any) -> list[tuple]:
            """The primitives of ``space`` now (dynamic and kinematic shapes, constraints)."""
            from ..model import args

            args.space(space)
            self.items = []
            first = self.static is None
            self._static_sink: list[tuple] = []
            space.debug_draw(self)
            if first:
                self.static = self._static_sink
            self.items += _constraint_items(space)
            return self.items

    return PaletteDrawOptions


def _constraint_items(space: Any) -> list[tuple]:
    """The primitives of the constraints of ``space`` that have a picture: springs (linear
    and rotary), pin and slide joints and grooves as lines, pivots as dots."""
    import pymunk

    items: list[tuple] = []
    for c in space.constraints:
        a, b = c.a, c.b
        if isinstance(c, pymunk.DampedSpring):
            pa, pb = a.local_to_world(c.anchor_a), b.local_to_world(c.anchor_b)
            items.append(("spring", pa.x, pa.y, pb.x, pb.y))
        elif isinstance(c, pymunk.DampedRotarySpring):
            # At the pivot the two bodies share, if any; else at the moving body.
            pins = [j for j in space.constraints if isinstance(j, pymunk.PivotJoint)
                    and {id(j.a), id(j.b)} == {id(a), id(b)}]
            if pins:
                p = pins[0].a.local_to_world(pins[0].anchor_a)
            else:
                body = b if b.body_type == pymunk.Body.DYNAMIC else a
                p = body.local_to_world(body.center_of_gravity)
            items.append(("rotary", p.x, p.y, a.angle - b.angle - c.rest_angle))
        elif isinstance(c, pymunk.PinJoint | pymunk.SlideJoint):
            pa, pb = a.local_to_world(c.anchor_a), b.local_to_world(c.anchor_b)
            items.append(("line", pa.x, pa.y, pb.x, pb.y))
        elif isinstance(c, pymunk.PivotJoint):
            p = a.local_to_world(c.anchor_a)
            items.append(("dot", p.x, p.y))
        elif isinstance(c, pymunk.GrooveJoint):
            ga, gb = a.local_to_world(c.groove_a), a.local_to_world(c.groove_b)
            items.append(("line", ga.x, ga.y, gb.x, gb.y))
    return items


def draw_options() -> Any:
    """A new ``PaletteDrawOptions`` (a ``pymunk.SpaceDebugDrawOptions``)."""
    return _options_class()()


def __getattr__(name: str) -> Any:
    # PaletteDrawOptions subclasses pymunk's class, so it is made when first asked for.
    if name == "PaletteDrawOptions":
        return _options_class()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _bounds(items: list[tuple]) -> tuple[float, float, float, float]:
    """World box (m) of primitives: x0, x1, y0, y1 (inf when there are none)."""
    xs: list[float] = []
    ys: list[float] = []
    for it in items:
        kind = it[0]
        if kind == "circle":
            _, _, x, y, r, _ = it
            xs += [x - r, x + r]
            ys += [y - r, y + r]
        elif kind == "seg":
            _, _, ax, ay, bx, by, r = it
            xs += [ax - r, ax + r, bx - r, bx + r]
            ys += [ay - r, ay + r, by - r, by + r]
        elif kind == "poly":
            r = it[3]
            xs += [v[0] + s * r for v in it[2] for s in (-1, 1)]
            ys += [v[1] + s * r for v in it[2] for s in (-1, 1)]
        elif kind in ("spring", "line"):
            xs += [it[1], it[3]]
            ys += [it[2], it[4]]
        elif kind in ("dot", "rotary"):
            xs.append(it[1])
            ys.append(it[2])
    ok = [(x, y) for x, y in zip(xs, ys, strict=True) if math.isfinite(x) and math.isfinite(y)]
    if not ok:
        return (math.inf, -math.inf, math.inf, -math.inf)
    return (min(p[0] for p in ok), max(p[0] for p in ok), min(p[1] for p in ok),
            max(p[1] for p in ok))


class Recorder:
    """Records ``space`` into ``path`` (.gif, or .mp4 with the ``[mp4]`` extra) at ``fps``
    frames per second: call :meth:`capture` once per frame while stepping the space yourself;
    the file is written when the ``with`` block ends.

    ``energy`` adds bars of K_trans, K_rot, U_g, U_spring and E (J, one fixed scale) and a
    strip of them over the whole recording with a cursor (``strip``); a ``heat`` counter
    (:class:`~dumbbell.spaces.HeatCounter`) adds its total and E + heat. ``world`` = (x0, x1,
    y0, y1) in m fixes the view (default: everything captured); ``size`` 'WxH' px; ``title``
    is written at the top."""

    def __init__(self, space: Any, path: str | Path, fps: int = 25, energy: bool = True, *,
                 size: str | tuple[int, int] = "640x360", strip: bool = True,
                 heat: Any = None, world: tuple[float, float, float, float] | None = None,
                 title: str = "", about: tuple[float, float] = (0.0, 0.0)) -> None:
        from ..model import args
        from .heat import HeatCounter

        self.space = args.space(space)
        self.path = args.path(path, "path")
        if self.path.suffix.lower() not in (".gif", ".mp4"):
            raise UsageError(f"path {self.path}: must end in .gif or .mp4", param="path")
        self.fps = check_fps(fps)
        self.W, self.H = check_size(size)
        self.energy = args.flag(energy, "energy")
        self.strip = args.flag(strip, "strip") and self.energy
        self.heat = None if heat is None else args.instance(
            heat, "heat", HeatCounter, "a dumbbell.spaces.HeatCounter or None")
        if world is not None:
            allowed = "must be four finite numbers (x0, x1, y0, y1) with x1 > x0 and y1 > y0 (m)"
            if type(world).__name__ == "ndarray":
                world = tuple(world.tolist()) if world.ndim == 1 else None
            if not isinstance(world, tuple | list) or len(world) != 4:
                raise UsageError(f"world = {args.show(world)}: {allowed}", param="world")
            x0, x1, y0, y1 = (args.real(v, "world", "m", positive=False) for v in world)
            if not (x1 > x0 and y1 > y0):
                raise UsageError(f"world = {args.show(world)}: {allowed}", param="world")
            world = (x0, x1, y0, y1)
        self.world = world
        self.title = args.text(title, "title", "a str (written at the top)")
        self.about = args.pair(about, "about", "m")
        self.options = draw_options()
        self.items: list[list[tuple]] = []
        self.terms: dict[str, list[float]] = {n: [] for n in (*TERMS, "heat")}
        self.timing: dict[str, float] = {}

    def __enter__(self) -> Self:
        return self

    def __exit__(self, exc_type: object, exc: object, tb: object) -> None:
        if exc_type is None:
            self.write()

    @property
    def frames(self) -> int:
        """Frames captured so far."""
        return len(self.items)

    def capture(self) -> None:
        """Keep the space as it is now as the next frame."""
        self.items.append(self.options.capture(self.space))
        if self.energy:
            from .accounting import energy

            e = energy(self.space, self.about)
            for name in TERMS:
                self.terms[name].append(getattr(e, name))
            self.terms["heat"].append(float(self.heat.total) if self.heat is not None else 0.0)

    def write(self) -> Path:
        """Draw and write the file (called when the ``with`` block ends)."""
        import time

        if not self.items:
            raise DumbbellError(f"{self.path}: no frames captured (call capture() per frame)")
        t0 = time.perf_counter()
        painter = _Painter(self)
        self.timing["setup"] = time.perf_counter() - t0
        if self.path.suffix.lower() == ".mp4":
            _write_mp4(self.path, painter, self.fps)
        else:
            _write_gif(self.path, painter, self.fps, self.timing)
        self.timing["total"] = time.perf_counter() - t0
        return self.path


def _write_gif(path: Path, painter: _Painter, fps: int, timing: dict[str, float]) -> None:
    n = painter.n
    with atomic_output(path) as tmp, open(tmp, "wb") as fh:
        draw, encode = write_frames(fh, (painter.W, painter.H), painter.frame, delays_cs(n, fps))
    timing.update(draw=draw, encode=encode, frames=n)


def _write_mp4(path: Path, painter: _Painter, fps: int) -> None:
    try:
        import imageio.v2 as imageio
        import imageio_ffmpeg  # noqa: F401
    except ImportError:
        raise DumbbellError(f"{path}: MP4 needs the optional extra: pip install "
                            "'dumbbell[mp4]' (imageio-ffmpeg)") from None
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


class _Painter(Backdrop):
    """Draws the recorder's frames into the fixed palette (see the module docstring)."""

    def __init__(self, rec: Recorder) -> None:
        self.rec = rec
        self.W, self.H = rec.W, rec.H
        self.n = len(rec.items)
        self.u = u = unit(self.W, self.H)
        self.t = np.arange(self.n) / rec.fps
        self.st_time = Stamps(font(max(9, round(14 * u)), bold=True))
        self.st_text = Stamps(font(max(8, round(12 * u))))
        self.st_note = Stamps(font(max(8, round(11 * u))))
        self.inks = [ink_index(c) for c in BODY_INKS]
        self.idx = {name: ink_index(rgb) for name, rgb in TERMS.items()}
        self.idx["heat"] = ink_index(blend(HEAT_RGB, 0.6))
        self.idx["ink"] = ink_index(INK)
        self.heat = rec.heat is not None and rec.energy
        self.names = [*TERMS, "heat"] if self.heat else list(TERMS)
        self.e = {k: np.asarray(v, dtype=float) for k, v in rec.terms.items()}
        self._layout()
        if rec.energy:
            self._energy_scale()
        self.bg = self._background()
        self.bg_rgb = self.bg.convert("RGB")
        self.bg_ss = self.bg_rgb.resize((self.W * SS, self.H * SS), Image.Resampling.NEAREST)

    # --- geometry -----------------------------------------------------------------------

    def _layout(self) -> None:
        rec, u, W, H = self.rec, self.u, self.W, self.H
        self.scene_w = round(0.56 * W) if rec.energy else W
        top = round(30 * u)
        if rec.world is not None:
            x0, x1, y0, y1 = rec.world
        else:
            allitems = [it for frame in rec.items for it in frame] + (rec.options.static or [])
            x0, x1, y0, y1 = _bounds(allitems)
            if not math.isfinite(x0):
                x0, x1, y0, y1 = -1.0, 1.0, -1.0, 1.0
            span = max(x1 - x0, y1 - y0, 1e-9)
            pad = 0.04 * span
            x0, x1, y0, y1 = x0 - pad, x1 + pad, y0 - pad, y1 + pad
        aw, ah = self.scene_w - round(16 * u), H - top - round(8 * u)
        self.s = min(aw / max(x1 - x0, 1e-12), ah / max(y1 - y0, 1e-12))
        self.ox = round(8 * u) + aw / 2 - (x0 + x1) / 2 * self.s
        self.oy = top + ah / 2 + (y0 + y1) / 2 * self.s
        right = self.scene_w + round(10 * u)
        self.bars_box = (right, round(8 * u), W - round(8 * u),
                         round(0.55 * H) if rec.energy and self.rec.strip else H - round(8 * u))
        self.strip_box = (right + round(34 * u), round(0.62 * H), W - round(12 * u),
                          H - round(22 * u))

    def px(self, x: float, y: float) -> tuple[float, float]:
        return self.ox + x * self.s, self.oy - y * self.s

    def _energy_scale(self) -> None:
        vals = [self.e[n] for n in TERMS]
        if self.heat:
            vals += [self.e["heat"], self.e["E"] + self.e["heat"]]
        self.scale = scale = EnergyScale.of(vals)
        self.e_lo, self.e_hi, self.decimals = scale.lo, scale.hi, scale.decimals
        span = scale.span
        bx0, _, bx1, _ = self.bars_box
        self.value_w = round(self.st_text.width(f"-{max(abs(self.e_lo), self.e_hi):.{self.decimals}f}")
                             + 8 * self.u)
        self.bar_left = bx0 + round(70 * self.u)
        self.bar_right = bx1 - self.value_w
        self.bar_scale = (self.bar_right - self.bar_left) / span
        self.bar_zero = self.bar_left - self.e_lo * self.bar_scale
        self.rows = bar_rows(self.names, self.bars_box, self.u, row_max=ROW_MAX)

    def bar_px(self, v: float) -> float:
        return self.bar_zero + v * self.bar_scale

    def strip_y(self, v: Any) -> Any:
        _, sy0, _, sy1 = self.strip_box
        pad = 3 * self.u
        return sy1 - pad - (sy1 - sy0 - 2 * pad) * (v - self.e_lo) / (self.e_hi - self.e_lo)

    def strip_x(self, t: Any) -> Any:
        sx0, _, sx1, _ = self.strip_box
        end = max(float(self.t[-1]), 1e-9)
        return sx0 + 1 + (sx1 - sx0 - 2) * t / end

    # --- drawing primitives ---------------------------------------------------------------

    def _draw_items(self, d: ImageDraw.ImageDraw, items: list[tuple], S: int,
                    cx: float, cy: float) -> None:
        u, s = self.u, self.s
        line = max(1, round(1.5 * u * S))

        def P(x: float, y: float) -> tuple[float, float]:
            px, py = self.px(x, y)
            return (px - cx) * S, (py - cy) * S

        def colours(ink: int) -> tuple[tuple[int, int, int], tuple[int, int, int]]:
            if ink < 0:
                return GREY, STATIC_FILL
            rgb = BODY_INKS[ink]
            return rgb, blend(rgb, 0.33)

        for it in items:
            kind = it[0]
            if kind == "circle":
                _, ink, x, y, r, angle = it
                out, fill = colours(ink)
                (X, Y), R = P(x, y), max(r * s, 1.5 * u) * S
                d.ellipse([X - R, Y - R, X + R, Y + R], fill=fill, outline=out, width=line)
                d.line([(X, Y), (X + R * math.cos(angle), Y - R * math.sin(angle))], fill=out,
                       width=line)
            elif kind == "seg":
                _, ink, ax, ay, bx, by, r = it
                out, fill = colours(ink)
                w = max(line, round(2 * r * s * S))
                d.line([P(ax, ay), P(bx, by)], fill=out if w <= 2 * line else fill, width=w)
                if w > 2 * line:
                    for x, y in ((ax, ay), (bx, by)):
                        X, Y = P(x, y)
                        d.ellipse([X - w / 2, Y - w / 2, X + w / 2, Y + w / 2], fill=fill)
            elif kind == "poly":
                _, ink, verts, r = it
                out, fill = colours(ink)
                d.polygon([P(*v) for v in verts], fill=fill, outline=out, width=line)
            elif kind == "spring":
                _, ax, ay, bx, by = it
                pa, pb = P(ax, ay), P(bx, by)
                d.line(zigzag(pa, pb, 5 * u * S, 9), fill=SPRING, width=line, joint="curve")
            elif kind == "line":
                _, ax, ay, bx, by = it
                d.line([P(ax, ay), P(bx, by)], fill=SPRING, width=line)
            elif kind == "dot":
                X, Y = P(it[1], it[2])
                R = 3 * u * S
                d.ellipse([X - R, Y - R, X + R, Y + R], fill=INK)
            elif kind == "rotary":
                _, x, y, twist = it
                X, Y = P(x, y)
                pts = []
                turns = 2.5
                for i in range(61):
                    f = i / 60
                    a = f * turns * 2 * math.pi + twist
                    rr = (4 + 8 * f) * u * S
                    pts.append((X + rr * math.cos(a), Y - rr * math.sin(a)))
                d.line(pts, fill=SPRING, width=line, joint="curve")

    def _background(self) -> Image.Image:
        W, H, u, S = self.W, self.H, self.u, SS
        img = Image.new("RGB", (W * S, H * S), WHITE)
        d = ImageDraw.Draw(img)
        self._draw_items(d, self.rec.options.static or [], S, 0.0, 0.0)
        if self.rec.title:
            d.text(((self.scene_w - 8 * u) * S, 6 * u * S), self.rec.title,
                   font=font(round(12 * u) * S, True), fill=INK, anchor="rt")
        if self.rec.energy:
            d.line([(self.scene_w * S, 8 * u * S), (self.scene_w * S, (H - 8 * u) * S)],
                   fill=LIGHT, width=S)
            draw_legend(d, S, u, self.bars_box, self.rows,
                        lambda name: HEAT_RGB if name == "heat" else TERMS[name], self.bar_zero)
            if self.rec.strip:
                self._strip_static(d, S)
        return to_palette(img.reduce(S))

    def _strip_static(self, d: ImageDraw.ImageDraw, S: int) -> None:
        u = self.u
        sx0, sy0, sx1, sy1 = self.strip_box
        fs = font(round(10 * u) * S)
        d.rectangle([sx0 * S, sy0 * S, sx1 * S + S - 1, sy1 * S + S - 1], outline=LIGHT, width=S)
        for v in self.scale.ticks():
            y = self.strip_y(v) * S
            d.line([((sx0 + 1) * S, y), ((sx1 - 1) * S, y)], fill=GRID, width=S)
            d.text(((sx0 - 4 * u) * S, y), fmt_tick(v), font=fs, fill=GREY, anchor="rm")
        end = float(self.t[-1])
        tstep = nice_step(end / 4) if end > 0 else 1.0
        for k in range(math.floor(end / tstep + 1e-9) + 1):
            x = self.strip_x(k * tstep) * S
            d.line([(x, sy1 * S), (x, (sy1 + 3 * u) * S)], fill=GREY, width=S)
            d.text((x, (sy1 + 5 * u) * S), fmt_tick(k * tstep), font=fs, fill=GREY, anchor="mt")
        d.text(((sx0 - 4 * u) * S, (sy1 + 5 * u) * S), "t (s)", font=fs, fill=GREY, anchor="rt")
        xs = self.strip_x(self.t) * S
        width = max(1, round(1.5 * u * S))
        series = [(n, self.e[n]) for n in TERMS if n != "E"]
        if self.heat:
            series.append(("heat", self.e["heat"]))
            series.append(("E + heat", self.e["E"] + self.e["heat"]))
        series.append(("E", self.e["E"]))
        for name, v in series:
            ys = self.strip_y(v) * S
            ok = np.isfinite(ys)
            if ok.sum() < 2:
                continue
            rgb = {"heat": HEAT_RGB, "E + heat": blend(HEAT_RGB, 0.6)}.get(name) or TERMS[name]
            d.line(list(zip(xs[ok].tolist(), ys[ok].tolist(), strict=True)), fill=rgb,
                   width=width, joint="curve")

    # --- one frame --------------------------------------------------------------------------

    def frame(self, k: int) -> Image.Image:
        """Frame ``k`` as a palette image."""
        img = self.bg.copy()
        items = self.rec.items[k]
        if items:
            x0, x1, y0, y1 = _bounds(items)
            if math.isfinite(x0):
                (px0, py0), (px1, py1) = self.px(x0, y1), self.px(x1, y0)
                m = 16 * self.u
                box = (max(px0 - m, 0), max(py0 - m, 0), min(px1 + m, self.scene_w - 1),
                       min(py1 + m, self.H))
                if box[2] > box[0] and box[3] > box[1]:
                    crop, (cx, cy), done = self.patch(img, box, SS)
                    self._draw_items(ImageDraw.Draw(crop), items, SS, cx, cy)
                    done()
        u = self.u
        crop, (cx, cy), done = self.patch(img, (4 * u, 2 * u, 130 * u, 24 * u), 1)
        self.st_time.draw(crop, (6 * u - cx, 6 * u - cy), f"t = {self.t[k]:.2f} s", INK, "lt")
        done()
        if self.rec.energy:
            self._bars(img, k)
            if self.rec.strip:
                _, sy0, _, sy1 = self.strip_box
                x = round(float(self.strip_x(self.t[k])))
                ImageDraw.Draw(img).line([(x, sy0 + 1), (x, sy1 - 1)], fill=self.idx["ink"],
                                         width=max(1, round(1.2 * u)))
        return img

    def _bars(self, img: Image.Image, k: int) -> None:
        d = ImageDraw.Draw(img)
        values = {n: float(self.e[n][k]) for n in self.names}
        for name, top, bot in self.rows:
            v = values[name]
            if not math.isfinite(v):
                continue
            a, b = sorted((round(self.bar_px(0.0)), round(self.bar_px(v))))
            if name == "E" and self.heat and values["heat"] > 0:
                # E + heat: what E was, were no energy lost to the contacts.
                h = round(self.bar_px(v + values["heat"]))
                if h > b:
                    d.rectangle([b, top, h - 1, bot - 1], fill=self.idx["heat"])
            if b > a:
                d.rectangle([a, top, b - 1, bot - 1], fill=self.idx[name])
        bx1 = self.bars_box[2]
        box = (self.bar_right + 2, self.rows[0][1] - 3, bx1, self.rows[-1][2] + 3)
        draw_values(self.patch(img, box, 1), self.rows,
                    lambda name: self.scale.text(values[name]), bx1, self.st_text)
