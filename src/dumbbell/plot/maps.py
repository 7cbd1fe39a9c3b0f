"""Maps over a grid of runs: the sweep's map (or line) and the stability map of the explicit
spring step. Each draws on the axes it is given or makes its own figure, and returns the
axes; none saves."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._display import counted
from ..analysis.stability import MAP_RATIOS, MAP_STEPS, MAP_UNSTABLE_ENERGY, MAP_WDT
from ..analysis.sweep import Axis, PointResult, SweepResult
from ..errors import UsageError
from ..model import args
from ..model.trajectory import COMPLETE
from . import style
from .style import FAIL_COLOURS, _subplots, finish, legend, legend_below, legend_inside, wrap_texts

__all__ = ["stability_map", "sweep_map"]


def _edges(values: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around sorted centre values (midpoints, geometric on a log axis)."""
    v = np.log10(values) if log else values.astype(float)
    if len(v) == 1:
        mid = np.array([v[0] - 0.5, v[0] + 0.5])
    else:
        inner = 0.5 * (v[1:] + v[:-1])
        mid = np.concatenate([[2 * v[0] - inner[0]], inner, [2 * v[-1] - inner[-1]]])
    return 10**mid if log else mid


def _is_log(axis: Axis) -> bool:
    if axis.spacing == "log":
        return True
    vals = np.array(axis.values, dtype=float)
    return axis.spacing == "list" and bool(np.all(vals > 0)) and vals.max() / vals.min() > 100


AXIS_LABELS = {"spring.stiffness": "k, spring constant [N/m]", "run.dt": "dt, time step [s]",
               "bodies.A.mass": "m_A [kg]", "bodies.B.mass": "m_B [kg]",
               "spring.rest_length": "b, rest length [m]", "gravity.g": "g [m/s^2]",
               "floor.elasticity": "floor elasticity [1]", "run.t_end": "t_end [s]"}


def axis_label(key: str) -> str:
    """The axis label of a swept scene key (its unit in brackets), else the key itself."""
    return AXIS_LABELS.get(args.text(key, "key", "a dotted scene key (str)"), key)


def _check_maps(maps: Any) -> None:
    """``maps``: solver name -> its rows, one per point of the map's grid, in grid order."""
    points = len(MAP_WDT) * len(MAP_RATIOS)
    allowed = (f"must map solver names to lists of {points} PointResult rows from "
               "dumbbell.analysis.stability.map_rows")
    if (not isinstance(maps, dict) or not maps
            or not all(isinstance(k, str) and isinstance(v, list | tuple) and len(v) == points
                       and all(isinstance(r, PointResult) for r in v) for k, v in maps.items())):
        raise UsageError(f"maps = {args.show(maps)}: {allowed}", param="maps")


def sweep_map(result: SweepResult, ax: Any = None) -> Any:
    """The sweep's map: log10 of the largest relative energy error over the grid (two axes),
    or along its one axis, failures painted by verdict, and the line w*dt = 2.

    A map's colour bar takes its room from ``ax`` (as ``Figure.colorbar(ax=)`` does); its
    legend hangs below the x label on a figure of its own, and on the user's axes sits inside
    them, in a band above the map (:func:`~.style.legend_inside`).

    Parameters
    ----------
    result : SweepResult
        What :func:`dumbbell.sweep` ran.
    ax : matplotlib.axes.Axes or None, default None
        Draw on these axes (their colour bar takes its room from them); None: a new figure.

    Returns
    -------
    matplotlib.axes.Axes
        The map's axes (not the colour bar's).

    Raises
    ------
    UsageError
        ``result`` not a SweepResult (from :func:`dumbbell.sweep`), or ``ax`` not one Axes.

    Examples
    --------
    Three stiffnesses by three steps: the stiff, long steps blow up.

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> result = dumbbell.sweep(scene, {"k": [200.0, 2e4, 2e6], "dt": [1e-5, 1e-4, 1e-3]},
    ...                         t_end=0.2, workers=1)
    >>> ax = dumbbell.plot.sweep_map(result)
    >>> ax.get_ylabel()
    'dt, time step [s]'
    """
    result = args.instance(result, "result", SweepResult, "a SweepResult (from dumbbell.sweep)")
    ax = args.axes(ax)
    own = ax is None
    if own:
        _, ax = _subplots(figsize=(8.2, 6.2) if len(result.axes) == 2 else (8.2, 4.6))
    fig = ax.figure
    title = (f"Sweep of {style.plain(result.scene.name)}: {result.solver}, "
             f"t_end = {result.t_end:g} s, "
             f"{counted(len(result.rows), 'run')}")
    if len(result.axes) == 2:
        mesh, handles = draw_map(ax, result.axes[0], result.axes[1], result.rows, title)
        cbar = fig.colorbar(mesh, ax=ax, pad=0.02)
        cbar.set_label("log10 of the largest |E - E0| / |E0| [1]")
        if own:
            legend_below(ax, handles=handles)   # its columns fitted again once laid out
        else:
            wrap_texts(cbar.ax)
            legend_inside(ax, handles=handles)
    else:
        draw_line(ax, result.axes[0], result.rows, title, own)
    if own:
        finish(fig)
    else:
        wrap_texts(ax)
    return ax


