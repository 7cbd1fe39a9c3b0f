"""The rotation preview's figure: K_rot(t) of spring dumbbells of growing stiffness beside the
rigid dumbbell. The runs come from :func:`dumbbell.analysis.rotation.series`; this module only
draws them."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..analysis.rotation import Series, mean_after_first_cluster
from .style import COLOURS, pyplot
from .trajectory import momentum_axis

__all__ = ["rotation"]


def _overlay(ax: Any, s: Series) -> None:
    """Every run's K_rot on one axes, the rigid dumbbell's dashed."""
    for i, (label, r) in enumerate(s.runs.items()):
        if label == "rigid":
            ax.plot(r.t, r["K_rot"], color="black", lw=1.0, ls="--",
                    label="K_rot of the rigid dumbbell")
        else:
            ax.plot(r.t, r["K_rot"], color=f"C{i % 10}", lw=0.9, label=f"K_rot, {label}")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("E [J]")
    ax.grid(True, color="0.9", lw=0.6)
    ax.legend(loc="upper right", fontsize=7.5, framealpha=0.9)


def rotation(s: Series, ax: Any = None) -> Any:
    """K_rot(t) (J) of each run of a rotation preview (:func:`dumbbell.analysis.rotation.series`).

    On ``ax``: every spring dumbbell's K_rot over the rigid one's. Without: one panel per run,
    with the vibration energy and the mean K_rot after the first impacts; returns the top
    panel."""
    from ..model import args

    s = args.instance(s, "s", Series, "a Series (from dumbbell.analysis.rotation.series)")
    ax = args.axes(ax)
    labels = list(s.runs)
    rigid = s.runs["rigid"]
    if ax is not None:
        _overlay(ax, s)
        return ax
    fig, axes = pyplot().subplots(len(labels), 1, figsize=(10, 2.8 * len(labels) + 1.2),
                                  sharex=True, sharey=True)
    rigid_mean = mean_after_first_cluster(rigid, "K_rot")[0]
    top = max(float(np.max(r["K_rot"])) for r in s.runs.values())
    top = max(top, max(float(np.max(r["K_vib"] + r.energy.get("U_spring", 0.0)))
                       for r in s.runs.values()))
    for panel, label in zip(axes, labels, strict=True):
        r = s.runs[label]
        if label != "rigid":
            e_vib = r["K_vib"] + r["U_spring"]
            panel.fill_between(r.t, 0, e_vib, color=COLOURS["K_vib"], alpha=0.15, lw=0,
                            label="K_vib + U_spring, vibration")
            panel.plot(rigid.t, rigid["K_rot"], color="black", lw=1.0, ls="--",
                    label="K_rot of the rigid dumbbell")
            panel.plot(r.t, r["K_rot"], color=COLOURS["K_rot"], lw=0.9,
                    label=f"K_rot, spring dumbbell, {label}")
            mean, a, b = mean_after_first_cluster(r, "K_rot")
            if math.isfinite(mean):
                panel.hlines(mean, a, b, colors=COLOURS["K_rot"], linestyles=(0, (1, 1)), lw=2.2,
                          label="its mean after the first impacts")
            note = (f"{label}: w = {r.scene.system.omega:.0f} rad/s\n"
                    f"mean K_rot after the first impacts ({a:.2f}-{b:.2f} s): {mean:.2f} J\n"
                    f"(rigid dumbbell after its 1st impact: {rigid_mean:.2f} J)")
        else:
            I = rigid.info.get("moment", r.scene.system.mu * r.scene.system.rigid.length**2)
            panel.plot(r.t, r["K_rot"], color="black", lw=1.2,
                    label="K_rot = 1/2 mu |w x u|^2 (partition)")
            half = slice(None, None, max(1, len(r.t) // 120))
            panel.plot(r.t[half], 0.5 * I * r.state["omega"][half] ** 2, "o", ms=3, mfc="none",
                    color=COLOURS["K_rot"], label="1/2 I w^2, I = mu L^2 (body's spin)")
            panel.plot(r.t, r["K_cm"], color=COLOURS["K_cm"], lw=0.8, alpha=0.7, label="K_cm")
            note = (f"rigid dumbbell (one body): I = {I:.3g} kg m^2\n"
                    f"mean K_rot after its 1st impact: {rigid_mean:.2f} J")
        panel.text(0.01, 0.95, note, transform=panel.transAxes, va="top", fontsize=8,
                bbox={"boxstyle": "round", "fc": "white", "ec": "0.7", "alpha": 0.9})
        panel.set_ylabel("E [J]")
        panel.set_ylim(0, top * 1.7)
        panel.grid(True, color="0.9", lw=0.6)
        panel.legend(loc="upper right", fontsize=7.5, framealpha=0.9)
        if "L_cm" in r.columns:
            momentum_axis(panel, r, float(r.t[-1]), loc="upper right", ncol=1)
    axes[-1].set_xlabel("t [s]")
    axes[-1].set_xlim(0, float(rigid.t[-1]))
    fig.suptitle(
        f"{s.scene.title}: rotation preview ({s.runs[labels[0]].solver}, dt = {s.dt:g} s)\n"
        "Between impacts a stiffer spring dumbbell turns more like a rigid body (flatter "
        "K_rot), but the floor pushes\nONE particle at a time, quicker than any spring: the "
        "first impacts leave far less rotation than the rigid body gets,\nand stiffer springs "
        "do not approach it: what the second particle's landing leaves depends on the "
        "vibration's phase",
        fontsize=9.5)
    fig.tight_layout()
    return axes[0]
