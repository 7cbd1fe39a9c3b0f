"""The one place colours, labels and line styles are defined, for figures and animations
(the particles' and energy terms' colours in :mod:`dumbbell.colours`, re-exported here).

Also :func:`pyplot`, the lazy import of matplotlib's pyplot, and how the package's figures are
made and laid out:

- :func:`_figure`, :func:`_subplots`: through pyplot, so that a notebook shows them and
  ``plt.show()`` opens them; but within :func:`dumbbell._install.command_line` (the
  ``dumbbell`` command, which only writes files), as a bare ``matplotlib.figure.Figure`` on the
  Agg canvas, without importing pyplot. The pixels are the same either way. None of this
  chooses a backend: a notebook keeps its own. Every such figure is laid out by matplotlib's
  constrained layout, which reserves room for every text (titles, tick and axis labels, colour
  bars, legends outside the axes) whatever their number and length;
- :func:`finish`, the last step of each figure the package makes: titles wrapped to the width
  they have, then the canvas grown wherever a text would still reach past its edge (a title or
  a legend wider than the whole figure): no text is ever cut;
- :func:`legend`: on the package's own figures the legend sits outside the axes, on the right
  (:func:`legend_outside`); on the user's axes it stays inside them, in a band above the data
  (:func:`legend_inside`), so that a figure drawn on a grid of the user's axes neither spills
  into its neighbours nor is squeezed by its legend.
"""

from __future__ import annotations

import re
from typing import Any

# Colour of each particle, the centre of mass and each energy term: defined apart, because the
# animations' palette is built from them without importing this package.
from ..colours import COLOURS  # noqa: F401  (re-exported)

#: No public names: the colours every figure shares.
__all__: list[str] = []

def plain(text: str) -> str:
    """``text`` of the user's (a scene's title or name) as matplotlib shows it letter for
    letter: it reads text between two ``$`` as mathtext, which a title such as ``"price
    $\\frac{ and $ end"`` breaks when the figure is drawn. The package's own labels use no
    mathtext; tick labels (which do, on log axes) are not touched."""
    return str(text).replace("$", r"\$")


#: Colour of the angular momentum L_cm (kept out of COLOURS: the GIF's palette is built from
#: those, and L_cm is text there, drawn in ink).
MOMENTUM_COLOUR = "#17becf"
#: Colour of E_heat, the energy the contacts dissipated (figures only, like L_cm).
HEAT_COLOUR = "#ff7f0e"

#: Legend text of each energy term.
LABELS = {"K_cm": "K_cm, centre of mass", "K_int": "K_int, relative to the centre of mass",
          "K_rot": "K_rot, rotation", "K_vib": "K_vib, vibration", "K_spin": "K_spin, own spin",
          "U_g": "U_g = M g X, external", "U_spring": "U_spring, internal", "E": "E, total",
          "E_lost": "E_lost", "E_heat": "E_heat, dissipated by contacts"}

#: Colour and marker of each solver in the benchmark figures.
SOLVER_STYLES = {"euler-cromer": ("#d62728", "o"), "verlet": ("#1f77b4", "s"),
                 "pymunk": ("#2ca02c", "^"), "euler-cromer-2d": ("#ff7f0e", "v"),
                 "exact": ("black", "*"), "reference": ("#9467bd", "P")}

#: Colours of the compared runs, in row order.
ROW_COLOURS = ["#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2"]
#: Line styles by row: runs that agree to rounding (pymunk and euler-cromer-2d) stay visible.
ROW_DASHES = ["-", (0, (4, 3)), (0, (1, 2)), "-.", "-", (0, (4, 3)), (0, (1, 2))]

#: Colours of the ways a run can fail, in the stability and sweep maps.
FAIL_COLOURS = {"unstable": "#bdbdbd", "tunnelled": "#f4a582", "failed": "#4d4d4d"}



def solver_style(name: str, i: int) -> tuple[str, str]:
    """Colour and marker of solver ``name``; the ``i``-th default for one without a style."""
    from ..model import args

    name = args.text(name, "name", "a solver name (str)")
    i = args.whole(i, "i", "index", lo=0)
    return SOLVER_STYLES.get(name, (f"C{i % 10}", "D"))


