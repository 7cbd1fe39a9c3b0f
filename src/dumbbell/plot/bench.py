"""Figures of a benchmark (:class:`dumbbell.analysis.bench.BenchResult`): work-precision
(error against run time) and convergence (error against dt, with the fitted orders). Each
draws on the axes it is given or makes its own figure, and returns the axes; none saves. The
legend of a figure of their own sits outside the axes (below the work-precision plot, whose
labels take the room beside its points; right of the convergence plot); on the user's axes,
inside them, above the data."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._display import counted
from ..analysis.bench import FIT_MAX_ERROR, BenchResult, dt_label
from ..model import args
from ..solvers import solver_class
from .style import (
    _subplots,
    finish,
    legend,
    legend_below,
    legend_inside,
    plain,  # the user's text, drawn as text
    solver_style,
    wrap_texts,
)

__all__ = ["convergence", "work_precision"]


def _checked(result: Any, ax: Any) -> tuple[BenchResult, Any]:
    return (args.instance(result, "result", BenchResult, "a BenchResult (from dumbbell.bench)"),
            args.axes(ax))


def work_precision(result: BenchResult, ax: Any = None) -> Any:
    """Log-log error (m) against run time (s), one line per solver, dt beside each point,
    failed runs as crosses on the top edge: the work-precision diagram.

    Parameters
    ----------
    result : BenchResult
        What :func:`dumbbell.bench` measured.
    ax : matplotlib.axes.Axes or None, default None
        Draw on these axes (the legend inside them); None: a new figure of its own, the
        legend below the plot.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on: ``ax``, or the new figure's one axes.

    Raises
    ------
    UsageError
        A ``result`` not a BenchResult (from :func:`dumbbell.bench`), or an ``ax`` not one Axes.

    Examples
    --------
    Two solvers, three steps each, run once:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> result = dumbbell.bench(scene, solvers=["euler-cromer", "verlet"],
    ...                         dts=[1e-3, 1e-4, 1e-5], window=1.0, t_end=1.0, repeat=1)
    >>> ax = dumbbell.plot.work_precision(result)
    >>> ax.get_xscale(), ax.get_yscale()
    ('log', 'log')
    """
    result, ax = _checked(result, ax)
    own = ax is None
    if own:
        fig, ax = _subplots(figsize=(7.2, 6.0), dpi=100)
    finite = [p.error for p in result.points if p.ran and math.isfinite(p.error) and p.error > 0]
    top = max(finite) * 8 if finite else 1.0
    names = list(dict.fromkeys(p.solver for p in result.points))
    labels: list[tuple[str, float, float, str]] = []
    for i, name in enumerate(names):
        colour, marker = solver_style(name, i)
        pts = [p for p in result.points if p.solver == name and p.ran]
        good = [p for p in pts if math.isfinite(p.error) and p.error > 0]
        bad = [p for p in pts if not math.isfinite(p.error)]
        single = all(p.dt is None for p in pts)  # a solver without a step: one point
        label = name
        if name == result.truth:
            label += (" (truth; error vs extended precision)"
                      if not solver_class(name).estimates_error
                      else " (truth; its own error estimate"
                      + (f" over [0, {good[0].window:g} s])" if good else ")"))
        elif single:
            label += " (error vs truth)"
        if good:
            ax.plot([p.seconds for p in good], [p.error for p in good], marker=marker,
                    color=colour, label=label, ms=11 if single else 6,
                    lw=0 if single else 1.5)
        for p in good:
            text = (dt_label(p.dt) if p.dt is not None
                    else f"samples every {dt_label(result.spacing)} s")
            labels.append((text, p.seconds, p.error, colour))
        if bad:
            ax.plot([p.seconds for p in bad], [top] * len(bad), ls="none", marker="x",
                    color=colour, ms=9, mew=2, label=f"{name}: failed ({bad[0].verdict})")
            labels.extend((dt_label(p.dt) if p.dt else "", p.seconds, top, colour)
                          for p in bad)
    sp = result.speedups()
    if sp:
        ax.axhline(sp["target_error"], color="grey", ls=":", lw=1,
                   label=f"textbook's accuracy ({sp['baseline']} at dt = 1e-5 s)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.margins(x=0.07, y=0.06)  # room for the labels of the outermost points
    ax.set_xlabel(f"run time [s], fastest of at least {counted(result.repeat, 'run')}")
    ax.set_ylabel(f"largest position error over [0, {result.window:g} s] [m]")
    ax.set_title(f"Work-precision: {plain(result.scene)}, {result.t_end:g} s simulated; "
                 f"labels: dt (s)", fontsize=10)
    ax.grid(True, which="major", alpha=0.3)
    if own:
        legend_below(ax)
        finish(fig)             # laid out before the labels are placed by their pixels
    else:
        legend_inside(ax)
        wrap_texts(ax)
    _place_labels(ax, labels)
    return ax


#: Where a point's label may go, in order of preference: offset (points) and alignment.
_LABEL_SPOTS = ((7, 2, "left"), (6, -11, "left"), (-7, 2, "right"), (-7, -11, "right"),
                (7, 9, "left"), (7, -18, "left"), (-7, 9, "right"), (-7, -18, "right"),
                (-4, 8, "right"), (4, 8, "left"), (-4, -17, "right"), (4, -17, "left"))


def _crossed(ax: Any, box: tuple[float, float, float, float]) -> bool:
    """Whether a drawn line of ``ax`` (a curve or a marked level) runs through ``box`` (px)."""
    from matplotlib.path import Path
    from matplotlib.transforms import Bbox

    bbox = Bbox.from_extents(*box)
    for line in ax.lines:
        if line.get_linestyle() in ("None", "", " ", "none") or not line.get_visible():
            continue
        xy = line.get_transform().transform_path(line.get_path()).vertices
        xy = xy[np.isfinite(xy).all(axis=1)]
        if len(xy) > 1 and Path(xy).intersects_bbox(bbox, filled=False):
            return True
    return False


def _place_labels(ax: Any, labels: list[tuple[str, float, float, str]],
                  size: float = 7.5) -> None:
    """Write each (text, x, y, colour) beside its point, at the first spot whose box (as the
    text is drawn: measured) stays inside the axes and overlaps neither a marker, a label
    already placed, the legend nor a line: near the point first, then farther out; where no
    spot is free, at the one with the fewest of those."""
    px = ax.figure.dpi / 72.0
    xy = ax.transData.transform([(x, y) for _, x, y, _ in labels]) if labels else []
    taken = [(u - 6, v - 6, u + 6, v + 6) for u, v in xy]  # the markers
    key = ax.get_legend()
    if key is not None:
        box = key.get_window_extent()
        taken.append((box.x0, box.y0, box.x1, box.y1))
    frame = ax.get_window_extent()
    gap = 2 * px
    spots = [(dx * f, dy * f, ha) for f in (1.0, 1.8, 2.6) for dx, dy, ha in _LABEL_SPOTS]
    for (text, x, y, colour), (u, v) in zip(labels, xy, strict=True):
        note = ax.annotate(text, (x, y), textcoords="offset points", xytext=spots[0][:2],
                           ha=spots[0][2], fontsize=size, color=colour)
        best: tuple[int, Any, Any] | None = None
        for spot in spots:
            dx, dy, ha = spot
            note.set_position((dx, dy))
            note.set_ha(ha)
            b = note.get_window_extent()
            box = (b.x0 - gap, b.y0, b.x1 + gap, b.y1)
            inside = (frame.x0 <= b.x0 and b.x1 <= frame.x1 and frame.y0 <= b.y0
                      and b.y1 <= frame.y1)
            clashes = (sum(box[0] < t[2] and t[0] < box[2] and box[1] < t[3] and t[1] < box[3]
                           for t in taken) + (not inside) + _crossed(ax, box))
            if best is None or clashes < best[0]:
                best = (clashes, spot, box)
            if clashes == 0:
                break
        _, (dx, dy, ha), box = best
        note.set_position((dx, dy))
        note.set_ha(ha)
        taken.append(box)


def convergence(result: BenchResult, ax: Any = None) -> Any:
    """Log-log error (m) against dt (s), one line per solver, with the fitted order.

    Parameters
    ----------
    result, ax
        As for :func:`dumbbell.plot.work_precision`: a bad ``result`` or ``ax``.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on, with one fitted line per solver.

    Raises
    ------
    UsageError
        A bad ``result`` or ``ax``, as :func:`dumbbell.plot.work_precision` says.

    Examples
    --------
    The measured order of Verlet's method over three steps, from the scene's file:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> result = dumbbell.bench(scenes_dir() / "textbook-1d.toml", solvers=["verlet"],
    ...                         dts=[1e-3, 1e-4, 1e-5], window=1.0, t_end=1.0, repeat=1)
    >>> dumbbell.plot.convergence(result).get_ylabel()
    'largest position error over [0, 1 s] [m]'
    """
    result, ax = _checked(result, ax)
    own = ax is None
    if own:
        fig, ax = _subplots(figsize=(9.6, 5.0), dpi=100)
    names = [n for n in dict.fromkeys(p.solver for p in result.points)
             if any(p.dt is not None for p in result.points if p.solver == n)]
    finite = [p.error for p in result.points if p.ran and math.isfinite(p.error) and p.error > 0]
    top = max(finite) * 8 if finite else 1.0
    for i, name in enumerate(names):
        colour, marker = solver_style(name, i)
        pts = [p for p in result.points if p.solver == name and p.ran and p.dt is not None]
        good = [p for p in pts if math.isfinite(p.error) and p.error > 0]
        bad = [p for p in pts if not math.isfinite(p.error)]
        fit = result.fits.get(name)
        label = name + (f":\nfitted order {fit.order:.2f} (dt {dt_label(min(fit.dts))} to "
                        f"{dt_label(max(fit.dts))} s)" if fit else ": no fit (< 3 points)")
        if fit and fit.expected is not None:
            label += f"\nits own order {fit.expected}: dashed"
        ax.plot([p.dt for p in good], [p.error for p in good], marker=marker, color=colour,
                lw=0, label=label)
        if fit:
            xs = np.array([min(fit.dts), max(fit.dts)])
            ax.plot(xs, 10 ** (fit.log10_c + fit.order * np.log10(xs)), color=colour, lw=1.2)
            if fit.expected is not None:
                # The slope the solver declares, through the middle of the fitted line.
                mid = np.log10(xs).mean()
                y_mid = fit.log10_c + fit.order * mid
                ax.plot(xs, 10 ** (y_mid + fit.expected * (np.log10(xs) - mid)), color=colour,
                        lw=1.0, ls="--")
        if bad:
            ax.plot([p.dt for p in bad], [top] * len(bad), ls="none", marker="x", color=colour,
                    ms=9, mew=2, label=f"{name}: failed")
    ax.axhline(FIT_MAX_ERROR, color="grey", ls=":", lw=1,
               label=f"fits use errors below {FIT_MAX_ERROR:g} m")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time step dt [s]")
    ax.set_ylabel(f"largest position error over [0, {result.window:g} s] [m]")
    ax.set_title(f"Convergence: {plain(result.scene)}, error over [0, {result.window:g} s]; "
                 "lines: least-squares fits", fontsize=10)
    ax.grid(True, which="major", alpha=0.3)
    legend(ax, own)
    if own:
        finish(fig)
    else:
        wrap_texts(ax)
    return ax
