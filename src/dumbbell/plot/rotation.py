"""The rotation preview's figure: K_rot(t) of spring dumbbells of growing stiffness beside the
rigid dumbbell. The runs come from :func:`dumbbell.analysis.rotation.series`; this module only
draws them."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..analysis.rotation import Series, mean_after_first_cluster
from .style import COLOURS, _subplots, finish, legend_inside, legend_outside, plain

__all__ = ["rotation"]

#: Colours of the spring runs in the overlay and the L_cm panel, softest to stiffest (the
#: rigid dumbbell's is black).
RUN_COLOURS = ("#9ecae1", "#4292c6", "#08519c", "#6baed6", "#2171b5")


def _colour(label: str, i: int) -> str:
    return "black" if label == "rigid" else RUN_COLOURS[i % len(RUN_COLOURS)]


def _overlay(ax: Any, s: Series) -> None:
    """Every run's K_rot on the user's axes, the rigid dumbbell's dashed; the legend inside
    them, above the data."""
    for i, (label, r) in enumerate(s.runs.items()):
        if label == "rigid":
            ax.plot(r.t, r["K_rot"], color="black", lw=1.0, ls="--",
                    label="K_rot of the rigid dumbbell")
        else:
            ax.plot(r.t, r["K_rot"], color=_colour(label, i), lw=0.9, label=f"K_rot, {label}")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("E [J]")
    ax.grid(True, color="0.9", lw=0.6)
    legend_inside(ax)


def _spring_panel(panel: Any, r: Any, rigid: Any, label: str, rigid_mean: float) -> str:
    """One spring dumbbell's panel; returns its note."""
    panel.fill_between(r.t, 0, r["K_vib"] + r["U_spring"], color=COLOURS["K_vib"], alpha=0.15,
                       lw=0, label="K_vib + U_spring,\nvibration")
    panel.plot(rigid.t, rigid["K_rot"], color="black", lw=1.0, ls="--",
               label="K_rot of the\nrigid dumbbell")
    panel.plot(r.t, r["K_rot"], color=COLOURS["K_rot"], lw=0.9, label="K_rot of this\nspring dumbbell")
    mean, a, b = mean_after_first_cluster(r, "K_rot")
    if math.isfinite(mean):
        panel.hlines(mean, a, b, colors=COLOURS["K_rot"], linestyles=(0, (1, 1)), lw=2.2,
                     label="its mean after the\nfirst impacts")
    return (f"{label}, w = {r.scene.system.omega:.0f} rad/s: mean K_rot after the first "
            f"impacts ({a:.2f}-{b:.2f} s) {mean:.2f} J, the rigid dumbbell's {rigid_mean:.2f} J")