def legend_outside(ax: Any, *args: Any, **kwargs: Any) -> Any:
    """``ax.legend(*args, **kwargs)`` outside the axes, on the right, its top level with the
    axes' top: no curve of the axes can run through it, whatever the data (the figures are
    checked for that). ``fontsize`` is 8 unless given. Returns the legend. For the package's
    figures (not exported): ``ax`` is theirs, and constrained layout makes room for it."""
    kwargs.setdefault("fontsize", 8)
    return ax.legend(*args, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                     **kwargs)


#: The gap (points) between the data and a legend inside the axes above it.
_BAND_GAP = 4.0
#: The most of the axes' height a band above the data may take when the legend is placed:
#: past it the legend, at 7 points, goes below the axes instead. Drawn smaller later, an axes
#: gives its band up to _BAND_MOST_DRAWN, the data keeping the rest.
_BAND_MOST = 0.45
_BAND_MOST_DRAWN = 0.7


def legend_inside(ax: Any, *args: Any, **kwargs: Any) -> Any:
    """``ax.legend(*args, **kwargs)`` inside the user's axes ``ax``: at the top, in as many
    columns as fit the axes' width, over a band that the top of the y range is raised to
    leave free of data (lines running the whole height, such as a marked time, stop below it,
    and notes placed in axes fractions come down below it). No curve runs through it and
    nothing leaves the axes, so a figure drawn on one axes of the user's grid neither covers
    its neighbours nor is squeezed by its legend. The band is kept at each draw, at the size
    the axes is drawn (whatever layout the user applies later), until the user sets the y
    limits themselves. A legend that would take more than :data:`_BAND_MOST` of the axes'
    height even at 7 points hangs below them instead. ``fontsize`` is 8 unless given.
    Returns the legend."""
    kwargs.setdefault("fontsize", 8)
    count = len(kwargs["handles"]) if "handles" in kwargs else len(
        ax.get_legend_handles_labels()[1])
    old = ax.get_axes_locator()
    if isinstance(old, _Band):       # drawn on again: the old legend's band goes with it
        ax.set_axes_locator(old.before)
        for axis_locator, set_locator in (
                (ax.yaxis.get_major_locator(), ax.yaxis.set_major_locator),
                (ax.yaxis.get_minor_locator(), ax.yaxis.set_minor_locator)):
            if hasattr(axis_locator, "inner"):
                set_locator(axis_locator.inner)
    frame = ax.get_window_extent()
    for size in dict.fromkeys((kwargs["fontsize"], min(kwargs["fontsize"], 7))):
        legend = ax.legend(*args, **{**kwargs, "fontsize": size}, loc="upper center")
        band = _Band(ax, legend, max(count, 1))
        if band.fit(frame.width, frame.height) <= _BAND_MOST:
            band.keep()
            return legend
        band.undo()
    return legend_below(ax, *args, **kwargs)


