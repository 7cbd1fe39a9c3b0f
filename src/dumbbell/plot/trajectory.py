"""The textbook's figures of section 13.5.1, drawn from a :class:`Trajectory`.

- :func:`positions` (Fig. 13.13): heights of A, B and the centre of mass;
- :func:`kinetic` (Fig. 13.14): positions, then K_cm, K_int and E;
- :func:`potential` (Fig. 13.15): positions, then the external (U_g) and internal (U_spring)
  potential energies;
- :func:`energy`: every energy term the scene has (and in 2D the motion in the plane).

All show the textbook's window, 0 to 2 s, and mark the first impact. Each draws on the axes
it is given, or makes its own figure when given none, and returns the axes; none saves (see
:func:`dumbbell.io.figures.save_figure`). Matplotlib is imported only when a figure is drawn.
On a figure of their own, legends sit outside the axes, on the right, and the first impact's
time above the top axes, so that no curve runs through text whatever the data; on the user's
axes, the legend (with the first impact's time in it) sits inside them, in a band above the
data (:func:`dumbbell.plot.style.legend_inside`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import UsageError
from ..model import args
from ..model.trajectory import Trajectory
from .style import (
    COLOURS,
    HEAT_COLOUR,
    LABELS,
    MOMENTUM_COLOUR,
    _figure,
    _subplots,
    finish,
    legend,
    plain,
)

__all__ = ["energy", "kinetic", "positions", "potential"]

#: The textbook's time window (s).
WINDOW = 2.0


def _window(traj: Trajectory, window: float) -> np.ndarray:
    return traj.t <= window + 1e-12


def heights(traj: Trajectory) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertical positions of A, B and the centre of mass (m), in 1D or 2D."""
    args.trajectory(traj)
    scene = traj.scene
    key = "x" if scene.system.dimensions == 1 else "y"
    a, b = traj[f"{key}A"], traj[f"{key}B"]
    return a, b, (scene.system.A.mass * a + scene.system.B.mass * b) / scene.system.M


def _positions_panel(ax: Any, traj: Trajectory, window: float) -> None:
    m = _window(traj, window)
    t = traj.t[m]
    a, b, cm = (h[m] for h in heights(traj))
    name = "x" if traj.scene.system.dimensions == 1 else "y"
    ax.plot(t, a, color=COLOURS["A"], lw=1.3, label=f"{name}_A, top particle")
    ax.plot(t, b, color=COLOURS["B"], lw=1.3, label=f"{name}_B, bottom particle")
    ax.plot(t, cm, color=COLOURS["cm"], lw=1.6, ls=":", label="centre of mass")
    if traj.scene.system.floor is not None:
        ax.axhspan(min(0.0, float(np.nanmin([a.min(), b.min()]))) - 1.0, 0.0, color="0.88",
                   zorder=0)
        ax.axhline(0.0, color="0.4", lw=1.0)
    ax.set_ylabel(f"{name} [m]")
    top = float(np.nanmax(a)) if len(a) else 1.0
    ax.set_ylim(min(-0.05, float(np.nanmin(b)) - 0.05) if len(b) else -0.05, top * 1.08 + 0.02)


def _mark_first_impact(axes: list[Any], traj: Trajectory, window: float, text: bool) -> None:
    """A dashed line at the first impact through every panel, and its time written above the
    top panel (outside it: no curve can cross the words), on the side with more room; without
    ``text`` (the user's axes) its time is the line's legend entry instead."""
    first = traj.first_impact()
    if first is None or first.t > window:
        return
    for ax in axes:
        ax.axvline(first.t, color="0.5", lw=0.8, ls="--", zorder=1,
                   label=None if text else f"first impact, t = {first.t:.4f} s")
    if text:
        left = first.t <= 0.6 * window
        axes[0].annotate(f"first impact, t = {first.t:.4f} s", xy=(first.t, 1.0),
                         xycoords=("data", "axes fraction"), xytext=(2 if left else -2, 2),
                         textcoords="offset points", ha="left" if left else "right",
                         va="bottom", fontsize=8, color="0.3")