def _rigid_panel(panel: Any, r: Any, rigid_mean: float) -> str:
    """The rigid dumbbell's panel; returns its note."""
    I = r.info.get("moment", r.scene.system.mu * r.scene.system.rigid.length**2)
    panel.plot(r.t, r["K_rot"], color="black", lw=1.2, label="K_rot = 1/2 mu |w x u|^2\n(partition)")
    half = slice(None, None, max(1, len(r.t) // 120))
    panel.plot(r.t[half], 0.5 * I * r.state["omega"][half] ** 2, "o", ms=3, mfc="none",
               color=COLOURS["K_rot"], label="1/2 I w^2, I = mu L^2\n(the body's spin)")
    panel.plot(r.t, r["K_cm"], color=COLOURS["K_cm"], lw=0.8, alpha=0.7, label="K_cm")
    return (f"rigid dumbbell (one body, I = {I:.3g} kg m^2): mean K_rot after its first "
            f"impact {rigid_mean:.2f} J")


def rotation(s: Series, ax: Any = None) -> Any:
    """K_rot(t) (J) of each run of a rotation preview (:func:`dumbbell.analysis.rotation.series`).

    On ``ax``: every spring dumbbell's K_rot over the rigid one's. Without: one panel per run,
    with the vibration energy and the mean K_rot after the first impacts, and a last panel
    with every run's L_cm on one scale (2D runs).

    Parameters
    ----------
    s : Series
        The runs of :func:`dumbbell.analysis.rotation.series`.
    ax : matplotlib.axes.Axes or None, default None
        Draw on these axes (the spring runs' K_rot over the rigid one's); None: a new figure.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on, or the top panel of the new figure.

    Raises
    ------
    UsageError
        An ``s`` that is not a Series of runs, or an ``ax`` that is not one Axes.

    Examples
    --------
    Two spring dumbbells and the rigid one, half a second each:

    >>> import dumbbell
    >>> from dumbbell.analysis.rotation import series
    >>> from dumbbell.model.scene import scenes_dir
    >>> runs = series(dumbbell.load_scene(scenes_dir() / "tilted-2d.toml"), dt=1e-4,
    ...               t_end=0.5, stiffnesses=(200.0, 2000.0))
    >>> ax = dumbbell.plot.rotation(runs)
    >>> ax.get_ylabel()
    'E [J]'
    """
    from ..model import args

    s = args.instance(s, "s", Series, "a Series (from dumbbell.analysis.rotation.series)")
    ax = args.axes(ax)
    labels = list(s.runs)
    rigid = s.runs["rigid"]
    if ax is not None:
        _overlay(ax, s)
        return ax
    momentum = all("L_cm" in r.columns for r in s.runs.values())
    rows = len(labels) + (1 if momentum else 0)
    fig, axes = _subplots(
        rows, 1, figsize=(10.5, 2.4 * len(labels) + (1.8 if momentum else 0) + 1.0),
        sharex=True, gridspec_kw={"height_ratios": [1] * len(labels) + ([0.8] if momentum
                                                                         else [])})
    rigid_mean = mean_after_first_cluster(rigid, "K_rot")[0]
    top = max(float(np.max(r["K_rot"])) for r in s.runs.values())
    top = max(top, max(float(np.max(r["K_vib"] + r.energy.get("U_spring", 0.0)))
                       for r in s.runs.values()))
    # The rigid panel draws K_cm too: over a short window (1 s) it peaks above every run's
    # internal energy, and a shared scale without it would cut the parabola's top off.
    top = max(top, float(np.max(rigid["K_cm"])))
    for panel, label in zip(axes, labels, strict=False):
        r = s.runs[label]
        note = (_rigid_panel(panel, r, rigid_mean) if label == "rigid"
                else _spring_panel(panel, r, rigid, label, rigid_mean))
        panel.set_title(note, loc="left", fontsize=8.5)
        panel.set_ylabel("E [J]")
        panel.set_ylim(0, top * 1.08)
        panel.grid(True, color="0.9", lw=0.6)
        legend_outside(panel, fontsize=7.5)
    if momentum:
        low = axes[-1]
        for i, (label, r) in enumerate(s.runs.items()):
            low.plot(r.t, r["L_cm"], color=_colour(label, i), lw=1.0,
                     ls="--" if label == "rigid" else "-", label=label)
        low.set_ylabel("L_cm [kg m²/s]")
        low.set_title("L_cm, the angular momentum about the centre of mass, of every run: "
                      "constant in flight, a step at each impact", loc="left", fontsize=8.5)
        low.grid(True, color="0.9", lw=0.6)
        legend_outside(low, fontsize=7.5)
    axes[-1].set_xlabel("t [s]")
    axes[-1].set_xlim(0, float(rigid.t[-1]))
    fig.suptitle(
        f"{plain(s.scene.title)}: rotation preview ({s.runs[labels[0]].solver}, dt = {s.dt:g} s)\n"
        "Between impacts a stiffer spring turns more like the rigid body; the floor's push on "
        "one particle leaves it far less rotation", fontsize=9.5)
    finish(fig)
    return axes[0]