class _Band:
    """A legend at the top of the user's axes, over a band kept free of data: placed for the
    axes' size now (:meth:`fit`), and again at each draw for the size it is drawn at (the
    axes' locator, :meth:`__call__`), until the user sets the y limits themselves."""

    def __init__(self, ax: Any, legend: Any, count: int) -> None:
        import numpy as np
        from matplotlib.text import Annotation

        self.ax, self.legend, self.count = ax, legend, count
        self.before = ax.get_axes_locator()
        self.lo, self.hi = ax.get_ylim()
        self.limits: tuple[float, float] | None = None
        # Lines from the axes' bottom to its top whatever the range (axvline), and notes
        # placed in axes fractions, as drawn before the band.
        self.lines = [(line, np.asarray(line.get_ydata(), dtype=float)) for line in ax.get_lines()
                      if line.get_transform().contains_branch_seperately(ax.transData)
                      == (True, False)]
        self.notes = [(t, t.xyann if isinstance(t, Annotation) else t.get_position())
                      for t in ax.texts
                      if (isinstance(t, Annotation) and t.anncoords == "axes fraction")
                      or (not isinstance(t, Annotation) and t.get_transform() == ax.transAxes)]

    def get_subplotspec(self) -> Any:
        """The axes' subplot spec: ``tight_layout`` lays out an axes that has a locator only
        when the locator answers this (as mpl_toolkits' locators do)."""
        return self.ax.get_subplotspec()

    def __call__(self, ax: Any, renderer: Any) -> Any:
        """The axes locator: the axes' box as it was (its own locator's or its position); the
        band fitted to that box's size, unless the user set the y limits since."""
        box = (self.before(ax, renderer) if self.before is not None
               else ax.get_position(original=True))
        if self.limits is None or ax.get_ylim() == self.limits:
            fig = ax.figure
            self.fit(box.width * fig.bbox.width, box.height * fig.bbox.height, renderer,
                     most=_BAND_MOST_DRAWN)
        return box

    def fit(self, width: float, height: float, renderer: Any = None,
            most: float = 0.9) -> float:
        """Fit the legend and its band to an axes ``width`` x ``height`` px: the most columns
        that fit, then the top of the y range raised (in the axis' own scale) so that the
        data fill the lowest 1 - band. Returns the band (a fraction of the height)."""
        import numpy as np

        legend = self.legend
        self._columns(0.98 * width, renderer)
        dpi = self.ax.figure.dpi
        pad = (legend.borderaxespad * legend.prop.get_size_in_points() + _BAND_GAP) * dpi / 72
        band = min((legend.get_window_extent(renderer).height + pad) / max(height, 1.0), most)
        scale = self.ax.yaxis.get_transform()
        a, b = scale.transform(np.array([[self.lo], [self.hi]], dtype=float)).ravel()
        top = scale.inverted().transform(np.array([[a + (b - a) / (1.0 - band)]])).ravel()[0]
        # Set only what changed: a draw that changes nothing marks nothing stale (an
        # interactive canvas would draw again, and again).
        if not np.isclose(self.ax.get_ylim()[1], top, rtol=1e-12, atol=0.0):
            self.ax.set_ylim(self.lo, top)
        self.limits = self.ax.get_ylim()
        keep = 1.0 - band
        for line, y in self.lines:
            new = np.minimum(y, keep)
            if not np.array_equal(np.asarray(line.get_ydata(), dtype=float), new):
                line.set_ydata(new)
        for text, (x, y) in self.notes:
            if hasattr(text, "xyann"):
                if tuple(text.xyann) != (x, y * keep):
                    text.xyann = (x, y * keep)
            elif tuple(text.get_position()) != (x, y * keep):
                text.set_position((x, y * keep))
        return band

    def _columns(self, room: float, renderer: Any) -> None:
        """The most columns whose legend fits in ``room`` px; in one column still too wide,
        its entries wrapped to the room left beside the keys."""
        legend = self.legend
        for ncol in range(self.count, 0, -1):
            legend.set_ncols(ncol)
            if legend.get_window_extent(renderer).width <= room:
                return
        texts = legend.get_texts()
        widest = max(t.get_window_extent(renderer).width for t in texts)
        keys = legend.get_window_extent(renderer).width - widest
        for t in texts:
            wrap_text(t, max(room - keys, 0.3 * room))

    def keep(self) -> None:
        """Keep the band at each draw (as the axes' locator), free of y ticks and grid lines
        (which would read as values of the data)."""
        self.ax.set_axes_locator(self)
        axis = self.ax.yaxis
        top = max(self.lo, self.hi)
        axis.set_major_locator(_ticks_under(axis.get_major_locator(), top))
        axis.set_minor_locator(_ticks_under(axis.get_minor_locator(), top))

    def undo(self) -> None:
        """Put back what :meth:`fit` changed and drop the legend."""
        self.ax.set_ylim(self.lo, self.hi)
        for line, y in self.lines:
            line.set_ydata(y)
        for text, xy in self.notes:
            if hasattr(text, "xyann"):
                text.xyann = xy
            else:
                text.set_position(xy)
        self.legend.remove()