def _energy_panel(ax: Any, traj: Trajectory, names: list[str], window: float) -> None:
    m = _window(traj, window)
    for name in names:
        style = {"ls": ":", "lw": 1.8} if name == "E" else {"lw": 1.2}
        colour = HEAT_COLOUR if name == "E_heat" else COLOURS.get(name)
        ax.plot(traj.t[m], traj[name][m], color=colour, label=LABELS.get(name, name),
                **style)
    ax.set_ylabel("E [J]")
    values = np.concatenate([traj[name][m] for name in names])
    lo, hi = float(np.nanmin(values)), float(np.nanmax(values))
    span = hi - min(lo, 0.0)
    ax.set_ylim(min(lo, 0.0) - 0.04 * span, hi + 0.08 * span)


def _frame(axes: list[Any], traj: Trajectory, window: float, own: bool = True) -> None:
    """Time axis, grid and first-impact mark shared by every panel, then each panel's legend
    (outside on the package's own figure, ``own``; inside on the user's axes)."""
    axes[-1].set_xlabel("t [s]")
    for ax in axes:
        ax.set_xlim(0, window)
        ax.grid(True, color="0.9", lw=0.6)
    _mark_first_impact(axes, traj, window, text=own)
    for ax in axes:
        legend(ax, own)


def _checked(traj: Any, ax: Any, window: Any) -> tuple[Trajectory, Any, float]:
    """A figure's arguments at the border: a Trajectory, None or an Axes, a window > 0 (s)."""
    return args.trajectory(traj), args.axes(ax), args.real(window, "window", "s")


def _title(fig: Any, axes: list[Any], traj: Trajectory, window: float, subtitle: str) -> None:
    """Finish a figure this module made: shared frame, then the title naming the run."""
    _frame(axes, traj, window)
    # A solver without a step takes dt only as the sample spacing: not worth a title (a
    # stepping solver counts its steps in info).
    dt = f", dt = {traj.dt:g} s" if traj.dt and "steps" in traj.info else ""
    fig.suptitle(f"{plain(traj.scene.title)}\n{subtitle} ({traj.solver}{dt})", fontsize=10)
    finish(fig)


def positions(traj: Trajectory, ax: Any = None, window: float = WINDOW) -> Any:
    """Fig. 13.13: heights of A, B and the centre of mass (m) over [0, window] s.

    Parameters
    ----------
    traj : Trajectory
        The run.
    ax : matplotlib.axes.Axes or None, default None
        Draw on these axes; None: a new figure (see below).
    window : float, default 2.0
        The span [0, window] (s) drawn.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on (``ax.figure`` is the figure).

    Raises
    ------
    UsageError
        A ``traj`` that is not a Trajectory, an ``ax`` that is not one Axes, or a window
        that is not a positive number.

    Examples
    --------
    The textbook's run, solved exactly, on a figure of its own:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> traj = dumbbell.simulate(scene, solver="exact", t_end=2.0, dt=1e-3)
    >>> ax = dumbbell.plot.positions(traj)
    >>> ax.figure.savefig("positions.png")
    """
    traj, ax, window = _checked(traj, ax, window)
    if ax is not None:
        _positions_panel(ax, traj, window)
        _frame([ax], traj, window, own=False)
        return ax
    fig, ax = _subplots(figsize=(9.5, 4.2))
    _positions_panel(ax, traj, window)
    _title(fig, [ax], traj, window,
           "the centre of mass falls on parabolas; the particles oscillate about it")
    return ax


def _two_panel(traj: Trajectory, ax: Any, names: list[str], window: float,
               subtitle: str) -> Any:
    """The energy terms ``names`` on ``ax``; without one, a figure of the positions above
    them (the textbook's layout). Returns the energy axes."""
    if ax is not None:
        _energy_panel(ax, traj, names, window)
        _frame([ax], traj, window, own=False)
        return ax
    fig, (top, bottom) = _subplots(2, 1, figsize=(9.5, 6.4), sharex=True)
    _positions_panel(top, traj, window)
    _energy_panel(bottom, traj, names, window)
    _title(fig, [top, bottom], traj, window, subtitle)
    return bottom


