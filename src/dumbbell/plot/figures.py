"""The textbook's figures of section 13.5.1 as PNG, drawn from a :class:`Trajectory`.

- ``positions`` (Fig. 13.13): heights of A, B and the centre of mass;
- ``kinetic`` (Fig. 13.14): positions, then K_cm, K_int and E;
- ``potential`` (Fig. 13.15): positions, then the external (U_g) and internal (U_spring)
  potential energies.

All show the textbook's window, 0 to 2 s, and mark the first impact. Matplotlib is imported
only here, and only when a figure is drawn.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..io.files import atomic_output
from ..model.trajectory import Trajectory

#: The textbook's time window (s).
WINDOW = 2.0

COLOURS = {"A": "#1f77b4", "B": "#d62728", "cm": "black", "K_cm": "#1f77b4", "K_int": "#d62728",
           "K_rot": "#2ca02c", "K_vib": "#d62728", "K_spin": "#9467bd", "U_g": "#8c564b",
           "U_spring": "#e6a700", "E": "black", "E_lost": "#7f7f7f"}

LABELS = {"K_cm": "K_cm, centre of mass", "K_int": "K_int, relative to the centre of mass",
          "K_rot": "K_rot, rotation", "K_vib": "K_vib, vibration", "K_spin": "K_spin, own spin",
          "U_g": "U_g = M g X, external", "U_spring": "U_spring, internal", "E": "E, total",
          "E_lost": "E_lost"}


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _window(traj: Trajectory, window: float) -> np.ndarray:
    return traj.t <= window + 1e-12


def heights(traj: Trajectory) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertical positions of A, B and the centre of mass (m), in 1D or 2D."""
    scene = traj.scene
    key = "x" if scene.dimensions == 1 else "y"
    a, b = traj[f"{key}A"], traj[f"{key}B"]
    return a, b, (scene.A.mass * a + scene.B.mass * b) / scene.M


def _positions_panel(ax: Any, traj: Trajectory, window: float) -> None:
    m = _window(traj, window)
    t = traj.t[m]
    a, b, cm = (h[m] for h in heights(traj))
    name = "x" if traj.scene.dimensions == 1 else "y"
    ax.plot(t, a, color=COLOURS["A"], lw=1.3, label=f"{name}_A, top particle")
    ax.plot(t, b, color=COLOURS["B"], lw=1.3, label=f"{name}_B, bottom particle")
    ax.plot(t, cm, color=COLOURS["cm"], lw=1.6, ls=":", label="centre of mass")
    if traj.scene.floor is not None:
        ax.axhspan(min(0.0, float(np.nanmin([a.min(), b.min()]))) - 1.0, 0.0, color="0.88",
                   zorder=0)
        ax.axhline(0.0, color="0.4", lw=1.0)
    ax.set_ylabel(f"{name} [m]")
    top = float(np.nanmax(a)) if len(a) else 1.0
    ax.set_ylim(min(-0.05, float(np.nanmin(b)) - 0.05) if len(b) else -0.05, top * 1.08 + 0.02)
    ax.legend(loc="upper right", fontsize=8, framealpha=0.9)


def _mark_first_impact(axes: list[Any], traj: Trajectory, window: float, text: bool) -> None:
    first = traj.first_impact()
    if first is None or first.t > window:
        return
    for ax in axes:
        ax.axvline(first.t, color="0.5", lw=0.8, ls="--", zorder=1)
    if text:
        axes[0].annotate(f"first impact, t = {first.t:.4f} s", xy=(first.t, 1.0),
                         xycoords=("data", "axes fraction"), xytext=(4, -12),
                         textcoords="offset points", fontsize=8, color="0.3")


def _energy_panel(ax: Any, traj: Trajectory, names: list[str], window: float) -> None:
    m = _window(traj, window)
    for name in names:
        style = {"ls": ":", "lw": 1.8} if name == "E" else {"lw": 1.2}
        ax.plot(traj.t[m], traj[name][m], color=COLOURS.get(name), label=LABELS.get(name, name),
                **style)
    ax.set_ylabel("E [J]")
    values = np.concatenate([traj[name][m] for name in names])
    lo, hi = float(np.nanmin(values)), float(np.nanmax(values))
    span = hi - min(lo, 0.0)
    # Head room above the curves keeps the legend off the total-energy line.
    ax.set_ylim(min(lo, 0.0) - 0.04 * span, hi + 0.3 * span)
    ax.legend(loc="upper center", fontsize=8, framealpha=0.9, ncol=len(names))


