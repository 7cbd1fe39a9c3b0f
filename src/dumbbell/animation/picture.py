"""What a frame shows: the one description of an animation that the GIF painter draws and
the player page is given.

A :class:`Picture` is made once per animation and frozen: the layout's boxes
(:class:`~.layout.Layout`), the scene panel (:class:`~.world.World`: the particles' drawn
radii, what joins them, the floor, the ruler), the energy bars (:class:`~.bars.Bars`: rows,
fixed scale, where the bars run, the note), the strip (:class:`~.strip.Strip`: its window and
scale; which terms it draws as bands), the colours and label texts, and the runs it shows
(:class:`~.frames.Frames`: the values per frame; several runs share one layout and one energy
scale, so they can be shown together). :func:`describe` makes it.

The GIF painter (:mod:`.painter`, with the scene's panel of :mod:`.world`) draws from it; :meth:`Picture.document` gives the same
record as plain data (JSON), with the pixel factors each piece draws with (the named
constants of :mod:`.world`, :mod:`.bars`, :mod:`.strip`, :mod:`.glyphs` and
:mod:`.palette`), which the player page (:mod:`.player`) draws from. Neither side has a
number or a label of its own: a change here shows in both.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model.energy import energy_columns
from . import bars as bars_module
from . import glyphs
from . import palette as palette_module
from . import strip as strip_module
from . import world as world_module
from .bars import Bars, EnergyScale
from .frames import Frames
from .glyphs import TEXT_PX, Stamps, font
from .layout import Layout, layout
from .strip import Strip
from .world import World

if TYPE_CHECKING:  # for the annotations only
    from ..model.scene import Scene

#: No public names: the description behind :func:`dumbbell.animation.render.render_gif` and
#: :func:`dumbbell.animation.player.player`.
__all__: list[str] = []

#: Columns the bars leave out: E_lost's split (E_heat, E_err) is in the CSV.
SPLIT_OF_LOST = ("E_heat", "E_err")

#: The pixel factors (px on the 640 x 360 reference frame, or shares) each piece draws with,
#: by module: the page receives them with the picture and draws with them.
FACTORS = {
    "world": ("COILS", "LEAD", "CM_RADIUS", "LABEL_CLEAR", "FLOOR_LINE", "RULER_TICK",
              "RULER_LABEL", "RULER_TITLE", "ZIGZAG_LINE", "ROD_LINE", "OUTLINE",
              "IMPACT_MARK", "IMPACT_LINE", "IMPACT_GAP", "LETTER_GAP", "LETTER_GAP_1D",
              "AXIS_REACH", "AXIS_MIN", "ARC", "ARC_LINE", "TIME_AT", "ANGLE_AT",
              "TIME_DECIMALS", "RULER_NAME", "IMPACT_WORD_TEXT", "ANGLE_TEXT", "CROP_1D",
              "CROP_2D", "LABELS_2D", "LABELS_RIGHT", "IMPACT_CROP", "IMPACT_WORD", "TIME_BOX",
              "TIME_BOTTOM_1D", "TIME_BOTTOM_2D"),
    "bars": ("LABEL_ROOM", "VALUE_PAD", "HEAD", "SWATCH", "SWATCH_GAP", "NOTE_X",
             "ZERO_OVERHANG", "LOST_INSET", "MARKER", "MOMENTUM_GAP", "MOMENTUM_EDGE",
             "MOMENTUM_ROOM", "MOMENTUM_HALF", "TITLE", "MOMENTUM_TEXT"),
    "strip": ("WINDOW", "AHEAD", "FUTURE", "TIME_TICKS", "BAND_ALPHA", "PAD", "TICK",
              "LABEL_GAP", "CONTACT_BAR", "IMPACT_TICK", "LINE", "CURSOR", "LABEL_OVERHANG",
              "LABEL_EDGE", "ENERGY_AXIS", "TIME_AXIS", "TAPE_CHUNK"),
    "glyphs": ("TEXT_PX", "TIME_PX", "NOTE_PX", "TITLE_PX", "SMALL_PX"),
    "palette": ("TINT",),
    "layout": ("EDGE",),
    "backdrop": ("SS",),
    "picture": ("GHOST", "STACK_BELOW"),
}
#: Opacity of the runs drawn beside the chosen one (ghosts), when runs are shown together.
GHOST = 0.35
#: A page narrower than this (px) shows the scene above the energy panel, each wider.
STACK_BELOW = 560


@dataclass(frozen=True)
class Picture:
    """What every frame of one animation shows (see the module notes): ``layout``, ``world``,
    ``bars``, ``strip`` (None without one), the energy ``names`` the bars and the strip
    show, the ``runs`` (one or more, on one clock) with their ``labels``, for each run which
    terms the strip draws as pale bands (``bands``), and the scene's ``title``."""

    layout: Layout
    world: World
    bars: Bars
    strip: Strip | None
    names: tuple[str, ...]
    runs: tuple[Frames, ...]
    labels: tuple[str, ...]
    bands: tuple[dict[str, bool], ...]
    title: str

    def document(self) -> dict[str, Any]:
        """The picture without its runs' values, as plain data (str, numbers, lists, dicts):
        what the page draws a frame with. Pixel positions and sizes are those of the GIF's
        frame (``size``); the page scales the whole frame alike."""
        L = self.layout
        doc: dict[str, Any] = {
            "size": [L.W, L.H],
            "layout": _plain(L),
            "world": _plain(self.world, skip=("layout",)),
            "bars": _plain(self.bars, skip=Bars.PAGE_SKIPS),
            "strip": None if self.strip is None else _plain(self.strip, skip=Strip.PAGE_SKIPS),
            "names": list(self.names),
            "labels": list(self.labels),
            "bands": [dict(b) for b in self.bands],
            "title": self.title,
            "colours": colours(),
            "factors": {group: {name: _value(_factor(group, name)) for name in names}
                        for group, names in FACTORS.items()},
        }
        if self.strip is not None:
            S = self.strip
            doc["strip"]["ticks"] = [list(tick) for tick in S.energy_ticks()[0]]
            # The time ticks of the whole tape, one beyond its end, and their labels.
            last = math.floor(S.tape_w / S.px_per_s / S.t_step + 1e-9) + 1
            doc["strip"]["time_ticks"] = [[k * S.t_step, glyphs.fmt_tick(k * S.t_step)]
                                          for k in range(last + 1)]
        return doc


