"""The player page of a recorded pymunk space: what ``spaces.Recorder(space, "run.html")``
writes.

The page is :mod:`.player`'s, drawing a recorded space's frame as the GIF's painter
(:func:`.recording.painter_of`) draws it, from that painter's own numbers: the frame's layout,
the camera's views, the shapes (each set in its bodies' coordinates, grown as the painter
grows them, a pose per body and frame), the constraints, the energy rows and the strip.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..files import atomic_output
from . import recording as R
from .bars import HEAT_ALPHA, SPACE_INKS
from .painter import SS
from .palette import GREY, INK, LIGHT, SPRING, WHITE, blend
from .pens import COILS, FLAT_MANY, SHAPE_COLOURS, SPRING_WIDTH
from .picture import hex_colour
from .player import b64_array, energy_array, page
from .recorded import Recording
from .strip import GRID
from .world import LEAD

#: No public names: the page behind :class:`dumbbell.spaces.Recorder` for a path ending in
#: .html.
__all__: list[str] = []


def write(path: Path, rec: Recording, timing: dict[str, float] | None = None) -> R.ViewPanel:
    """Write the player page of ``rec`` to ``path`` (atomically); ``timing`` receives the
    seconds spent. Returns the view panel (its ``view``), as :func:`.recording.write`
    does."""
    t0 = time.perf_counter()
    painter = R.painter_of(rec)
    text = space_page(painter)
    # What the GIF's painter counts as it draws (which bodies each frame holds and shows,
    # for the recorder's note), counted without drawing.
    panel = painter.panel
    for k in range(painter.n):
        panel._count(panel.layer(k))
    with atomic_output(path) as tmp:
        Path(tmp).write_text(text, encoding="utf-8")
    if timing is not None:
        timing.update(frames=painter.n, total=time.perf_counter() - t0)
    return panel

def space_document(painter: Any) -> dict[str, Any]:
    """The page's data for a recorded space, from the painter of its GIF
    (:func:`~.recording.painter_of`): the frame's layout, the camera's views, the static and
    moving shapes (each moving set in its bodies' coordinates, a pose per body and frame),
    the constraints per frame, the energy rows with their labels, scale and values, and the
    strip of the whole run. The page draws what the painter draws, from the painter's own
    numbers."""
    from .picture import colours

    panel, bars, strip = painter.panel, painter.bars, painter.strip
    rec, u = panel.rec, painter.u
    views: list[Any] = []
    view_of = []
    for v in panel.views:
        if not views or views[-1] is not v:
            views.append(v)
        view_of.append(len(views) - 1)
    shape_sets = []
    for i, shapes in enumerate(rec.shapes):
        # As the painter draws them: each body at least its least size across.
        first = next((k for k, s in enumerate(rec.shape_of) if s == i), None)
        if first is not None:
            shapes = panel._shapes(i, panel.views[first])
        kinds = [""] * shapes.n
        npts = [0] * shapes.n
        local: list[list[float]] = [[] for _ in range(shapes.n)]
        radius = [0.0] * shapes.n
        for g in shapes.groups:
            for i, j in enumerate(g.at.tolist()):
                kinds[j], npts[j] = g.kind, int(g.local.shape[1])
                local[j] = g.local[i].reshape(-1).tolist()
                radius[j] = float(g.r[i])
        shape_sets.append({"kind": kinds, "body": shapes.body.tolist(),
                           "ink": shapes.ink.tolist(), "npts": npts,
                           "local": b64_array(np.array([c for pts in local for c in pts]), "f8"),
                           "r": radius})
    counts = [len(p) for p in rec.poses]
    poses = np.concatenate([np.asarray(p, dtype=float).reshape(-1, 3) for p in rec.poses]
                           + [np.zeros((0, 3))])
    shape_colours = [[hex_colour(out), hex_colour(fill)] for out, fill in SHAPE_COLOURS]
    doc: dict[str, Any] = {
        "size": [painter.W, painter.H], "u": u, "title": rec.title,
        "time_unit": rec.time_unit, "t_decimals": panel.t_decimals,
        "scene_w": painter.scene_w, "area": list(panel.area),
        "views": [[v.s, v.ox, v.oy, v.flip] for v in views], "view_of": view_of,
        "statics": [[list(it) for it in items] for items in rec.statics],
        "static_of": list(rec.static_of),
        "shapes": shape_sets, "shape_of": list(rec.shape_of),
        "counts": counts, "poses": b64_array(poses, "f4"),
        "extras": [[list(it) for it in items] for items in rec.extras],
        "shape_colours": shape_colours, "spring": hex_colour(SPRING), "ink": hex_colour(INK),
        "light": hex_colour(LIGHT), "grey": hex_colour(GREY), "grid": hex_colour(GRID),
        "white": hex_colour(WHITE),
        "factors": {"COILS": COILS, "SPRING_WIDTH": SPRING_WIDTH, "LEAD": LEAD,
                    "SS": SS, "FUTURE": _strip_future(), "STACK_BELOW": _stack_below(),
                    "FLAT_MANY": FLAT_MANY},
        "label_box": list(painter.clock.box), "colours": colours(),
    }
    if bars is not None:
        doc["bars"] = {
            "box": list(bars.box), "rows": [list(r) for r in bars.rows],
            "labels": {n: bars.labels.get(n, n) for n in bars.names},
            "title": bars.title, "scale": {"lo": bars.scale.lo, "hi": bars.scale.hi,
                                          "decimals": bars.scale.decimals},
            "left": bars.left, "right": bars.right, "zero": bars.zero,
            "px_per_j": bars.px_per_j, "heat": bars.heat,
            "inks": {n: hex_colour(SPACE_INKS[n]) for n in bars.names},
            "heat_ink": hex_colour(blend(SPACE_INKS["heat"], HEAT_ALPHA)),
        }
        if strip is not None:
            from .glyphs import fmt_tick

            step = strip.t_step
            ticks = range(math.ceil(strip.t0 / step - 1e-9),
                          math.floor(strip.t_last / step + 1e-9) + 1)
            energy_ticks, axis = strip.energy_ticks()  # as the GIF's strip shows them
            doc["strip"] = {"box": list(strip.box), "pad": strip.pad, "t0": strip.t0,
                            "span": strip.window,
                            "ticks": [[v, label] for v, label in energy_ticks], "axis": axis,
                            "time_ticks": [[k * step, fmt_tick(k * step)] for k in ticks]}
    return doc


def _strip_future() -> float:
    from .strip import FUTURE

    return FUTURE


def _stack_below() -> int:
    from .picture import STACK_BELOW

    return STACK_BELOW


def space_page(painter: Any) -> str:
    """The player page of a recorded space (see :func:`space_document`)."""
    rec, bars, t = painter.panel.rec, painter.bars, painter.readings.t
    decimals = bars.scale.decimals if bars is not None else 2
    names = bars.names if bars is not None else ()
    run = {"label": rec.title or "", "note": "", "t": b64_array(np.asarray(t), "f8"),
           "energy": {name: energy_array(painter.readings.energy[name], decimals)
                      for name in names}}
    doc = {"kind": "space", "fps": rec.fps, "t_end": float(t[-1]),
           "picture": space_document(painter), "runs": [run],
           "units": {"energy": rec.energy_unit, "time": rec.time_unit, "L_cm": ""}}
    return page(doc, rec.title or "pymunk space")
