"""Verdicts shared by the solvers: how a run ended, and the likely cause in words."""

from __future__ import annotations

import numpy as np

from ..energy import relative_energy_error
from ..scene import Scene
from ..trajectory import Trajectory, Verdict


def stability_limit(scene: Scene) -> float | None:
    """The largest stable step of the explicit spring, 2/w (s); None without a spring force."""
    w = scene.omega
    return 2.0 / w if w > 0 else None


def nonfinite_reason(scene: Scene, dt: float) -> str:
    """Why a state most likely blew up at step ``dt`` (s), with the fix when it is the step."""
    w = scene.omega
    if w > 0 and w * dt >= 2.0:
        return (f"w*dt = {w * dt:.2f} > 2 (w = sqrt(k/mu) = {w:.4g} rad/s); "
                f"use dt < {2.0 / w:.3g} s")
    if w > 0:
        return f"the state grew without bound although w*dt = {w * dt:.2f} < 2"
    return "the state grew without bound"


def energy_verdict(traj: Trajectory, dt: float | None) -> Verdict:
    """``unstable`` if the relative energy error passes the scene's ``run.unstable_energy``
    (the trajectory is then cut after the first such sample), else ``ok``.

    Dissipative scenes lose energy by design; only a gain past the threshold counts there."""
    scene = traj.scene
    if len(traj.t) == 0:
        return Verdict()
    err = relative_energy_error(traj)
    if scene.dissipative:
        E = traj["E"]
        err = np.where(E > E[0], err, 0.0)
    bad = np.flatnonzero(~(err <= scene.run.unstable_energy))
    if bad.size == 0:
        return Verdict()
    j = int(bad[0])
    t_fail = float(traj.t[j])
    if dt is not None and scene.omega * dt >= 2.0:
        reason = nonfinite_reason(scene, dt)
    else:
        reason = (f"energy error {float(err[j]):.3g} passed run.unstable_energy = "
                  f"{scene.run.unstable_energy:g}")
    traj.t = traj.t[: j + 1]
    traj.state = {name: col[: j + 1] for name, col in traj.state.items()}
    traj._energy = None
    return Verdict("unstable", t_fail, reason)