def _factor(group: str, name: str) -> Any:
    """The constant ``name`` of :data:`FACTORS`'s ``group``: its module's (the world's time
    label's, TIME_AT and ANGLE_AT, are the painter's, which draws every time label)."""
    module = _module(group)
    if not hasattr(module, name):
        from . import painter

        module = painter
    return getattr(module, name)


def _module(group: str) -> Any:
    """The module whose constants :data:`FACTORS` names under ``group``."""
    from . import layout as layout_module
    from . import painter

    # (The supersampling factor is the painter's; the page knows its group as "backdrop".)
    return {"world": world_module, "bars": bars_module, "strip": strip_module,
            "glyphs": glyphs, "palette": palette_module, "layout": layout_module,
            "backdrop": painter, "picture": sys.modules[__name__]}[group]


def colours() -> dict[str, Any]:
    """The colours a frame is drawn in, as '#rrggbb': the inks by role and each energy term's
    and particle's own (``terms``), with the pale version of each (``tints``, opacity
    :data:`~.palette.TINT` over white, as the palette holds it)."""
    P = palette_module
    roles = {"white": P.WHITE, "black": P.BLACK, "ink": P.INK, "grey": P.GREY,
             "light": P.LIGHT, "floor": P.FLOOR, "spring": P.SPRING,
             "grid": strip_module.GRID, "impact": strip_module.IMPACT}
    out: dict[str, Any] = {name: hex_colour(rgb) for name, rgb in roles.items()}
    out["terms"] = {name: hex_colour(rgb) for name, rgb in P.TERM_RGB.items()}
    out["tints"] = {name: hex_colour(P.blend(rgb, P.TINT)) for name, rgb in P.TERM_RGB.items()}
    out["bands"] = {name: hex_colour(P.blend(rgb, strip_module.BAND_ALPHA))
                    for name, rgb in P.TERM_RGB.items()}
    return out


def hex_colour(rgb: tuple[int, int, int]) -> str:
    r, g, b = rgb
    return f"#{r:02x}{g:02x}{b:02x}"


def _value(v: Any) -> Any:
    """A constant as plain data: tuples as lists, numpy numbers as Python's."""
    if isinstance(v, tuple | list):
        return [_value(x) for x in v]
    if isinstance(v, dict):
        return {str(k): _value(x) for k, x in v.items()}
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, EnergyScale):
        return _plain(v)
    return v


def _plain(record: Any, skip: Sequence[str] = ()) -> dict[str, Any]:
    """A frozen record's fields as plain data."""
    return {f.name: _value(getattr(record, f.name)) for f in fields(record)
            if f.name not in skip}


def scaled(runs: Sequence[Frames], names: Sequence[str]) -> list[np.ndarray]:
    """Every value the bars and the strip show (J), over all ``runs``: the series, the
    extremes between frames, and E + E_lost (the stacked bar's end)."""
    values: list[np.ndarray] = []
    for fr in runs:
        values += [fr.series[n] for n in names if n != "E_lost"]
        values += [fr.hi[n] for n in names] + [fr.lo[n] for n in names]
        if "E_lost" in names:
            values.append(fr.series["E"] + fr.series["E_lost"])
    return values


def describe(scene: Scene, runs: Sequence[Frames], size: tuple[int, int], strip: bool,
             labels: Sequence[str] | None = None) -> Picture:
    """The picture of ``runs`` (the frames of one run of ``scene``, or of several shown
    together on one clock) on frames of ``size`` (px), with the strip of the energy time
    series when ``strip``; ``labels`` name the runs (default: none)."""
    runs = tuple(runs)
    lay = layout(scene, runs, size, strip)
    u = lay.u
    names = tuple(n for n in energy_columns(scene) if n not in SPLIT_OF_LOST)
    values = Stamps(font(max(8, round(TEXT_PX * u))))
    scale = EnergyScale.of(scaled(runs, names))
    bars = Bars.build(lay.bars_box, u, names, scale, values)
    t_end = max(fr.t_end for fr in runs)
    panel = Strip.build(lay.strip_box, u, scale, t_end) if strip else None
    bands = tuple(panel.curves(fr, names)[1] for fr in runs) if panel else ()
    return Picture(lay, World.build(scene.system, lay), bars, panel, names, runs,
                   tuple(labels) if labels is not None else ("",) * len(runs), bands,
                   scene.title)
