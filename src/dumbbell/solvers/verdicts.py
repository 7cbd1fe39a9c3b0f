"""Verdicts shared by the solvers: how a run ended, and the likely cause in words.

A solver that stops early keeps its samples up to the failure (:func:`keep_samples`) and sets
``traj.verdict`` to one of these, whose ``str`` is the line ``dumbbell simulate`` prints:

- ``unstable``: the state stopped being finite or the energy grew past ``run.unstable_energy``
  ("unstable at t = 0.031 s: w*dt = 2.10 > 2 (w = sqrt(k/mu) = 1000 rad/s); use dt < 2e-3 s");
- ``tunnelled``: a particle went through the floor (:func:`tunnel_reason`);
- ``failed``: anything else, with the reason.

The theory behind the messages (explicit spring steps are stable iff w*dt < 2, with
w = sqrt(k/mu)) is in docs/physics.md.
"""

from __future__ import annotations

import math

import numpy as np

from ..model.energy import relative_energy_error
from ..model.scene import Scene
from ..model.trajectory import Trajectory, Verdict

#: The explicit spring step (Euler-Cromer, Verlet, pymunk) is stable iff w*dt < this.
STEP_LIMIT = 2.0


def stability_limit(scene: Scene) -> float | None:
    """The largest stable step of the explicit spring, 2/w (s); None without a spring force."""
    w = scene.system.omega
    return STEP_LIMIT / w if w > 0 else None


def step_ratio(scene: Scene, dt: float | None) -> float:
    """w*dt (dimensionless) for step ``dt`` (s); 0 without a spring or without a step."""
    return scene.system.omega * dt if dt else 0.0


def seconds(value: float) -> str:
    """A time as people write it: '0.031', '3.16e-3' (s, without the unit)."""
    if value == 0 or 1e-2 <= abs(value) < 1e4:
        return f"{value:.3g}"
    mantissa, exponent = f"{value:.2e}".split("e")
    mantissa = mantissa.rstrip("0").rstrip(".")
    return f"{mantissa}e{int(exponent)}"


def ratio_text(ratio: float) -> str:
    """w*dt for a message: two decimals, more near the limit so that 1.999 is not '2.00'."""
    if abs(ratio - STEP_LIMIT) < 0.005:
        return f"{ratio:.5f}"
    return f"{ratio:.2f}" if ratio >= 0.1 else f"{ratio:.2g}"


def stable_swing(ratio: float) -> float:
    """Largest relative swing of a *stable* explicit oscillator's energy at w*dt = ``ratio``:
    h/(2 - h) of its vibration energy (a 19-fold swing at 1.9); inf at and past the limit."""
    return ratio / (STEP_LIMIT - ratio) if ratio < STEP_LIMIT else math.inf


def nonfinite_reason(scene: Scene, dt: float) -> str:
    """Why a state most likely blew up at step ``dt`` (s), with the fix when it is the step."""
    w = scene.system.omega
    limit = stability_limit(scene)
    if limit is not None and w * dt >= STEP_LIMIT:
        return (f"w*dt = {ratio_text(w * dt)} > 2 (w = sqrt(k/mu) = {w:.4g} rad/s); "
                f"use dt < {seconds(limit)} s")
    if limit is not None:
        return (f"the state grew without bound although w*dt = {ratio_text(w * dt)} < 2 "
                f"(w = {w:.4g} rad/s)")
    return "the state grew without bound"


def tunnel_reason(
    scene: Scene, body: str, height: float, speed: float, dt: float | None,
    depth: float | None = None,
) -> str:
    """Why ``body`` went through the floor: it is ``height`` (m, < 0) below it moving down at
    ``speed`` (m/s). ``depth`` (m) is how far past the floor a contact can still be caught in
    one step (2r for a circle on a thin floor); with it, the message gives the step to use."""
    text = f"{body} is {abs(height):.3g} m below the floor, still moving down at {abs(speed):.3g} m/s"
    if dt is None:
        return text
    travel = abs(speed) * dt
    if depth is not None and depth > 0:
        text += (f": it moves {travel:.3g} m per step, more than the {depth:.3g} m in which "
                 f"a contact is caught; use dt < {seconds(depth / abs(speed))} s or a larger "
                 "radius")
    else:
        text += f" ({travel:.3g} m per step): the velocity flip came too late to stop it"
    return text