def kinetic(traj: Trajectory, ax: Any = None, window: float = WINDOW) -> Any:
    """Fig. 13.14: the kinetic energy split into K_cm and K_int (in 2D K_rot, K_vib, K_spin),
    and E (J); without ``ax``, below the positions.

    Parameters
    ----------
    traj, ax, window
        As for :func:`dumbbell.plot.positions` (``ax`` None: a new figure, see above).

    Returns
    -------
    matplotlib.axes.Axes
        The energy panel.

    Raises
    ------
    UsageError
        As for :func:`dumbbell.plot.positions`.

    Examples
    --------
    The kinetic and the potential energy side by side, on the user's own figure:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> traj = dumbbell.simulate(scene, solver="exact", t_end=2.0, dt=1e-3)
    >>> import matplotlib.pyplot as plt
    >>> fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.5), layout="constrained")
    >>> _ = dumbbell.plot.kinetic(traj, ax=left)
    >>> _ = dumbbell.plot.potential(traj, ax=right)
    >>> fig.savefig("energies.png")
    """
    traj, ax, window = _checked(traj, ax, window)
    names = ["K_cm", "K_int", "E"] if traj.scene.system.dimensions == 1 else [
        n for n in ("K_cm", "K_rot", "K_vib", "K_spin", "E") if n in traj.columns]
    return _two_panel(traj, ax, names, window,
                      "kinetic energy: centre of mass against internal motion")


def potential(traj: Trajectory, ax: Any = None, window: float = WINDOW) -> Any:
    """Fig. 13.15: the external (U_g) and internal (U_spring) potential energy (J); without
    ``ax``, below the positions.

    Parameters
    ----------
    traj, ax, window
        As for :func:`dumbbell.plot.kinetic`.

    Returns
    -------
    matplotlib.axes.Axes
        The energy panel: ``ax``, or the lower panel of the new figure.

    Raises
    ------
    UsageError
        The arguments' faults that :func:`dumbbell.plot.positions` names.

    Examples
    --------
    The exact run of the textbook's scene, straight from its file:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> ax = dumbbell.plot.potential(dumbbell.simulate(
    ...     dumbbell.load_scene(scenes_dir() / "textbook-1d.toml"), solver="exact", t_end=2.0))
    >>> len(ax.figure.axes)                          # the positions above it
    2
    """
    traj, ax, window = _checked(traj, ax, window)
    names = [n for n in ("U_g", "U_spring") if n in traj.columns]
    return _two_panel(traj, ax, names, window,
                      "potential energy: external (gravity) against internal (spring)")


def _plane_panel(ax: Any, traj: Trajectory, window: float) -> None:
    """The motion in the plane (2D): paths of A and B, and the dumbbell every 0.1 s."""
    m = _window(traj, window)
    xA, yA, xB, yB = (traj[c][m] for c in ("xA", "yA", "xB", "yB"))
    ax.plot(xA, yA, color=COLOURS["A"], lw=0.5, alpha=0.5)
    ax.plot(xB, yB, color=COLOURS["B"], lw=0.5, alpha=0.5)
    t = traj.t[m]
    # Clipped: a snapshot time may round past the last sample (0.1 * 3 > 0.3).
    snaps = (np.minimum(np.searchsorted(t, np.arange(0.0, t[-1] + 1e-9, 0.1)), len(t) - 1)
             if len(t) else [])
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
    if traj.scene.system.floor is not None:
        ax.axhline(0.0, color="0.4", lw=1.0)
        ax.axhspan(lo - 1.0, 0.0, color="0.88", zorder=0)
    ax.set_xlim(mid - half, mid + half)
    ax.set_ylim(lo, hi)
    ax.set_aspect("equal", adjustable="box")
    ax.locator_params(axis="x", nbins=4)    # a narrow panel: few x labels, none touching
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"in the plane, 0-{window:g} s\n(axis every 0.1 s, dark = later)", fontsize=8)


