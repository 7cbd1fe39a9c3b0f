"""Animation frames drawn with Pillow straight into one fixed 256-colour palette.

A frame is the scene panel (:mod:`.world`: floor, height ruler, the dumbbell, the time), the
energy panel (:mod:`.bars`: one bar per energy column on one fixed scale) and optionally the
strip of the energy time series (:mod:`.strip`). :class:`Painter` puts them together on a
:class:`~.layout.Layout` computed once: it draws the background once (:mod:`.backdrop`) and
per frame only what changes, on crops of it, in the palette of :mod:`.palette`, with text from
the glyph cache of :mod:`.glyphs`.
"""

from __future__ import annotations

import math

import numpy as np
from PIL import Image, ImageDraw

from ..model.energy import energy_columns
from ..model.scene import Scene
from .backdrop import SS, Backdrop
from .bars import MOMENTUM_EDGE, MOMENTUM_GAP, Bars, EnergyScale
from .frames import Frames
from .glyphs import NOTE_PX, TEXT_PX, TIME_PX, Stamps, font
from .layout import EDGE, Layout, layout
from .palette import LIGHT, WHITE, to_palette
from .strip import Strip
from .world import World

#: No public names: this is the painter behind :func:`dumbbell.animation.render.render_gif`.
__all__: list[str] = []

#: Columns the bars leave out: E_lost's split (E_heat, E_err) is in the CSV.
SPLIT_OF_LOST = ("E_heat", "E_err")


class Painter(Backdrop):
    """Draws the frames of one animation of ``scene`` at ``size`` (px) into the palette:
    the scene panel (``world``), the energy bars (``bars``) and, with ``strip``, the energy
    time series (``strip``, None without), all on one ``layout``."""

    def __init__(self, scene: Scene, frames: Frames, size: tuple[int, int], strip: bool):
        self.frames = frames
        self.W, self.H = size
        self.layout: Layout = layout(scene, frames, size, strip)
        u = self.layout.u
        self.world = World(scene.system, self.layout)
        names = [n for n in energy_columns(scene) if n not in SPLIT_OF_LOST]
        self.values = Stamps(font(max(8, round(TEXT_PX * u))))
        self.time = Stamps(font(max(9, round(TIME_PX * u)), bold=True))
        self.letters = Stamps(font(max(8, round(NOTE_PX * u)) * SS, bold=True))
        self.small = Stamps(font(max(8, round(NOTE_PX * u)) * SS))
        self.note = Stamps(font(max(8, round(NOTE_PX * u))))
        scale = EnergyScale.of(self._scaled(names))
        self.bars = Bars.build(self.layout.bars_box, u, names, scale, self.values)
        self.strip = Strip.build(self.layout.strip_box, u, scale, frames.t_end) if strip else None
        self.tape = self.strip.tape(frames, names) if self.strip else None
        self.bg = self._background()
        self.bg_rgb = self.bg.convert("RGB")
        self.bg_ss = self.bg_rgb.resize((self.W * SS, self.H * SS), Image.Resampling.NEAREST)
        t, impacts = frames.t, np.asarray(frames.impacts)
        # Frames after which an impact happened since the previous frame.
        self.impact_frames = {int(k) for k in np.searchsorted(t, impacts, side="left")
                              if 0 < k < len(t)}

    def _scaled(self, names: list[str]) -> list[np.ndarray]:
        """Every value the bars and the strip show (J): the series, the extremes between
        frames, and E + E_lost (the stacked bar's end)."""
        fr = self.frames
        values = [fr.series[n] for n in names if n != "E_lost"]
        values += [fr.hi[n] for n in names] + [fr.lo[n] for n in names]
        if "E_lost" in names:
            values.append(fr.series["E"] + fr.series["E_lost"])
        return values

    def _background(self) -> Image.Image:
        """Everything static, drawn once at :data:`SS` times the size, then halved."""
        W, H, u, S = self.W, self.H, self.layout.u, SS
        img = Image.new("RGB", (W * S, H * S), WHITE)
        d = ImageDraw.Draw(img)
        fs = font(round(NOTE_PX * u) * S)
        self.world.draw_static(d, S, fs)
        x = self.layout.scene_w * S  # the line between the scene and the energy panel
        d.line([(x, EDGE * u * S), (x, (H - EDGE * u) * S)], fill=LIGHT, width=S)
        self.bars.draw_static(d, S)
        if self.strip:
            self.strip.draw_static(d, S, fs)
        return to_palette(img.reduce(S))

    def frame(self, k: int) -> Image.Image:
        """Frame ``k`` as a palette image."""
        fr = self.frames
        img = self.bg.copy()
        self.world.draw_dumbbell(fr, k, k in self.impact_frames,
                                 lambda box: self.patch(img, box, SS), self.letters, self.small)
        flat = lambda box: self.patch(img, box, 1)
        self.world.draw_time(fr, k, flat, self.time, self.note)
        self.bars.draw(img, fr, k, flat, self.values)
        if fr.L_cm is not None and math.isfinite(float(fr.L_cm[k])):
            u = self.layout.u
            limit = (self.strip.box[1] - round(MOMENTUM_GAP * u) if self.strip
                     else self.H - round(MOMENTUM_EDGE * u))
            self.bars.draw_momentum(float(fr.L_cm[k]), limit, flat, self.note)
        if self.strip:
            self.strip.draw(img, float(fr.t[k]), self.tape, flat, self.note)
        return img