def draw_map(ax: Any, x_axis: Axis, y_axis: Axis, rows: list[PointResult],
             title: str, x_label: str | None = None, y_label: str | None = None,
             wdt: np.ndarray | None = None, limits: tuple[int, int] | None = None
             ) -> tuple[Any, list[Any]]:
    """Paint a 2D grid of sweep rows (x outer, y inner, as in grid order) on ``ax``:
    colour by log10 of the largest relative energy error (between ``limits``, else fitted),
    failures by verdict, and the line w*dt = 2 (from the rows' w_dt, or ``wdt`` given on the
    same grid: :func:`limit_line`). Returns the colour mesh and the legend's entries (for
    :func:`~.style.legend_below`, once the figure is laid out)."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    if not (x_axis.numeric and y_axis.numeric):
        raise UsageError(f"axes {x_axis.key}, {y_axis.key}: a map needs numbers on both")
    nx, ny = len(x_axis.values), len(y_axis.values)
    xs, ys = np.array(x_axis.values, float), np.array(y_axis.values, float)
    grid = np.array(rows, dtype=object).reshape(nx, ny).T  # [iy, ix]
    xo, yo = np.argsort(xs), np.argsort(ys)
    grid = grid[np.ix_(yo, xo)]
    xs, ys = xs[xo], ys[yo]
    err = np.array([[r.max_rel_energy_error for r in line] for line in grid], float)
    verdict = np.array([[r.verdict for r in line] for line in grid])
    w_dt = (np.array([[r.w_dt for r in line] for line in grid], float) if wdt is None
            else wdt)
    xlog, ylog = _is_log(x_axis), _is_log(y_axis)
    xe, ye = _edges(xs, xlog), _edges(ys, ylog)
    with np.errstate(divide="ignore", invalid="ignore"):
        level = np.log10(np.maximum(err, 1e-17))
    # Runs that reached their end (ok or inaccurate) are coloured by their error.
    level = np.ma.masked_where(~np.isin(verdict, COMPLETE) | ~np.isfinite(level), level)
    if limits is None:
        lo = math.floor(float(level.min())) if level.count() else -16
        limits = (lo, max(lo + 1, math.ceil(float(level.max()))) if level.count() else 2)
    mesh = ax.pcolormesh(xe, ye, level, cmap="viridis", vmin=limits[0], vmax=limits[1],
                         shading="flat")
    handles = []
    for code, (name, colour) in enumerate(FAIL_COLOURS.items()):
        mask = verdict == name
        if mask.any():
            ax.pcolormesh(xe, ye, np.ma.masked_where(~mask, np.full(mask.shape, code)),
                          cmap=ListedColormap([colour]), shading="flat")
            handles.append(Patch(facecolor=colour, edgecolor="0.3",
                                 label=f"{name} ({counted(int(mask.sum()), 'run')})"))
    if x_axis.key == "w_dt":
        ax.axvline(2.0, color="red", lw=2.2, ls="--")
        handles.append(_legend_line("red", "--", "w*dt = 2: stability limit from theory"))
    elif np.nanmax(w_dt) > 2.0 > np.nanmin(w_dt):
        for x, y in limit_line(xs, ys, w_dt, xlog, ylog):
            ax.plot(x, y, color="red", lw=2.2, ls="--")
        handles.append(_legend_line("red", "--", "w*dt = 2: stability limit from theory"))
    else:
        handles.append(Patch(facecolor="none", edgecolor="none",
                             label=f"w*dt from {np.nanmin(w_dt):.2g} to {np.nanmax(w_dt):.2g}: "
                                   "the line w*dt = 2 is off the map"))
    ax.set_xscale("log" if xlog else "linear")
    ax.set_yscale("log" if ylog else "linear")
    ax.set_xlim(xe[0], xe[-1])
    ax.set_ylim(ye[0], ye[-1])
    ax.set_xlabel(x_label or axis_label(x_axis.key))
    ax.set_ylabel(y_label or axis_label(y_axis.key))
    ax.set_title(title, fontsize=10)
    return mesh, handles


def limit_line(xs: np.ndarray, ys: np.ndarray, w_dt: np.ndarray, xlog: bool, ylog: bool
               ) -> list[tuple[np.ndarray, np.ndarray]]:
    """The line w*dt = 2 over a map whose cells are centred on the sorted ``xs`` and ``ys``
    (``w_dt[iy, ix]`` at each centre), out to the map's edges: its pieces, as (x, y) arrays.

    Traced in the axes' own scale (log10 of a log axis), where log10(w*dt) is linear in
    log k and log dt: the level crossings interpolated there lie on the exact line, and the
    pieces between them are straight on the drawn axes. (Interpolated in the values
    themselves, the crossings fall off the line and the contour kinks at each decade.) The
    grid is carried to the cells' outer edges linearly in the same scale."""
    import contourpy

    def scaled(values: np.ndarray, log: bool) -> np.ndarray:
        return np.log10(values) if log else values.astype(float)

    u, v = scaled(xs, xlog), scaled(ys, ylog)
    ue, ve = scaled(_edges(xs, xlog), xlog), scaled(_edges(ys, ylog), ylog)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.log10(w_dt) - math.log10(2.0)
    u, z = _to_edges(u, ue[[0, -1]], z, axis=1)
    v, z = _to_edges(v, ve[[0, -1]], z, axis=0)
    pieces = contourpy.contour_generator(u, v, np.ma.masked_invalid(z)).lines(0.0)
    back = [(10**p[:, 0] if xlog else p[:, 0], 10**p[:, 1] if ylog else p[:, 1])
            for p in pieces if len(p) >= 2]
    return back