def momentum_panel(ax: Any, traj: Trajectory, window: float = WINDOW) -> Any:
    """L_cm, the angular momentum about the centre of mass (kg m^2/s, 2D), against time on
    ``ax``: flat in flight, a step at each impact; its legend entry is placed with the
    figure's others. Returns the axes."""
    traj, ax, window = _checked(traj, ax, window)
    if ax is None:
        raise UsageError("ax = None: must be a matplotlib Axes (the panel to draw on)",
                         param="ax")
    if traj.scene.system.dimensions != 2:
        raise UsageError(f"traj = {traj.scene.name}: L_cm needs a 2D scene (dimensions = 2)",
                         param="traj")
    m = _window(traj, window)
    L = traj["L_cm"][m]
    ax.plot(traj.t[m], L, color=MOMENTUM_COLOUR, lw=1.2, label="L_cm, about the\ncentre of mass")
    lo, hi = (float(np.nanmin(L)), float(np.nanmax(L))) if len(L) else (0.0, 0.0)
    pad = 0.1 * max(hi - lo, abs(hi), abs(lo), 1e-12)
    ax.set_ylim(lo - pad, hi + pad)
    ax.set_ylabel("L_cm [kg m²/s]")
    return ax


def energy(traj: Trajectory, ax: Any = None, window: float = WINDOW) -> Any:
    """How the energy is shared (J). On ``ax``: every energy term the scene has. Without:
    positions (and, in 2D, the motion in the plane), then two panels, the centre of mass's
    terms (K_cm, U_g) with E and E_lost, and the internal ones (K_int, or K_rot, K_vib,
    U_spring and K_spin), and in 2D a panel of L_cm (:func:`momentum_panel`).

    Parameters
    ----------
    traj, ax, window
        The run, the axes (None: the figure described above) and the span [0, window] (s),
        as for :func:`dumbbell.plot.positions`.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on, or the centre-of-mass panel of the new figure.

    Raises
    ------
    UsageError
        A bad ``traj``, ``ax`` or ``window`` (:func:`dumbbell.plot.positions` says which).

    Examples
    --------
    A tilted dumbbell in the plane, whose impacts set it spinning:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "tilted-2d.toml")
    >>> traj = dumbbell.simulate(scene, dt=1e-4, t_end=1.0)
    >>> ax = dumbbell.plot.energy(traj)              # positions, plane, energies, L_cm
    >>> ax.get_ylabel()
    'E [J]'
    """
    traj, ax, window = _checked(traj, ax, window)
    cols = traj.columns
    outer = [n for n in ("K_cm", "U_g", "E", "E_lost", "E_heat") if n in cols]
    inner = [n for n in ("K_int", "K_rot", "K_vib", "U_spring", "K_spin") if n in cols]
    if ax is not None:
        _energy_panel(ax, traj, outer + inner, window)
        _frame([ax], traj, window, own=False)
        return ax
    wide = traj.scene.system.dimensions == 2
    spin = wide and "L_cm" in cols and bool(inner)
    # Constrained layout (every figure's): the time panels stay aligned in one column
    # whatever their legends (outside, on the right) need; in 2D the motion in the plane sits
    # right of the legends.
    fig = _figure(figsize=(11.5 if wide else 10.0, 10.8 if spin else 8.8))
    rows = 4 if spin else 3
    grid = fig.add_gridspec(rows, 2 if wide else 1, width_ratios=[3.2, 1] if wide else None,
                            height_ratios=[1.15, 1, 1, 0.55][:rows])
    top = fig.add_subplot(grid[0, 0])
    _positions_panel(top, traj, window)
    if wide:
        _plane_panel(fig.add_subplot(grid[0:2, 1]), traj, window)
    middle = fig.add_subplot(grid[1, 0], sharex=top)
    bottom = fig.add_subplot(grid[2, 0], sharex=top)
    panels = [top, middle, bottom]
    _energy_panel(middle, traj, outer, window)
    middle.set_title("centre of mass: K_cm and U_g trade on each parabola; " + (
        "E + E_lost stays at E(0) (the floor takes energy out;\nE_heat is what the contacts "
        "dissipated)" if "E_lost" in cols else "E stays constant"), fontsize=9)
    if inner:
        _energy_panel(bottom, traj, inner, window)
        bottom.set_title("internal: the impacts feed the motion relative to the centre of mass",
                         fontsize=9)
    if spin:
        low = fig.add_subplot(grid[3, 0], sharex=top)
        momentum_panel(low, traj, window)
        low.set_title("angular momentum about the centre of mass: constant in flight, changed "
                      "only by impacts", fontsize=9)
        panels.append(low)
    for ax in panels[:-1]:
        ax.tick_params(labelbottom=False)
    _title(fig, panels, traj, window, "how the energy is shared")
    return middle
