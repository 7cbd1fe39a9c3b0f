"""Figures of a comparison (:class:`dumbbell.analysis.compare.Comparison`): heights of each
solver over the truth, position error against time, and E(t) per solver. Each draws on the
axes it is given or makes its own figure, and returns the axes; none saves. Legends sit outside
the axes, on the right, and every marked line (the window, 1 mm, the truth's impacts) has its
entry there."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..analysis.compare import DIVERGED, Comparison
from ..analysis.metrics import energy_error
from ..model import args
from .style import ROW_COLOURS, ROW_DASHES, _subplots, legend_outside, plain

__all__ = ["compare", "compare_energy", "compare_positions"]


def _checked(result: Any, ax: Any) -> tuple[Comparison, Any]:
    return (args.instance(result, "result", Comparison, "a Comparison (from dumbbell.compare)"),
            args.axes(ax))


def _shown(result: Comparison) -> float:
    """The time shown in the heights figure (s): twice the window, at most the whole run."""
    return min(float(result.truth.t[-1]), 2.0 * result.window)


def _heights_panel(ax: Any, result: Comparison, body: str) -> None:
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
    legend_outside(ax)


def compare_positions(result: Comparison, ax: Any = None) -> Any:
    """Heights (m) of each solver over the truth's, twice the error window long: on ``ax``
    particle B only; without, A above B. Returns the (last) axes."""
    result, ax = _checked(result, ax)
    if ax is not None:
        _heights_panel(ax, result, "B")
        ax.set_xlabel("t [s]")
        ax.set_xlim(0, _shown(result))
        return ax
    fig, axes = _subplots(2, 1, figsize=(11, 6.4), sharex=True)
    for panel, body in zip(axes, "AB", strict=True):
        _heights_panel(panel, result, body)
    axes[-1].set_xlabel("t [s]")
    axes[-1].set_xlim(0, _shown(result))
    fig.suptitle(f"{plain(result.scene.title)}: heights, each solver over the truth", fontsize=10)
    fig.tight_layout()
    return axes[-1]


def compare(result: Comparison, ax: Any = None) -> Any:
    """Largest position error (m, log scale) of each solver against the truth over time, with
    the truth's impacts and the error window marked."""
    result, ax = _checked(result, ax)
    own = ax is None
    if own:
        fig, ax = _subplots(figsize=(11, 4.6))
    scene, truth = result.scene, result.truth
    for colour, row in zip(ROW_COLOURS, result.rows, strict=False):
        t = row.traj.t[: len(row.error)]
        ax.semilogy(t, np.maximum(row.error, 1e-17), color=colour, lw=1.1,
                    ls=ROW_DASHES[result.rows.index(row) % len(ROW_DASHES)],
                    label=f"{row.label}: {row.window_error:.2g} m max\nin [0, {result.window:g}] s")
    ax.axvline(result.window, color="0.4", ls="--", lw=0.8,
               label=f"end of the {result.window:g} s window")
    ax.axhline(DIVERGED, color="0.6", ls=":", lw=0.8,
               label=f"{DIVERGED * 1e3:g} mm: the runs have parted")
    for i, ev in enumerate(truth.events):
        ax.axvline(ev.t, color="0.85", lw=0.6, zorder=0,
                   label=f"impacts of the truth ({truth.solver})" if i == 0 else None)
    positive = np.concatenate([row.error[row.error > 0] for row in result.rows] or [[1.0]])
    if positive.size:
        ax.set_ylim(bottom=max(1e-16, float(np.percentile(positive, 1)) / 10))
    ax.set_xlabel("t [s]")
    ax.set_ylabel("largest |position error| [m]")
    ax.set_xlim(0, float(truth.t[-1]))
    ax.grid(True, which="major", color="0.9", lw=0.6)
    legend_outside(ax)
    ax.set_title(f"{plain(scene.title)}: position error against {truth.solver}", fontsize=9)
    if own:
        fig.tight_layout()
    return ax


def _truth_label(truth: Any) -> str:
    """The truth's legend entry: its own energy drift, or only its name in a dissipative
    scene (nothing to measure its energy against)."""
    error = energy_error(truth, None)
    name = f"{truth.solver} (truth)"
    return f"{name}:\nenergy error {error:.1e}" if np.isfinite(error) else name


def compare_energy(result: Comparison, ax: Any = None) -> Any:
    """E(t)/E(0) - 1 of each solver and of the truth."""
    result, ax = _checked(result, ax)
    own = ax is None
    if own:
        fig, ax = _subplots(figsize=(11, 4.6))
    scene, truth = result.scene, result.truth
    E0 = float(truth["E"][0]) or 1.0
    for colour, row in zip(ROW_COLOURS, result.rows, strict=False):
        r = row.traj
        ax.plot(r.t, r["E"] / E0 - 1.0, color=colour, lw=1.0,
                ls=ROW_DASHES[result.rows.index(row) % len(ROW_DASHES)],
                label=f"{row.label}:\nenergy error {row.energy_error:.2e}")
    ax.plot(truth.t, truth["E"] / E0 - 1.0, color="black", lw=1.2,
            label=_truth_label(truth))
    ax.set_xlabel("t [s]")
    ax.set_ylabel("E(t) / E(0) - 1 [1]")
    ax.set_xlim(0, float(truth.t[-1]))
    ax.grid(True, color="0.9", lw=0.6)
    legend_outside(ax)
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
    ax.set_title(f"{plain(scene.title)}: total energy per solver, relative to E(0) = {E0:.4g} J",
                 fontsize=9)
    if own:
        fig.tight_layout()
    return ax