def _to_edges(centres: np.ndarray, ends: np.ndarray, z: np.ndarray, axis: int
              ) -> tuple[np.ndarray, np.ndarray]:
    """Cell centres ``centres`` and ``z`` along ``axis`` extended to the two outer edges
    ``ends``, z linearly from its two outermost values on each side (held where the axis has
    one value)."""
    z = np.moveaxis(z, axis, 0)
    if len(centres) < 2:
        first, last = z[0], z[-1]
    else:
        first = z[0] + (z[0] - z[1]) * (ends[0] - centres[0]) / (centres[0] - centres[1])
        last = z[-1] + (z[-1] - z[-2]) * (ends[1] - centres[-1]) / (centres[-1] - centres[-2])
    out = np.concatenate([first[None], z, last[None]])
    return np.concatenate([[ends[0]], centres, [ends[1]]]), np.moveaxis(out, 0, axis)


def _legend_line(colour: str, style: str, label: str) -> Any:
    from matplotlib.lines import Line2D

    return Line2D([], [], color=colour, ls=style, lw=2.2, label=label)


def draw_line(ax: Any, axis: Axis, rows: list[PointResult], title: str, own: bool) -> None:
    """A one-axis sweep: log10 of the largest relative energy error against the value, the
    failures marked by verdict and the value where w*dt = 2; the legend outside on the right
    of the package's own figure (``own``), else inside the axes."""
    if not axis.numeric:
        raise UsageError("grid: a plot needs a numeric axis; use a list of numbers", param="grid")
    xs = np.array(axis.values, float)
    order = np.argsort(xs)
    xs = xs[order]
    rows = [rows[i] for i in order]
    err = np.array([r.max_rel_energy_error for r in rows], float)
    verdicts = [r.verdict for r in rows]
    ok = np.array([v in COMPLETE for v in verdicts])
    label = ("ok" if all(v == "ok" for v in verdicts if v in COMPLETE)
             else "stable: ok or inaccurate")
    ax.plot(xs[ok], err[ok], "o-", color="#31688e", ms=4, lw=1.2, label=label)
    top = np.nanmax(err[np.isfinite(err)]) if np.isfinite(err).any() else 1.0
    for name, colour in FAIL_COLOURS.items():
        mask = np.array([v == name for v in verdicts])
        if mask.any():
            # At the error reached before the run stopped; off the top if none was finite.
            ys = np.where(np.isfinite(err[mask]), err[mask], max(top, 1.0) * 3)
            ax.plot(xs[mask], ys, "X", color=colour, mec="0.2", ms=9, ls="none",
                    label=f"{name} ({counted(int(mask.sum()), 'run')}, error when it stopped)")
    w_dt = np.array([r.w_dt for r in rows], float)
    cross = np.flatnonzero(np.diff(np.sign(w_dt - 2.0)) != 0)
    if cross.size:
        j = int(cross[0])
        # Interpolate log(w*dt) between the two values around 2.
        f = (math.log(2.0) - math.log(w_dt[j])) / (math.log(w_dt[j + 1]) - math.log(w_dt[j]))
        x2 = (xs[j] * (xs[j + 1] / xs[j]) ** f if _is_log(axis)
              else xs[j] + f * (xs[j + 1] - xs[j]))
        ax.axvline(x2, color="red", ls="--", lw=2, label="w*dt = 2: stability limit")
    ax.set_yscale("log")
    if _is_log(axis):
        ax.set_xscale("log")
    ax.set_xlabel(axis_label(axis.key))
    ax.set_ylabel("largest relative energy error [1]")
    ax.set_title(title, fontsize=10)
    ax.grid(True, color="0.9")
    legend(ax, own)