def _ticks_under(inner: Any, top: float) -> Any:
    """A tick locator (``matplotlib.ticker.Locator``): the ticks of ``inner`` up to ``top``
    (a data value), none above."""
    import numpy as np
    from matplotlib.ticker import Locator

    def under(values: Any) -> Any:
        values = np.asarray(values)
        return values[values <= top + 1e-9 * abs(top)]

    class TicksUnder(Locator):
        #: The locator it filters.
        inner: Any = None

        def set_axis(self, axis: Any) -> None:
            super().set_axis(axis)
            inner.set_axis(axis)

        def __call__(self) -> Any:
            return under(inner())

        def tick_values(self, vmin: float, vmax: float) -> Any:
            return under(inner.tick_values(vmin, vmax))

    ticks = TicksUnder()
    ticks.inner = inner
    return ticks


def legend_below(ax: Any, *args: Any, **kwargs: Any) -> Any:
    """``ax.legend(*args, **kwargs)`` below the axes ``ax``, under its tick labels and x label
    (measured), without a frame, in as many columns as fit the axes' width: for a map, whose
    data fill the axes (on a figure of the package's own, :func:`finish` fits the columns
    again to the axes' width as laid out). ``fontsize`` is 8 unless given. Returns the
    legend."""
    from matplotlib.transforms import ScaledTranslation

    kwargs.setdefault("fontsize", 8)
    kwargs.setdefault("frameon", False)
    fig = ax.figure
    frame = ax.get_window_extent()
    axis = ax.xaxis.get_tightbbox()
    below = frame.y0 - min(frame.y0, axis.y0) if axis is not None else 0.0
    # Its top that far (inches: fonts do not scale with the axes) under the frame's bottom.
    drop = (below + _BAND_GAP * fig.dpi / 72.0) / fig.dpi
    anchor = ax.transAxes + ScaledTranslation(0.0, -drop, fig.dpi_scale_trans)
    count = len(kwargs["handles"]) if "handles" in kwargs else len(
        ax.get_legend_handles_labels()[1])
    legend = None
    for ncol in range(max(count, 1), 0, -1):
        legend = ax.legend(*args, loc="upper center", ncols=ncol, borderaxespad=0.0,
                           bbox_to_anchor=(0.5, 0.0), bbox_transform=anchor, **kwargs)
        if legend.get_window_extent().width <= frame.width:
            break
    return legend


def legend(ax: Any, own: bool, *args: Any, **kwargs: Any) -> Any:
    """The legend of ``ax``: outside on the right on the package's own figure (``own``),
    inside in a band above the data on the user's axes. Returns the legend."""
    return (legend_outside if own else legend_inside)(ax, *args, **kwargs)


def wrap_text(text: Any, length: float) -> bool:
    """Break ``text`` (a matplotlib Text: a title, an axis label) at spaces into lines no
    longer than ``length`` px where it is longer (along its direction: across for a level
    text, up for a rotated one); its own line breaks stay. A line with mathtext (an unescaped
    ``$``, where the text parses math) is left whole: breaking it could split a formula.
    Returns whether the text changed."""
    def size() -> float:
        box = text.get_window_extent()
        return box.height if abs(text.get_rotation() - 90.0) % 180.0 < 1.0 else box.width

    def fits(line: str) -> bool:
        text.set_text(line)
        return size() <= length

    def greedy(pieces: list[str]) -> list[str]:
        out = [pieces[0]]
        for piece in pieces[1:]:
            if fits(f"{out[-1]} {piece}"):
                out[-1] = f"{out[-1]} {piece}"
            else:
                out.append(piece)
        return out

    whole = text.get_text()
    if not whole.strip() or not text.get_visible() or size() <= length:
        return False
    lines = []
    for line in whole.split("\n"):
        if text.get_parse_math() and re.search(r"(?<!\\)\$", line):
            lines.append(line)
            continue
        # Whole phrases first (a break after a comma, colon or semicolon), so that "t_end =
        # 0.2 s" stays on one line; words only within a phrase too long for a line.
        # A unit in brackets stays with the word before it ("error [1]").
        for phrase in greedy(re.split(r"(?<=[,:;]) ", line)):
            lines.extend(greedy(re.split(r" (?!\[)", phrase)) if not fits(phrase)
                         else [phrase])
    text.set_text("\n".join(lines))
    return text.get_text() != whole