def _finish(fig: Any, axes: list[Any], traj: Trajectory, window: float, path: Path,
            subtitle: str) -> Path:
    axes[-1].set_xlabel("t [s]")
    for ax in axes:
        ax.set_xlim(0, window)
        ax.grid(True, color="0.9", lw=0.6)
    _mark_first_impact(axes, traj, window, text=True)
    from ..solvers import solver_class

    # A solver without a step takes dt only as the sample spacing: not worth a title.
    dt = f", dt = {traj.dt:g} s" if traj.dt and solver_class(traj.solver).has_step else ""
    fig.suptitle(f"{traj.scene.title}\n{subtitle} ({traj.solver}{dt})", fontsize=10)
    fig.tight_layout()
    with atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=110)
    _pyplot().close(fig)
    return path


def positions_figure(traj: Trajectory, path: str | Path, window: float = WINDOW) -> Path:
    """Fig. 13.13: heights of A, B and the centre of mass over [0, window] s."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.2))
    _positions_panel(ax, traj, window)
    return _finish(fig, [ax], traj, window, Path(path),
                   "the centre of mass falls on parabolas; the particles oscillate about it")


def _two_panel(traj: Trajectory, path: str | Path, names: list[str], window: float,
               subtitle: str) -> Path:
    plt = _pyplot()
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6.4), sharex=True)
    _positions_panel(top, traj, window)
    _energy_panel(bottom, traj, names, window)
    return _finish(fig, [top, bottom], traj, window, Path(path), subtitle)


def kinetic_figure(traj: Trajectory, path: str | Path, window: float = WINDOW) -> Path:
    """Fig. 13.14: positions, then the kinetic energy split into K_cm and K_int, and E (J)."""
    names = ["K_cm", "K_int", "E"] if traj.scene.dimensions == 1 else [
        n for n in ("K_cm", "K_rot", "K_vib", "K_spin", "E") if n in traj.columns]
    return _two_panel(traj, path, names, window,
                      "kinetic energy: centre of mass against internal motion")


def potential_figure(traj: Trajectory, path: str | Path, window: float = WINDOW) -> Path:
    """Fig. 13.15: positions, then the external (U_g) and internal (U_spring) potential (J)."""
    names = [n for n in ("U_g", "U_spring") if n in traj.columns]
    return _two_panel(traj, path, names, window,
                      "potential energy: external (gravity) against internal (spring)")


def _plane_panel(ax: Any, traj: Trajectory, window: float) -> None:
    """The motion in the plane (2D): paths of A and B, and the dumbbell every 0.1 s."""
    m = _window(traj, window)
    xA, yA, xB, yB = (traj[c][m] for c in ("xA", "yA", "xB", "yB"))
    ax.plot(xA, yA, color=COLOURS["A"], lw=0.5, alpha=0.5)
    ax.plot(xB, yB, color=COLOURS["B"], lw=0.5, alpha=0.5)
    t = traj.t[m]
    snaps = np.searchsorted(t, np.arange(0.0, t[-1] + 1e-9, 0.1)) if len(t) else []
    for j, i in enumerate(snaps):
        grey = str(round(0.75 - 0.7 * j / max(1, len(snaps) - 1), 3))
        ax.plot([xA[i], xB[i]], [yA[i], yB[i]], color=grey, lw=1.0, zorder=2)
        ax.plot([xA[i]], [yA[i]], "o", ms=2.5, color=COLOURS["A"], zorder=3)
        ax.plot([xB[i]], [yB[i]], "o", ms=2.5, color=COLOURS["B"], zorder=3)
    lo = min(float(np.nanmin(yB)), float(np.nanmin(yA)), 0.0) - 0.05
    hi = max(float(np.nanmax(yA)), float(np.nanmax(yB))) + 0.05
    xs = np.concatenate([xA, xB])
    mid = 0.5 * (float(np.nanmin(xs)) + float(np.nanmax(xs)))
    half = max(0.5 * (float(np.nanmax(xs)) - float(np.nanmin(xs))) + 0.05, 0.35 * (hi - lo))
    if traj.scene.floor is not None:
        ax.axhline(0.0, color="0.4", lw=1.0)
        ax.axhspan(lo - 1.0, 0.0, color="0.88", zorder=0)
    ax.set_xlim(mid - half, mid + half)
    ax.set_ylim(lo, hi)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"in the plane, 0-{window:g} s\n(axis every 0.1 s, dark = later)", fontsize=8)


def _momentum_axis(ax: Any, traj: Trajectory, window: float) -> None:
    """L_cm (kg m^2/s) on a right-hand axis of ``ax``: flat in flight, a step at each impact."""
    m = _window(traj, window)
    right = ax.twinx()
    L = traj["L_cm"][m]
    right.plot(traj.t[m], L, color="#17becf", lw=1.0, ls=(0, (5, 2)),
               label="L_cm, about the centre of mass (right axis)")
    lo, hi = float(np.nanmin(L)), float(np.nanmax(L))
    pad = 0.1 * max(hi - lo, abs(hi), abs(lo), 1e-12)
    right.set_ylim(lo - pad, hi + 3 * pad)
    right.set_ylabel("L_cm [kg m^2/s]", color="#17becf")
    right.tick_params(axis="y", colors="#17becf", labelsize=8)
    # One legend, drawn on the upper axis so that the dashed line does not run through it.
    handles, labels = ax.get_legend_handles_labels()
    extra = right.get_legend_handles_labels()
    if ax.get_legend() is not None:
        ax.get_legend().remove()
    right.legend(handles + extra[0], labels + extra[1], loc="upper center", fontsize=8,
                 framealpha=0.9, ncol=3)


def energy_figure(traj: Trajectory, path: str | Path, window: float = WINDOW) -> Path:
    """Positions (and, in 2D, the motion in the plane), then the energy terms the scene has
    in two panels (J): the centre of mass's (K_cm, U_g) with E and E_lost, and the internal
    ones (K_int, or K_rot, K_vib, U_spring and K_spin)."""
    plt = _pyplot()
    cols = traj.columns
    outer = [n for n in ("K_cm", "U_g", "E", "E_lost") if n in cols]
    inner = [n for n in ("K_int", "K_rot", "K_vib", "U_spring", "K_spin") if n in cols]
    fig = plt.figure(figsize=(10, 8.6))
    wide = traj.scene.dimensions == 2
    grid = fig.add_gridspec(3, 3 if wide else 1, height_ratios=[1.1, 1, 1])
    top = fig.add_subplot(grid[0, :2] if wide else grid[0, 0])
    _positions_panel(top, traj, window)
    if wide:
        _plane_panel(fig.add_subplot(grid[0, 2]), traj, window)
    middle = fig.add_subplot(grid[1, :], sharex=top)
    bottom = fig.add_subplot(grid[2, :], sharex=top)
    _energy_panel(middle, traj, outer, window)
    middle.set_title("centre of mass: K_cm and U_g trade on each parabola; " + (
        "the floor takes energy out: E + E_lost stays at E(0)" if "E_lost" in cols
        else "E stays constant"), fontsize=9)
    if inner:
        _energy_panel(bottom, traj, inner, window)
        bottom.set_title("internal: the impacts feed the motion relative to the centre of mass",
                         fontsize=9)
        if "L_cm" in cols:
            _momentum_axis(bottom, traj, window)
    return _finish(fig, [top, middle, bottom], traj, window, Path(path),
                   "how the energy is shared")


def rotation_figure(traj: Trajectory, path: str | Path, window: float = WINDOW) -> Path:
    """Rotation preview: K_rot(t) of the spring dumbbell for k = 200, 2e3, 2e4 N/m beside
    the rigid one (see :mod:`dumbbell.analysis.rotation`)."""
    from ..analysis.rotation import rotation_figure as draw

    return draw(traj, path, window)


def topple_figure(traj: Trajectory, path: str | Path) -> Path:
    """The toppling dumbbell in ``traj`` against its closed form: angle, the centre of mass's
    horizontal position and the top particle's speed (see :mod:`dumbbell.analysis.topple`)."""
    from ..analysis.topple import closed_form, measure
    from .rotation_chapter import topple

    plt = _pyplot()
    fig, axes = plt.subplots(3, 1, figsize=(8.5, 8.0), sharex=True)
    topple(closed_form(traj.scene), measure(traj), ax=axes, solver=traj.solver)
    fig.tight_layout()
    path = Path(path)
    with atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return path


def contact_figure(traj: Trajectory, path: str | Path) -> Path:
    """Angular momentum about the contact point through the first impact of ``traj`` (2D):
    L_cm and the orbital part jump, their sum does not (see :mod:`dumbbell.analysis.contact`)."""
    from ..analysis.contact import about_contact
    from .rotation_chapter import contact_momentum

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8.5, 4.6))
    contact_momentum(about_contact(traj), ax=ax, solver=traj.solver)
    fig.tight_layout()
    path = Path(path)
    with atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return path


#: Figure name (as in a scene's ``[outputs] figures``) -> drawing function.
FIGURES: dict[str, Callable[[Trajectory, str | Path], Path]] = {
    "positions": positions_figure,
    "kinetic": kinetic_figure,
    "potential": potential_figure,
    "energy": energy_figure,
    "rotation": rotation_figure,
    "topple": topple_figure,
    "contact": contact_figure,
}