def stability_map(maps: dict[str, list[PointResult]]) -> list[Any]:
    """One panel per solver (rows of :func:`dumbbell.analysis.stability.map_rows`): log10 of
    the largest relative energy error over (w*dt, mass ratio), blow-ups marked, and the line
    w*dt = 2. Makes its own figure (the panels share one colour bar).

    Parameters
    ----------
    maps : dict of str to list of PointResult
        Solver name -> its map's rows, in grid order.

    Returns
    -------
    list of matplotlib.axes.Axes
        The panels, one per solver.

    Raises
    ------
    UsageError
        A ``maps`` that is not such a dict of rows.

    Examples
    --------
    One solver's map, its points run in this process:

    >>> import dumbbell
    >>> from dumbbell.analysis.stability import map_rows
    >>> panels = dumbbell.plot.stability_map({"euler-cromer": map_rows("euler-cromer",
    ...                                                                workers=1)})
    >>> len(panels)
    1
    """
    _check_maps(maps)
    n = len(maps)
    fig, axes = _subplots(1, n, figsize=(4.6 * n + 1.2, 4.6), squeeze=False)
    x_axis = Axis("w_dt", "w*dt", MAP_WDT, "lin")
    y_axis = Axis("mass_ratio", "mB/mA", MAP_RATIOS, "log")
    errs = [r.max_rel_energy_error for rows in maps.values() for r in rows
            if r.verdict in COMPLETE and r.max_rel_energy_error > 0]
    lo = math.floor(math.log10(min(errs))) if errs else -16
    hi = max(lo + 1, math.ceil(math.log10(max(errs)))) if errs else 3
    mesh = None
    for ax, (solver, rows) in zip(axes[0], maps.items(), strict=True):
        wdt = np.array([[r.w_dt for r in rows[i::len(MAP_RATIOS)]]
                        for i in range(len(MAP_RATIOS))], float)
        mesh, handles = draw_map(ax, x_axis, y_axis, rows, solver,
                                 x_label="w*dt, w = sqrt(k/mu) [1]",
                                 y_label="mass ratio mB/mA [1]", wdt=wdt, limits=(lo, hi))
        legend_below(ax, handles=handles)   # its columns fitted again once laid out
    cbar = fig.colorbar(mesh, ax=list(axes[0]), pad=0.02, aspect=30)
    cbar.set_label("log10 of the largest relative energy error [1]")
    fig.suptitle(f"Stability of the explicit spring step: {MAP_STEPS} steps per run, no floor, "
                 f"no gravity;\n'unstable' = non-finite or energy error > "
                 f"{MAP_UNSTABLE_ENERGY:g}", fontsize=10)
    finish(fig)
    return list(axes[0])