def wrap_texts(ax: Any) -> bool:
    """Wrap each title of ``ax`` (centre, left, right: the texts among its children that are
    neither its own texts nor its axis labels) and its x label to the axes' width, its y label
    to the axes' height. Returns whether any changed."""
    from matplotlib.text import Text

    frame = ax.get_window_extent()
    changed = [wrap_text(child, frame.width) for child in ax.get_children()
               if isinstance(child, Text) and child not in ax.texts]
    changed += [wrap_text(ax.xaxis.label, frame.width), wrap_text(ax.yaxis.label, frame.height)]
    return any(changed)


def _refit_below(ax: Any) -> bool:
    """A legend hanging below ``ax`` (:func:`legend_below`) in the most columns that fit the
    axes' width as laid out. Returns whether it changed."""
    legend = ax.get_legend()
    frame = ax.get_window_extent()
    if legend is None or legend.get_window_extent().y1 > frame.y0:
        return False
    before = legend.get_window_extent().width
    count = len(legend.get_texts())
    for ncol in range(max(count, 1), 0, -1):
        legend.set_ncols(ncol)
        if legend.get_window_extent().width <= frame.width:
            break
    return legend.get_window_extent().width != before


#: Room kept round the figure's contents when its canvas grows (inches).
_PAD = 0.06


def finish(fig: Any) -> Any:
    """The last step of each figure the package makes: lay it out (constrained layout), wrap
    each axes' titles and labels to its size and the figure's title to the figure's width
    (:func:`wrap_texts`), give each legend below an axes the columns that fit its width, then
    grow the canvas wherever a text still reaches past its edge (by as much, laid out again),
    until every text fits. Returns ``fig``."""
    for _ in range(6):
        fig.draw_without_rendering()
        changed = [wrap_texts(ax) | _refit_below(ax) for ax in fig.axes]
        # The figure's title (suptitle) among the figure's texts.
        changed += [wrap_text(text, 0.96 * fig.bbox.width) for text in fig.texts]
        if any(changed):
            continue                  # laid out again before it is measured
        box = fig.get_tightbbox()     # inches
        w, h = fig.get_size_inches()
        grow_w = max(0.0, -box.x0) + max(0.0, box.x1 - w)
        grow_h = max(0.0, -box.y0) + max(0.0, box.y1 - h)
        if max(grow_w, grow_h) * fig.dpi < 0.5:
            # Laid out and unchanged since: measuring only placed the titles again as the
            # draw did (and marked the figure stale for it). Not stale, a figure written as
            # it is keeps this layout (dumbbell.io.figures.write_figure).
            fig.stale = False
            break
        fig.set_size_inches(w + (grow_w + 2 * _PAD if grow_w > 0 else 0.0),
                            h + (grow_h + 2 * _PAD if grow_h > 0 else 0.0))
    return fig


def pyplot() -> Any:
    """matplotlib.pyplot, imported on first use (whatever backend is configured)."""
    import matplotlib.pyplot as plt

    return plt


def _figure(**kwargs: Any) -> Any:
    """A new figure (``kwargs`` as ``Figure`` takes them; constrained layout unless
    ``layout`` is given): pyplot's, or within :func:`dumbbell._install.command_line` a bare one
    on the Agg canvas."""
    from .._install import COMMAND_LINE

    kwargs.setdefault("layout", "constrained")
    if not COMMAND_LINE.get():
        return pyplot().figure(**kwargs)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(**kwargs)
    FigureCanvasAgg(fig)
    return fig


#: The keywords of ``pyplot.subplots`` that go to ``Figure.subplots`` (the rest make the figure).
_GRID_KEYWORDS = ("sharex", "sharey", "squeeze", "gridspec_kw")


def _subplots(nrows: int = 1, ncols: int = 1, **kw: Any) -> tuple[Any, Any]:
    """``pyplot.subplots`` by way of :func:`_figure`: the figure and its grid of axes."""
    grid = {k: kw.pop(k) for k in _GRID_KEYWORDS if k in kw}
    fig = _figure(**kw)
    return fig, fig.subplots(nrows, ncols, **grid)
