"""Verdicts shared by the solvers: how a run ended, and the likely cause in words.

A solver hands its raw samples and its own verdict (from its status) to :func:`conclude`, the
one path from a finished run to its frozen Trajectory: :func:`judge` settles the final verdict
and how many samples the run keeps (those up to the failure), without changing any array, and
the Trajectory is built once from them. The verdict's ``str`` is the line ``dumbbell
simulate`` prints:

- ``unstable``: the state stopped being finite or the energy grew past ``run.unstable_energy``
  ("unstable at t = 0.031 s: w*dt = 2.10 > 2 (w = sqrt(k/mu) = 1000 rad/s); use dt < 2e-3 s");
- ``tunnelled``: a particle went through the floor (:func:`tunnel_reason`);
- ``failed``: anything else, with the reason.

The theory behind the messages (explicit spring steps are stable iff w*dt < 2, with
w = sqrt(k/mu)) is in docs/physics.md.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from ..model.energy import partition, relative_energy_error
from ..model.scene import Scene
from ..model.trajectory import Impact, Trajectory, Verdict
from .kernels import BIG

#: Nothing public: the machinery the solver classes share.
__all__: list[str] = []

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
    scene: Scene, t: float, body: str, height: float, speed: float, dt: float,
    push: float = 0.0, depth: float | None = None, E: Sequence[float] | None = None,
) -> Verdict:
    """The verdict for ``body`` found ``height`` (m, < 0) below the floor at time ``t`` (s),
    moving down at ``speed`` (m/s) although the floor should have turned it back. ``push`` is
    the spring's downward acceleration on it (m/s^2), ``depth`` as in :func:`tunnel_reason`,
    ``E`` the total energy (J) at the run's first and last samples, if known.

    Moving down no faster than a few steps of gravity plus the spring's push give, it is held
    on the floor (at rest, or pressed by the other particle), which a velocity-flip rule
    cannot do: ``failed``, saying how much energy was left. Otherwise it went through:
    ``tunnelled``."""
    pressed = max(push, 0.0)
    if abs(speed) <= 3.0 * (scene.system.g + pressed) * dt:
        how = (f"pressed onto it by the spring at {pressed:.3g} m/s^2" if pressed > scene.system.g
               else "at rest on it")
        reason = (f"{body} stays on the floor, {how} ({abs(height):.2g} m below it, moving at "
                  f"{abs(speed):.2g} m/s): a velocity-flip floor cannot hold a particle in "
                  "lasting contact")
        floor = scene.system.floor
        if E is not None and len(E) and floor is not None and floor.elasticity >= 1.0:
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


#: A truth solver's samples may lie at most this far below the floor (m): more means it
#: missed an impact, and its run must not end ``ok``.
FLOOR_TOLERANCE = 1e-9


def missed_impact(
    scene: Scene, solver: str, t: np.ndarray, state: Mapping[str, np.ndarray],
) -> tuple[Verdict, int] | None:
    """For a truth solver (exact, reference) with samples at ``t`` (s) of ``state``: if a
    particle is more than FLOOR_TOLERANCE below the floor at some sample, ``failed`` at the
    first such sample and the number of samples up to it (the truth missed an impact); else
    None."""
    if scene.system.floor is None or not len(t):
        return None
    key = "x" if scene.system.dimensions == 1 else "y"
    heights = np.vstack([state[f"{key}{body}"] for body in "AB"])
    bad = np.flatnonzero(np.min(heights, axis=0) < -FLOOR_TOLERANCE)
    if not bad.size:
        return None
    j = int(bad[0])
    body = "AB"[int(np.argmin(heights[:, j]))]
    depth = float(-heights[:, j].min())
    return Verdict("failed", float(t[j]),
                   f"{body} is {depth:.3g} m below the floor (more than {FLOOR_TOLERANCE:g} m): "
                   f"{solver} missed an impact, so this run is not a truth"), j + 1


def energy_verdict(
    scene: Scene, t: np.ndarray, energy: Mapping[str, np.ndarray], dt: float | None,
) -> tuple[Verdict, int]:
    """``unstable`` if the relative energy error of the energy columns ``energy`` (J, at the
    sample times ``t`` in s) passes the scene's ``run.unstable_energy``, else ``ok``; and how
    many samples to keep (up to the first bad one; all when ok). ``dt`` is the step (s; None
    for a truth solver, whose dt only sets the sample times).

    Dissipative scenes lose energy by design; only a gain past the threshold counts there."""
    if len(t) == 0:
        return Verdict(), 0
    err = relative_energy_error(energy)
    if scene.system.dissipative:
        E = energy["E"]
        err = np.where(E > E[0], err, 0.0)
    bad = np.flatnonzero(~(err <= scene.run.unstable_energy))
    if bad.size == 0:
        return Verdict(), len(t)
    j = int(bad[0])
    t_fail = float(t[j])
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
    return Verdict("unstable", t_fail, reason), j + 1


def finite_samples(state: Mapping[str, np.ndarray]) -> int:
    """How many samples come before the first whose state is non-finite or beyond :data:`BIG`."""
    columns = list(state.values())
    if not columns:
        return 0
    good = np.ones(len(columns[0]), dtype=bool)
    for col in columns:
        good &= np.abs(col) < BIG
    return int(np.argmin(good)) if not good.all() else len(good)


def head(columns: Mapping[str, np.ndarray], count: int) -> dict[str, np.ndarray]:
    """The first ``count`` samples of every column (views, not copies)."""
    return {name: col[:count] for name, col in columns.items()}


def judge(
    scene: Scene, solver: str, t: np.ndarray, state: Mapping[str, np.ndarray],
    events: Iterable[Impact], verdict: Verdict, dt: float | None,
    energy: Mapping[str, np.ndarray] | None = None, truth: bool = False,
) -> tuple[Verdict, int, dict[str, np.ndarray]]:
    """The one mapping from how a run ended to its verdict. ``verdict`` is the solver's own
    (from its status), ``t`` (s), ``state`` and ``events`` its raw samples and impacts,
    ``energy`` its energy columns (J) if it counted them itself, ``dt`` its step (s).

    - a truth solver (``truth``) whose samples pass below the floor: ``failed`` there
      (:func:`missed_impact`);
    - ``unstable`` (the state blew up): the samples before the explosion, then the energy
      verdict if it finds the failure earlier, else the solver's;
    - ``tunnelled``, ``failed``: the solver's, all samples kept;
    - ``ok``: :func:`energy_verdict` (a truth solver's with no step).

    Returns the verdict, how many samples the run keeps, and the energy columns of those
    samples (from :func:`dumbbell.model.energy.partition` unless given). Changes nothing."""
    keep = len(t)
    if truth:
        missed = missed_impact(scene, solver, t, state)
        if missed is not None:
            verdict, keep = missed
        dt = None
    elif verdict.status == "unstable":
        # The explosion's samples (up to 1e300 J) would swamp every plot and bar scale.
        keep = finite_samples(state)
    t, state = t[:keep], head(state, keep)
    energy = (partition(scene, t, state, events) if energy is None
              else head(energy, keep))
    if verdict.ok or verdict.status == "unstable":
        judged, keep = energy_verdict(scene, t, energy, dt)
        if not (judged.ok and verdict.status == "unstable"):
            verdict = judged
    return verdict, keep, head(energy, keep)


def conclude(
    scene: Scene, solver: str, t: np.ndarray, state: Mapping[str, np.ndarray],
    events: Iterable[Impact], verdict: Verdict, *, dt: float | None, every: int = 1,
    wall_time: float = 0.0, info: Mapping[str, Any] | None = None,
    energy: Mapping[str, np.ndarray] | None = None, truth: bool = False,
) -> Trajectory:
    """The finished run as its one frozen Trajectory: :func:`judge` decides the verdict and
    where the run ends, then the Trajectory is built from the samples kept, and the impacts up
    to the last of them. Arguments as for
    :func:`judge`; ``every``, ``wall_time`` (s) and ``info`` go to the Trajectory as they are."""
    events = tuple(events)
    verdict, keep, energy = judge(scene, solver, t, state, events, verdict, dt, energy, truth)
    if keep < len(t):
        # The verdict cut the run: impacts after its last sample belong to the part cut off
        # (an energy blow-up may bounce on for a while before the solver's end).
        end = float(t[keep - 1]) if keep else -math.inf
        events = tuple(e for e in events if e.t <= end)
    return Trajectory(scene=scene, solver=solver, t=t[:keep], state=head(state, keep),
                      events=events, verdict=verdict, dt=dt, every=every, wall_time=wall_time,
                      info=dict(info or {}), energy=energy)
