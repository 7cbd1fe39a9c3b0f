"""Is a matplotlib figure fit for a lecture? :func:`findings` lists what collides on it.

    from tests.figcheck import findings, outside_axes, problems
    assert findings(fig) == []          # or print them: each finding is one line
    assert problems(fig) == []          # findings and missing units, as lines of text
    assert outside_axes(ax) == []       # a figure drawn on the user's axes stays inside them

It lays the figure out and draws it once without painting (unless that was done since it last
changed, as the package leaves its figures) and reads every artist's window extent (px):

- **text on text**: any two pieces of text overlap (titles, axis labels, tick labels, offset
  texts such as ``1e-6``, annotations (their words: an arrow may reach the data), figure
  texts, a text's box where it has one; a legend counts as one box);
- **text on a legend**: a text, or another legend, overlaps a legend's frame;
- **a line through text**: a ``Line2D`` (data curves, markers, ``axhline``/``axvline``) crosses
  a text's box or a legend's frame; lines are clipped to their axes, as drawn;
- **data under text**: the other data an axes draws (filled areas such as ``fill_between``,
  bars, colour meshes, scatter markers, line collections such as ``hlines`` or a contour)
  lies under a text's box or a legend's frame; a span that marks a stretch of an axis
  (``axvspan``, ``axhspan``: drawn over the whole height or width whatever the data) is a
  background, not data;
- **cut off**: a text or legend reaches past the figure's edge;
- **squeezed**: an axes' data area takes less than ``share`` (half) of the width, or of the
  height, of its whole box (its frame with its tick labels, axis labels, titles and legend):
  a legend or a text beside it has taken the room its data should have (a legend outside
  each axes of a row squeezes each plot to a third of its width). A colour bar is not
  checked (it is a thin strip by design).

:func:`missing_units` lists the axes whose tick labels show numbers but whose label names no
unit in brackets (``t [s]``; a ratio is ``[1]``).

Two texts (or a text and a legend) side by side must stand at least ``gap`` points apart: tick
labels 1 px apart read as one number ("-0.250.00"). Above each other they only must not overlap
(matplotlib's own tick labels at an axes' corner come within 1 px diagonally). A line may pass within ``tolerance`` px of a text's
box (its box is shrunk by that much), so that a curve that only grazes the padding does not
count. Only what is drawn counts: hidden artists, empty strings and ticks outside the view
limits are left out.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Finding", "findings", "missing_units", "outside_axes", "problems"]


@dataclass(frozen=True)
class Finding:
    """One collision: ``kind`` (text/text, text/legend, line/text, line/legend, cut off) and
    the two artists it is between, in words."""

    kind: str
    first: str
    second: str = ""

    def __str__(self) -> str:
        return f"{self.kind}: {self.first}" + (f" <-> {self.second}" if self.second else "")


@dataclass(frozen=True)
class _Box:
    name: str
    bbox: Any           # matplotlib Bbox in display px
    owner: Any = None   # the legend a box belongs to (its own texts are not compared with it)


def _short(text: str, n: int = 40) -> str:
    text = " ".join(text.split())
    return repr(text if len(text) <= n else text[: n - 3] + "...")


def _axes_name(fig: Any, ax: Any) -> str:
    label = ax.get_label() or ""
    where = f"axes {fig.axes.index(ax)}"
    title = ax.get_title() or ax.get_title("left") or ""
    return f"{where} ({_short(title, 30)})" if title else (f"{where} ({label})" if label else where)


def _drawn(artist: Any) -> bool:
    return bool(artist.get_visible()) and (artist.get_alpha() is None or artist.get_alpha() > 0)


def _text_box(text: Any, renderer: Any, name: str) -> _Box | None:
    if not _drawn(text) or not text.get_text().strip():
        return None
    from matplotlib.text import Text
    from matplotlib.transforms import Bbox

    # An annotation's own extent takes in its arrow, which is meant to reach the data: only
    # the words count (Text's extent).
    box = Text.get_window_extent(text, renderer)
    if box.width <= 0 or box.height <= 0:
        return None
    patch = text.get_bbox_patch()      # a text drawn in a box: the box counts
    if patch is not None and _drawn(patch):
        box = Bbox.union([box, patch.get_window_extent(renderer)])
    return _Box(f"{name} {_short(text.get_text())}", box)


def _ticks(axis: Any) -> list[Any]:
    """The ticks the axis draws (inside its view limits), major and minor."""
    update = getattr(axis, "_update_ticks", None)
    if update is not None:
        return list(update())
    lo, hi = sorted(axis.get_view_interval())
    return [t for t in axis.get_major_ticks() + axis.get_minor_ticks()
            if lo <= t.get_loc() <= hi]


def _texts_and_legends(fig: Any, renderer: Any) -> tuple[list[_Box], list[_Box]]:
    from matplotlib.legend import Legend
    from matplotlib.text import Text

    texts: list[_Box] = []
    legends: list[_Box] = []

    def add_legend(legend: Any, where: str) -> None:
        if legend is None or not _drawn(legend):
            return
        legends.append(_Box(f"legend of {where}", legend.get_window_extent(renderer), legend))

    for child in fig.get_children():
        if isinstance(child, Text):
            box = _text_box(child, renderer, "figure text")
            if box:
                texts.append(box)
        elif isinstance(child, Legend):
            add_legend(child, "the figure")
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        where = _axes_name(fig, ax)
        for child in ax.get_children():
            if isinstance(child, Text):
                box = _text_box(child, renderer, f"{where}: text")
                if box:
                    texts.append(box)
        add_legend(ax.get_legend(), where)
        if not ax.axison:
            continue
        for xy, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            if not axis.get_visible():
                continue
            for text, what in ((axis.label, "label"), (axis.get_offset_text(), "offset")):
                box = _text_box(text, renderer, f"{where}: {xy} {what}")
                if box:
                    texts.append(box)
            for tick in _ticks(axis):
                for label in (tick.label1, tick.label2):
                    box = _text_box(label, renderer, f"{where}: {xy} tick")
                    if box:
                        texts.append(box)
    return texts, legends


def _draw(fig: Any) -> None:
    """Lay the figure out and place every artist as a draw does, without painting pixels,
    unless it was laid out and drawn since it last changed (not stale: every artist set
    since marks it stale): as the package's figures leave :func:`dumbbell.plot.style.finish`,
    and as it saves them (without laying them out again), they are read as they are."""
    if fig.stale:
        fig.draw_without_rendering()


def _grown(bbox: Any, by: float, vertical: float | None = None) -> Any:
    """``bbox`` grown by ``by`` px on the left and right and ``vertical`` px (default ``by``)
    at the top and bottom; shrunk where negative."""
    from matplotlib.transforms import Bbox

    v = by if vertical is None else vertical
    return Bbox.from_extents(bbox.x0 - by, bbox.y0 - v, bbox.x1 + by, bbox.y1 + v)


def _overlap(a: Any, b: Any) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def _line_pieces(line: Any) -> tuple[list[np.ndarray], np.ndarray, float]:
    """A drawn line in display px: its polyline pieces (split at non-finite points; none
    without a line style), its marker positions (empty without markers) and the markers'
    half size (px)."""
    path = line.get_transform().transform_path(line.get_path())
    xy = np.asarray(path.vertices, dtype=float)
    finite = np.isfinite(xy).all(axis=1)
    pieces: list[np.ndarray] = []
    if line.get_linestyle() not in ("None", "", " ", "none") and line.get_linewidth() > 0:
        breaks = np.flatnonzero(~finite)
        start = 0
        for stop in [*breaks.tolist(), len(xy)]:
            if stop - start >= 2:
                pieces.append(xy[start:stop])
            start = stop + 1
    marker = line.get_marker()
    if marker in (None, "None", "", " ", "none"):
        return pieces, np.empty((0, 2)), 0.0
    half = line.get_markersize() * line.figure.dpi / 72.0 / 2.0
    return pieces, xy[finite], half


def _crosses(pieces: list[np.ndarray], marks: np.ndarray, half: float, box: Any) -> bool:
    from matplotlib.path import Path

    for piece in pieces:
        if (piece[:, 0].max() < box.x0 or piece[:, 0].min() > box.x1
                or piece[:, 1].max() < box.y0 or piece[:, 1].min() > box.y1):
            continue
        if Path(piece).intersects_bbox(box, filled=False):
            return True
    if len(marks):
        inside = ((marks[:, 0] >= box.x0 - half) & (marks[:, 0] <= box.x1 + half)
                  & (marks[:, 1] >= box.y0 - half) & (marks[:, 1] <= box.y1 + half))
        return bool(inside.any())
    return False


def problems(fig: Any) -> list[str]:
    """Everything :func:`findings` and :func:`missing_units` report on ``fig``, one line each,
    from one layout of the figure: [] when it is fit for a lecture."""
    _draw(fig)
    return [str(f) for f in findings(fig, draw=False)] + missing_units(fig, draw=False)


def findings(fig: Any, gap: float = 2.0, tolerance: float = 1.0, lines: bool = True,
             draw: bool = True, share: float = 0.5) -> list[Finding]:
    """Everything that collides on ``fig`` (see the module docstring): [] when nothing does.
    Texts and legends side by side must stand ``gap`` points apart; a line may come within
    ``tolerance`` px of a box; ``lines`` False skips the lines and the other data; an axes'
    data area must take at least ``share`` of its box's width and height; ``draw`` False
    trusts that the figure was laid out since it last changed."""
    from matplotlib.lines import Line2D
    from matplotlib.transforms import Bbox

    if draw:
        _draw(fig)
    renderer = fig.canvas.get_renderer()
    texts, legends = _texts_and_legends(fig, renderer)
    out: list[Finding] = []
    page = Bbox.from_extents(0, 0, fig.bbox.width, fig.bbox.height)
    for box in texts + legends:
        b = box.bbox
        if (b.x0 < page.x0 - tolerance or b.y0 < page.y0 - tolerance
                or b.x1 > page.x1 + tolerance or b.y1 > page.y1 + tolerance):
            out.append(Finding("cut off", box.name))
    half = gap * fig.dpi / 72.0 / 2.0
    wide = {id(box): _grown(box.bbox, half, 0.0) for box in texts + legends}
    for a, b in itertools.combinations(texts, 2):
        if _overlap(wide[id(a)], wide[id(b)]):
            out.append(Finding("text/text", a.name, b.name))
    for legend in legends:
        for text in texts:
            if _overlap(wide[id(legend)], wide[id(text)]):
                out.append(Finding("text/legend", text.name, legend.name))
    for a, b in itertools.combinations(legends, 2):
        if _overlap(wide[id(a)], wide[id(b)]):
            out.append(Finding("text/legend", a.name, b.name))
    out += _squeezed(fig, renderer, share)
    if not lines:
        return out
    small = {id(box): _grown(box.bbox, -tolerance) for box in texts + legends}
    out += _data_under_text(fig, texts + legends, small)
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for line in ax.get_children():
            if not isinstance(line, Line2D) or not _drawn(line):
                continue
            pieces, marks, half = _line_pieces(line)
            if not pieces and not len(marks):
                continue
            clip = line.get_clip_box() if line.get_clip_on() else None
            label = line.get_label()
            name = f"{_axes_name(fig, ax)}: line {_short(label) if not label.startswith('_') else ''}"
            for box in texts + legends:
                target = small[id(box)]
                if clip is not None:
                    target = Bbox.intersection(target, clip)
                    if target is None or target.width <= 0 or target.height <= 0:
                        continue
                if _crosses(pieces, marks, half, target):
                    kind = "line/legend" if box.owner is not None else "line/text"
                    out.append(Finding(kind, name.rstrip(), box.name))
    return out


def _squeezed(fig: Any, renderer: Any, share: float) -> list[Finding]:
    """The axes whose data area (frame) takes less than ``share`` of the width or the height
    of its whole box (``Axes.get_tightbbox``: frame, tick labels, axis labels, titles, legend),
    colour bars left out."""
    out = []
    for ax in fig.axes:
        if not ax.get_visible() or ax.get_label() == "<colorbar>":
            continue
        frame, box = ax.get_window_extent(renderer), ax.get_tightbbox(renderer)
        if box is None or box.width <= 0 or box.height <= 0:
            continue
        for what, part, whole in (("width", frame.width, box.width),
                                  ("height", frame.height, box.height)):
            if part < share * whole:
                out.append(Finding("squeezed", f"{_axes_name(fig, ax)}: its data area is "
                                   f"{part / whole:.0%} of its box's {what} ({part:.0f} of "
                                   f"{whole:.0f} px)"))
    return out


def _is_span(artist: Any, ax: Any) -> bool:
    """Whether ``artist`` spans the axes' whole height or width whatever the data (axvspan,
    axhspan: one of its coordinates is in axes fractions)."""
    x, y = artist.get_transform().contains_branch_seperately(ax.transData)
    return x != y


def _data_shapes(ax: Any) -> list[tuple[str, Any]]:
    """What ``ax`` draws as data besides its lines, as (name, hit) where ``hit(box)`` says
    whether it lies under the display box ``box``."""
    from matplotlib.collections import Collection, LineCollection, QuadMesh
    from matplotlib.image import AxesImage
    from matplotlib.patches import Patch
    from matplotlib.path import Path
    from matplotlib.transforms import Bbox

    def paths_hit(paths: list[Any], filled: bool) -> Any:
        pieces = [(pa, pa.get_extents()) for pa in paths if len(pa.vertices)]

        def hit(box: Any) -> bool:
            return any(e.overlaps(box) and pa.intersects_bbox(box, filled=filled)
                       for pa, e in pieces)
        return hit

    shapes: list[tuple[str, Any]] = []
    where = _axes_name(ax.figure, ax)
    for child in ax.get_children():
        if (not isinstance(child, Collection | Patch | AxesImage) or not _drawn(child)
                or child is ax.patch):
            continue
        label = str(child.get_label() or "")
        shown = _short(label) if label and not label.startswith("_") else ""
        name = f"{where}: {type(child).__name__} {shown}".rstrip()
        if isinstance(child, QuadMesh):
            xy = child.get_transform().transform(child.get_coordinates().reshape(-1, 2))
            xy = xy[np.isfinite(xy).all(axis=1)]
            if len(xy):
                extent = Bbox.from_extents(*xy.min(axis=0), *xy.max(axis=0))
                shapes.append((name, extent.overlaps))
        elif isinstance(child, Collection):
            offsets = np.asarray(child.get_offsets(), dtype=float)
            if len(offsets) and np.any(offsets) and not isinstance(child, LineCollection):
                # Markers (scatter): each a square of its size (points²) round its offset.
                xy = child.get_offset_transform().transform(offsets)
                sizes = np.asarray(child.get_sizes(), dtype=float)
                half = (np.sqrt(sizes.max()) if sizes.size else 6.0) * ax.figure.dpi / 72 / 2

                def hit(box: Any, xy: Any = xy, half: float = half) -> bool:
                    return bool(((xy[:, 0] >= box.x0 - half) & (xy[:, 0] <= box.x1 + half)
                                 & (xy[:, 1] >= box.y0 - half)
                                 & (xy[:, 1] <= box.y1 + half)).any())
                shapes.append((name, hit))
            elif not _is_span(child, ax):
                t = child.get_transform()
                paths = [t.transform_path(pa) for pa in child.get_paths()]
                shapes.append((name, paths_hit(paths, not isinstance(child, LineCollection))))
        elif isinstance(child, Patch) and not _is_span(child, ax):
            path = child.get_transform().transform_path(child.get_path())
            shapes.append((name, paths_hit([Path(path.vertices, path.codes)], True)))
        elif isinstance(child, AxesImage):
            shapes.append((name, child.get_window_extent().overlaps))
    return shapes


def _data_under_text(fig: Any, boxes: list[_Box], small: dict[int, Any]) -> list[Finding]:
    """Data other than lines (:func:`_data_shapes`) under a text's box or a legend's frame,
    each clipped to its axes as drawn."""
    from matplotlib.transforms import Bbox

    out = []
    for ax in fig.axes:
        if not ax.get_visible() or ax.get_label() == "<colorbar>":
            continue
        clip = ax.get_window_extent()
        shapes = _data_shapes(ax)
        for box in boxes:
            target = Bbox.intersection(small[id(box)], clip)
            if target is None or target.width <= 0 or target.height <= 0:
                continue
            for name, hit in shapes:
                if hit(target):
                    kind = "data/legend" if box.owner is not None else "data/text"
                    out.append(Finding(kind, name, box.name))
    return out


def outside_axes(ax: Any, draw: bool = True, tolerance: float = 1.0) -> list[Finding]:
    """What ``ax`` holds that reaches outside it, for a figure drawn on the user's axes (the
    package's own figures put legends outside on purpose): its legend or a text of its own
    (``ax.text``, an annotation's words) past its frame on any side, or a title past the
    frame's left or right edge (into the neighbouring axes). ``draw`` as for
    :func:`findings`; ``tolerance`` px are allowed."""
    from matplotlib.text import Text

    if draw:
        _draw(ax.figure)
    renderer = ax.figure.canvas.get_renderer()
    frame = _grown(ax.get_window_extent(renderer), tolerance)
    where = _axes_name(ax.figure, ax)
    out = []
    legend = ax.get_legend()
    boxes = []
    if legend is not None and _drawn(legend):
        boxes.append((f"legend of {where}", legend.get_window_extent(renderer), True))
    for child in ax.get_children():
        if isinstance(child, Text):
            box = _text_box(child, renderer, f"{where}: text")
            if box is not None:
                boxes.append((box.name, box.bbox, child in ax.texts))
    for name, b, whole in boxes:
        sideways = b.x0 < frame.x0 or b.x1 > frame.x1
        if sideways or (whole and (b.y0 < frame.y0 or b.y1 > frame.y1)):
            out.append(Finding("outside its axes", name))
    return out


#: A unit in brackets: "t [s]", "E [J]", "e_eff [1]".
_UNIT = re.compile(r"\[[^\]]+\]")


def missing_units(fig: Any, draw: bool = True) -> list[str]:
    """The axes (x or y) of ``fig`` whose tick labels show numbers but whose label has no unit
    in brackets ([s], [m], [J], [1] for a ratio or a count), one line each. ``draw`` as for
    :func:`findings`."""
    if draw:
        _draw(fig)
    out = []
    for ax in fig.axes:
        if not ax.get_visible() or not ax.axison:
            continue
        for xy, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            if not axis.get_visible():
                continue
            shown = [t for tick in _ticks(axis) for t in (tick.label1, tick.label2)
                     if _drawn(t) and re.search(r"\d", t.get_text())]
            if not shown:
                continue
            label = axis.label.get_text() if _drawn(axis.label) else ""
            if not _UNIT.search(label):
                out.append(f"{_axes_name(fig, ax)}: {xy} axis {_short(label)} has no [unit]")
    return out