def below_floor_verdict(
    traj: Trajectory, t: float, body: str, height: float, speed: float, dt: float,
    push: float = 0.0, depth: float | None = None,
) -> Verdict:
    """The verdict for ``body`` found ``height`` (m, < 0) below the floor at time ``t`` (s),
    moving down at ``speed`` (m/s) although the floor should have turned it back. ``push`` is
    the spring's downward acceleration on it (m/s^2), ``depth`` as in :func:`tunnel_reason`.

    Moving down no faster than a few steps of gravity plus the spring's push give, it is held
    on the floor (at rest, or pressed by the other particle), which a velocity-flip rule
    cannot do: ``failed``, saying how much energy was left. Otherwise it went through:
    ``tunnelled``."""
    scene = traj.scene
    pressed = max(push, 0.0)
    if abs(speed) <= 3.0 * (scene.system.g + pressed) * dt:
        how = (f"pressed onto it by the spring at {pressed:.3g} m/s^2" if pressed > scene.system.g
               else "at rest on it")
        reason = (f"{body} stays on the floor, {how} ({abs(height):.2g} m below it, moving at "
                  f"{abs(speed):.2g} m/s): a velocity-flip floor cannot hold a particle in "
                  "lasting contact")
        if len(traj.t) and scene.system.floor is not None and scene.system.floor.elasticity >= 1.0:
            E = traj["E"]
            left = float(E[-1] / E[0]) if E[0] else math.nan
            if left < 0.5:
                reason += (f"; the floor is elastic, so the step's impact errors drained the "
                           f"energy to {left:.0%} of its start: use a smaller dt")
        return Verdict("failed", t, reason)
    reason = tunnel_reason(scene, body, height, speed, dt, depth)
    if push > scene.system.g:
        reason += (f"; the spring pushed it back down (at {push:.3g} m/s^2) before it climbed "
                   f"out, with w*dt = {ratio_text(step_ratio(scene, dt))}: use a smaller dt")
    return Verdict("tunnelled", t, reason)


def keep_samples(traj: Trajectory, count: int) -> None:
    """Keep only the first ``count`` samples of ``traj`` (the ones before a failure)."""
    count = max(0, min(count, len(traj.t)))
    traj.t = traj.t[:count]
    traj.state = {name: col[:count] for name, col in traj.state.items()}
    traj._energy = None
    traj._momentum = None


#: A truth solver's samples may lie at most this far below the floor (m): more means it
#: missed an impact, and its run must not end ``ok``.
FLOOR_TOLERANCE = 1e-9


def truth_verdict(traj: Trajectory, verdict: Verdict) -> Verdict:
    """The verdict of a truth solver (exact, reference) that ended with ``verdict``: if any
    sample has a particle more than FLOOR_TOLERANCE below the floor, ``failed`` at the first
    such sample (the trajectory is cut after it: the truth missed an impact); else the
    solver's own verdict, or when that is ok :func:`energy_verdict`."""
    scene = traj.scene
    if scene.system.floor is not None and len(traj.t):
        key = "x" if scene.system.dimensions == 1 else "y"
        heights = np.vstack([traj.state[f"{key}{body}"] for body in "AB"])
        bad = np.flatnonzero(np.min(heights, axis=0) < -FLOOR_TOLERANCE)
        if bad.size:
            j = int(bad[0])
            body = "AB"[int(np.argmin(heights[:, j]))]
            depth = float(-heights[:, j].min())
            t_fail = float(traj.t[j])
            keep_samples(traj, j + 1)
            return Verdict("failed", t_fail,
                           f"{body} is {depth:.3g} m below the floor (more than "
                           f"{FLOOR_TOLERANCE:g} m): {traj.solver} missed an impact, so this "
                           "run is not a truth")
    return verdict if not verdict.ok else energy_verdict(traj, None)


def energy_verdict(traj: Trajectory, dt: float | None) -> Verdict:
    """``unstable`` if the relative energy error passes the scene's ``run.unstable_energy``
    (the trajectory is then cut after the first such sample), else ``ok``. ``dt`` is the step
    (s; None for the exact solution).

    Dissipative scenes lose energy by design; only a gain past the threshold counts there."""
    scene = traj.scene
    if len(traj.t) == 0:
        return Verdict()
    err = relative_energy_error(traj)
    if scene.system.dissipative:
        E = traj["E"]
        err = np.where(E > E[0], err, 0.0)
    bad = np.flatnonzero(~(err <= scene.run.unstable_energy))
    if bad.size == 0:
        return Verdict()
    j = int(bad[0])
    t_fail = float(traj.t[j])
    ratio = step_ratio(scene, dt)
    if ratio >= STEP_LIMIT:
        reason = nonfinite_reason(scene, dt)  # type: ignore[arg-type]
    else:
        reason = (f"energy error {float(err[j]):.3g} passed run.unstable_energy = "
                  f"{scene.run.unstable_energy:g}")
        if ratio > 1.0:
            # Near the limit a stable explicit step swings the energy a lot without growing.
            reason += (f"; w*dt = {ratio_text(ratio)} < 2, where even a stable step swings the "
                       f"vibration energy by up to {stable_swing(ratio):.3g} times itself: "
                       "raise run.unstable_energy if that swing is expected, or lower dt")
    keep_samples(traj, j + 1)
    return Verdict("unstable", t_fail, reason)
