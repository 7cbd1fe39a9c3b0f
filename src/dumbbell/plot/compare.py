"""Figures of a comparison (:class:`dumbbell.analysis.compare.Comparison`): heights of each
solver over the truth, position error against time, and E(t) per solver. Each draws on the
axes it is given or makes its own figure, and returns the axes; none saves. Every marked line
(the window, 1 mm, the truth's impacts) has its legend entry; the legend sits outside the axes,
on the right, on a figure of their own, and inside the user's axes, above the data."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..analysis.compare import PART_FRACTION, Comparison
from ..analysis.metrics import energy_error
from ..model import args
from ..solvers.advice import length as dumbbell_length
from .style import ROW_COLOURS, ROW_DASHES, _subplots, finish, legend, plain, wrap_texts

__all__ = ["compare", "compare_energy", "compare_positions"]


def _checked(result: Any, ax: Any) -> tuple[Comparison, Any]:
    return (args.instance(result, "result", Comparison, "a Comparison (from dumbbell.compare)"),
            args.axes(ax))


def _one_panel(result: Any, ax: Any) -> tuple[Comparison, Any, bool]:
    """The checked arguments of a one-panel figure: the result, the axes to draw on (a new
    figure's when ``ax`` is None) and whether the figure is the package's own."""
    result, ax = _checked(result, ax)
    own = ax is None
    if own:
        _, ax = _subplots(figsize=(11, 4.6))
    return result, ax, own


def _shown(result: Comparison) -> float:
    """The time shown in the heights figure (s): twice the window, at most the whole run."""
    return min(float(result.truth.t[-1]), 2.0 * result.window)


def _heights_panel(ax: Any, result: Comparison, body: str, own: bool) -> None:
    key = "x" if result.scene.system.dimensions == 1 else "y"
    truth = result.truth
    shown = _shown(result)
    m = truth.t <= shown + 1e-12
    ax.plot(truth.t[m], truth[f"{key}{body}"][m], color="black", lw=2.4, alpha=0.35,
            label=f"{truth.solver} (truth)")
    for colour, row in zip(ROW_COLOURS, result.rows, strict=False):
        r = row.traj
        mm = r.t <= shown + 1e-12
        ax.plot(r.t[mm], r[f"{key}{body}"][mm], color=colour, lw=1.1, label=row.label,
                ls=ROW_DASHES[result.rows.index(row) % len(ROW_DASHES)])
    ax.axvspan(result.window, max(shown, result.window), color="0.93", zorder=0,
               label="after the window:\nthe runs part (chaos)")
    ax.set_ylabel(f"{key}_{body} [m]")
    ax.set_title(f"particle {body} ({'top' if body == 'A' else 'bottom'})", fontsize=9)
    ax.grid(True, color="0.9", lw=0.6)
    ax.set_xlim(0, _shown(result))
    legend(ax, own)


def compare_positions(result: Comparison, ax: Any = None) -> Any:
    """Heights (m) of each solver over the truth's, twice the error window long: on ``ax``
    particle B only; without, A above B.

    Parameters
    ----------
    result, ax
        As for :func:`dumbbell.plot.compare`; on ``ax`` particle B only.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on: ``ax``, or the lower panel (B) of the new figure.

    Raises
    ------
    UsageError
        A bad ``result`` or ``ax``, as for :func:`dumbbell.plot.compare`.

    Examples
    --------
    Each run's heights over the truth's, past the window where the runs part:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> result = dumbbell.compare(scenes_dir() / "textbook-1d.toml", solvers=["euler-cromer"],
    ...                           dts=[1e-4], t_end=1.0, window=1.0)
    >>> dumbbell.plot.compare_positions(result).get_ylabel()
    'x_B [m]'
    """
    result, ax = _checked(result, ax)
    if ax is not None:
        ax.set_xlabel("t [s]")
        _heights_panel(ax, result, "B", own=False)
        return ax
    fig, axes = _subplots(2, 1, figsize=(11, 6.4), sharex=True)
    axes[-1].set_xlabel("t [s]")
    for panel, body in zip(axes, "AB", strict=True):
        _heights_panel(panel, result, body, own=True)
    fig.suptitle(f"{plain(result.scene.title)}: heights, each solver over the truth", fontsize=10)
    finish(fig)
    return axes[-1]


def compare(result: Comparison, ax: Any = None) -> Any:
    """Largest position error (m, log scale) of each solver against the truth over time, with
    the truth's impacts and the error window marked.

    Parameters
    ----------
    result : Comparison
        What :func:`dumbbell.compare` measured.
    ax : matplotlib.axes.Axes or None, default None
        Draw on these axes (the legend inside them, above the data); None: a new figure,
        the legend outside on the right.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on, ``ax`` or the new figure's.

    Raises
    ------
    UsageError
        A ``result`` that is not a Comparison (what :func:`dumbbell.compare` gives), or an
        ``ax`` that is not one Axes.

    Examples
    --------
    On the user's own axes:

    >>> import matplotlib.pyplot as plt
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> fig, ax = plt.subplots(figsize=(8, 4), layout="constrained")
    >>> result = dumbbell.compare(scenes_dir() / "textbook-1d.toml", solvers=["verlet"],
    ...                           dts=[1e-4], t_end=1.0, window=1.0)
    >>> dumbbell.plot.compare(result, ax=ax).get_yscale()
    'log'
    """
    result, ax, own = _one_panel(result, ax)
    scene, truth = result.scene, result.truth
    # Each entry says the span its maximum covers (up to where the runs part); on the user's
    # axes on one line.
    for colour, row in zip(ROW_COLOURS, result.rows, strict=False):
        t = row.traj.t[: len(row.error)]
        ax.semilogy(t, np.maximum(row.error, 1e-17), color=colour, lw=1.1,
                    ls=ROW_DASHES[result.rows.index(row) % len(ROW_DASHES)],
                    label=f"{row.label}: {row.window_error:.2g} m max"
                          + ("\n" if own else " ") + f"in [0, {row.error_until:.3g}] s"
                          + (" (then parted)" if row.error_until < result.window else ""))
    ax.axvline(result.window, color="0.4", ls="--", lw=0.8,
               label=f"end of the {result.window:g} s window")
    distance = PART_FRACTION * dumbbell_length(scene.system)
    ax.axhline(distance, color="0.6", ls=":", lw=0.8,
               label=f"{distance * 1e3:.3g} mm ({PART_FRACTION:.0%} of the dumbbell): past it,"
                     "\nthe runs have parted (at the impact before)")
    for i, ev in enumerate(truth.events):
        ax.axvline(ev.t, color="0.85", lw=0.6, zorder=0,
                   label=f"impacts of the truth ({truth.solver})" if i == 0 else None)
    positive = np.concatenate([row.error[row.error > 0] for row in result.rows] or [[1.0]])
    if positive.size:
        # A quarter decade under a decade: no tick label sits in the corner, on the x axis's.
        low = max(1e-16, float(np.percentile(positive, 1)) / 10)
        ax.set_ylim(bottom=10 ** (math.floor(math.log10(low)) - 0.25))
    ax.set_xlabel("t [s]")
    ax.set_ylabel("largest |position error| [m]")
    ax.set_xlim(0, float(truth.t[-1]))
    ax.grid(True, which="major", color="0.9", lw=0.6)
    # On the user's axes the scene's title is theirs to give (a figure's title): not repeated
    # over each axes.
    ax.set_title(f"{plain(scene.title)}: position error against {truth.solver}" if own
                 else f"Position error against {truth.solver}", fontsize=9)
    _end(ax, own)
    return ax


def _end(ax: Any, own: bool) -> None:
    """The legend, then the layout: the package's own figure finished, or the title wrapped
    to the width of the user's axes."""
    legend(ax, own)
    if own:
        finish(ax.figure)
    else:
        wrap_texts(ax)


def _truth_label(truth: Any, own: bool) -> str:
    """The truth's legend entry: its own energy drift, or only its name in a dissipative
    scene (nothing to measure its energy against); on one line on the user's axes."""
    error = energy_error(truth, None)
    name = f"{truth.solver} (truth)"
    return (f"{name}:{chr(10) if own else ' '}energy error {error:.1e}" if np.isfinite(error)
            else name)


def compare_energy(result: Comparison, ax: Any = None) -> Any:
    """E(t)/E(0) - 1 of each solver and of the truth.

    Parameters
    ----------
    result, ax
        The comparison and the axes, as for :func:`dumbbell.plot.compare`.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on (without ``ax``, the one axes of the new figure).

    Raises
    ------
    UsageError
        A bad ``result`` or ``ax`` (:func:`dumbbell.plot.compare` says which).

    Examples
    --------
    The energy each run gains or loses, beside the truth's own drift:

    >>> from dumbbell import compare, plot
    >>> from dumbbell.model.scene import scenes_dir
    >>> ax = plot.compare_energy(compare(scenes_dir() / "textbook-1d.toml",
    ...                                  solvers=["euler-cromer"], dts=[1e-4], t_end=1.0))
    >>> ax.get_ylabel()
    'E(t) / E(0) - 1 [1]'
    """
    result, ax, own = _one_panel(result, ax)
    scene, truth = result.scene, result.truth
    E0 = float(truth["E"][0]) or 1.0
    for colour, row in zip(ROW_COLOURS, result.rows, strict=False):
        r = row.traj
        ax.plot(r.t, r["E"] / E0 - 1.0, color=colour, lw=1.0,
                ls=ROW_DASHES[result.rows.index(row) % len(ROW_DASHES)],
                label=f"{row.label}:{chr(10) if own else ' '}energy error "
                      f"{row.energy_error:.2e}")
    ax.plot(truth.t, truth["E"] / E0 - 1.0, color="black", lw=1.2,
            label=_truth_label(truth, own))
    ax.set_xlabel("t [s]")
    ax.set_ylabel("E(t) / E(0) - 1 [1]")
    ax.set_xlim(0, float(truth.t[-1]))
    ax.grid(True, color="0.9", lw=0.6)
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
    ax.set_title((f"{plain(scene.title)}: total" if own else "Total")
                 + f" energy per solver, relative to E(0) = {E0:.4g} J", fontsize=9)
    _end(ax, own)
    return ax
