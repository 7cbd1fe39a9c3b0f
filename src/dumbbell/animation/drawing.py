"""Animation frames drawn with Pillow straight into one fixed 256-colour palette.

A frame is the scene panel (:mod:`.world`: floor, height ruler, the dumbbell, the time), the
energy panel (:mod:`.bars`: one bar per energy column on one fixed scale) and optionally the
strip of the energy time series (:mod:`.strip`), as one :class:`~.picture.Picture` describes
them (the description the player page is given too). :class:`Painter` draws it: the
background once (:mod:`.backdrop`) and per frame only what changes, on crops of it, in the
palette of :mod:`.palette`, with text from the glyph cache of :mod:`.glyphs`.
"""

from __future__ import annotations

import math

import numpy as np
from PIL import Image, ImageDraw

from ..model.scene import Scene
from .backdrop import SS, Backdrop
from .bars import MOMENTUM_EDGE, MOMENTUM_GAP
from .frames import Frames
from .glyphs import NOTE_PX, TEXT_PX, TIME_PX, Stamps, font
from .layout import EDGE
from .palette import LIGHT, WHITE, to_palette
from .picture import Picture, describe

#: No public names: this is the painter behind :func:`dumbbell.animation.render.render_gif`.
__all__: list[str] = []


class Painter(Backdrop):
    """Draws the frames of run ``run`` of a ``picture`` into the palette: the scene panel
    (``world``), the energy bars (``bars``) and the energy time series (``strip``, None
    without), all on the picture's ``layout``."""

    def __init__(self, picture: Picture, run: int = 0):
        self.picture = picture
        self.frames = frames = picture.runs[run]
        self.layout = picture.layout
        self.W, self.H = self.layout.W, self.layout.H
        u = self.layout.u
        self.world = picture.world
        self.values = Stamps(font(max(8, round(TEXT_PX * u))))
        self.time = Stamps(font(max(9, round(TIME_PX * u)), bold=True))
        self.letters = Stamps(font(max(8, round(NOTE_PX * u)) * SS, bold=True))
        self.small = Stamps(font(max(8, round(NOTE_PX * u)) * SS))
        self.note = Stamps(font(max(8, round(NOTE_PX * u))))
        self.bars = picture.bars
        self.strip = picture.strip
        self.tape = self.strip.tape(frames, picture.names) if self.strip else None
        self.bg = self._background()
        self.bg_rgb = self.bg.convert("RGB")
        self.bg_ss = self.bg_rgb.resize((self.W * SS, self.H * SS), Image.Resampling.NEAREST)
        t, impacts = frames.t, np.asarray(frames.impacts)
        # Frames after which an impact happened since the previous frame.
        self.impact_frames = {int(k) for k in np.searchsorted(t, impacts, side="left")
                              if 0 < k < len(t)}

    @classmethod
    def of(cls, scene: Scene, frames: Frames, size: tuple[int, int], strip: bool) -> Painter:
        """The painter of ``frames`` of ``scene`` alone on frames of ``size`` (px)."""
        return cls(describe(scene, (frames,), size, strip))

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
                                 lambda box: self.patch(img, box, SS),
                                 (self.letters, self.small))
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
