"""Verdicts shared by the solvers: how a run ended, and the likely cause in words.

A solver hands its raw samples and its own verdict (from its status), as a :class:`RawRun`, to
:func:`conclude`, the one path from a finished run to its frozen Trajectory: :func:`judge`
settles the final verdict and how many samples the run keeps (those up to the failure),
without changing any array, and the Trajectory is built once from them. A verdict is dated at
the step where it happens, whatever the sampling: a stepping solver can replay its steps
between the samples (``RawRun.replay``), and the energy is then judged step by step. The verdict's ``str`` is the line ``dumbbell
simulate`` prints:

- ``inaccurate``: the run stayed stable to its end, but its energy error passed
  ``run.inaccurate_energy`` (dated at the step where it first did; every sample kept);
- ``unstable``: the state stopped being finite or the energy grew past ``run.unstable_energy``
  ("unstable at t = 0.031 s: w*dt = 2.10 > 2 (w = sqrt(k/mu) = 1000 rad/s): stable only for
  dt < 2e-3 s; try dt = 4e-5 s (...)");
- ``tunnelled``: a particle went through the floor (:func:`tunnel_reason`);
- ``failed``: anything else, with the reason.

Every message but ``ok``'s ends with what to change: where the step is the cause, a value
(:mod:`.advice` computes it).

The theory behind the messages (a solver's spring step is stable iff w*dt is below its
``step_limit``, 2 for an explicit step, with w = sqrt(k/mu)) is in docs/physics.md.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model.energy import _partition, _start_scale
from ..model.scene import Scene
from ..model.trajectory import Impact, Trajectory, Verdict
from . import advice
from .advice import seconds
from .kernels import BIG

if TYPE_CHECKING:
    from .base import RunOptions, Solver

#: Nothing public: the machinery the solver classes share.
__all__: list[str] = []


def step_ratio(scene: Scene, dt: float | None) -> float:
    """w*dt (dimensionless) for step ``dt`` (s); 0 without a spring or without a step."""
    return scene.system.omega * dt if dt else 0.0


def ratio_text(ratio: float, limit: float) -> str:
    """w*dt for a message: two decimals, more near the step ``limit`` so that 1.999 is not
    '2.00'."""
    if abs(ratio - limit) < 0.005:
        return f"{ratio:.5f}"
    return f"{ratio:.2f}" if ratio >= 0.1 else f"{ratio:.2g}"


def nonfinite_reason(scene: Scene, dt: float, limit: float | None) -> str:
    """Why a state most likely blew up at step ``dt`` (s) of a solver whose spring step is
    stable below w*dt = ``limit`` (None: no such limit), with the fix when it is the step."""
    w = scene.system.omega
    if limit is None or not w > 0:
        return "the state grew without bound"
    if w * dt >= limit:
        return (f"w*dt = {ratio_text(w * dt, limit)} > {limit:.3g} (w = sqrt(k/mu) = {w:.4g} "
                f"rad/s): the step is stable only for dt < {seconds(limit / w)} s")
    return (f"the state grew without bound although w*dt = {ratio_text(w * dt, limit)} < "
            f"{limit:.3g} (w = {w:.4g} rad/s)")


@dataclass(frozen=True)
class Sinking:
    """A particle found below the floor although the floor should have turned it back:
    ``body`` ('A' or 'B'), ``height`` (m, < 0), ``speed`` its vertical velocity (m/s, < 0),
    ``push`` the spring's downward acceleration on it (m/s^2), ``depth`` how far past the
    floor a contact can still be caught (m; None: a flip at the first step below it)."""

    body: str
    height: float
    speed: float
    push: float = 0.0
    depth: float | None = None


def tunnel_reason(scene: Scene, sinking: Sinking, dt: float | None) -> str:
    """Why a particle went through the floor (``sinking``: where it is, how fast it moves,
    and how far past the floor a contact can still be caught in one step, 2r for a circle on
    a thin floor; with that depth the message gives the step to use) at step ``dt`` (s)."""
    speed, depth = abs(sinking.speed), sinking.depth
    text = (f"{sinking.body} is {abs(sinking.height):.3g} m below the floor, still moving "
            f"down at {speed:.3g} m/s")
    if dt is None:
        return text
    travel = speed * dt
    if depth is not None and depth > 0 and travel > depth:
        text += (f": it moves {travel:.3g} m per step, more than the {depth:.3g} m in which "
                 f"a contact is caught (at dt < {seconds(depth / speed)} s, or with a larger "
                 "radius, it would be)")
    elif depth is not None and depth > 0:
        text += f", past the {depth:.3g} m in which a contact is caught"
    else:
        text += f" ({travel:.3g} m per step): the velocity flip came too late to stop it"
    return text


#: What every verdict of a particle come to rest on an inelastic floor says (:func:`rest_reason`);
#: :func:`judge` then adds what to change.
RESTED = "came to rest on the floor"
#: What the verdict of a run stopped by its budget of impacts or work says; :func:`judge` then
#: adds the end time to use.
SHORTER = "a shorter t_end fits"


def rest_reason(body: str, v: float) -> str:
    """Why a run ends where ``body`` meets an inelastic floor at a speed ``v`` (m/s) too small
    to go on: the bounces ahead are infinitely many and come in a finite time."""
    return (f"{body} {RESTED} (impact speed {abs(v):.1e} m/s): an inelastic floor has "
            "infinitely many impacts in finite time here")


def below_floor_verdict(scene: Scene, t: float, dt: float, sinking: Sinking,
                        E: Sequence[float] | None = None) -> Verdict:
    """The verdict for a particle ``sinking`` at time ``t`` (s) of a run at step ``dt`` (s);
    ``E`` the total energy (J) at the run's first and last samples, if known.

    Moving down no faster than a few steps of gravity plus the spring's push give, it is held
    on the floor (at rest, or pressed by the other particle), which a velocity-flip rule
    cannot do: ``failed``, saying how much energy was left. Otherwise it went through:
    ``tunnelled``."""
    body, height, speed, push = sinking.body, sinking.height, sinking.speed, sinking.push
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
                           f"energy to {left:.0%} of its start")
        return Verdict("failed", t, reason)
    reason = tunnel_reason(scene, sinking, dt)
    if push > scene.system.g:
        reason += (f"; the spring pushed it back down (at {push:.3g} m/s^2) before it climbed "
                   f"out, with w*dt = {step_ratio(scene, dt):.2f}")
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
    a, b = state[f"{key}A"], state[f"{key}B"]
    if a.min() >= -FLOOR_TOLERANCE and b.min() >= -FLOOR_TOLERANCE:
        return None  # the usual case, told without a temporary array (NaN goes on below)
    heights = np.vstack([a, b])
    bad = np.flatnonzero(np.min(heights, axis=0) < -FLOOR_TOLERANCE)
    if not bad.size:
        return None
    j = int(bad[0])
    body = "AB"[int(np.argmin(heights[:, j]))]
    depth = float(-heights[:, j].min())
    return Verdict("failed", float(t[j]),
                   f"{body} is {depth:.3g} m below the floor (more than {FLOOR_TOLERANCE:g} m): "
                   f"{solver} missed an impact, so this run is not a truth"), j + 1


def _energy_errors(scene: Scene, E: np.ndarray, E0: float, scale: float) -> np.ndarray:
    """|E - E0| / scale at every sample (dimensionless); on a dissipative scene, which loses
    energy by design, only a gain counts."""
    err = np.subtract(E, E0)  # |E - E0| / scale, in one array
    np.abs(err, out=err)
    with np.errstate(over="ignore"):  # a blown-up state's 1e300 J over a small scale: inf
        err /= scale
    return np.where(E > E0, err, 0.0) if scene.system.dissipative else err


def _unstable(cls: type[Solver], scene: Scene, t: float, err: float, dt: float | None
              ) -> Verdict:
    """``unstable`` at ``t`` (s), where the relative energy error ``err`` passed the scene's
    ``run.unstable_energy`` in a run of the solver ``cls`` at step ``dt`` (s; None: none)."""
    ratio, limit = step_ratio(scene, dt), cls.step_limit
    if limit is not None and ratio >= limit:
        return Verdict("unstable", t, nonfinite_reason(scene, dt, limit))  # type: ignore[arg-type]
    reason = (f"energy error {err:.3g} passed run.unstable_energy = "
              f"{scene.run.unstable_energy:g}")
    swing = cls.swing(ratio) if limit is not None and ratio > 1.0 else None
    if swing is not None:
        # Near the limit a stable step may swing the energy a lot without growing.
        reason += (f"; w*dt = {ratio_text(ratio, limit)} < {limit:.3g}, where even a stable "  # type: ignore[arg-type]
                   f"step swings the vibration energy by up to {swing:.3g} times itself: "
                   "raise run.unstable_energy if that swing is expected, or lower dt")
    return Verdict("unstable", t, reason)


def _accuracy_errors(scene: Scene, energy: Mapping[str, np.ndarray], E0: float, scale: float
                     ) -> np.ndarray:
    """The method's own relative energy error at every sample of the energy columns
    ``energy`` (J): |E - E0| / scale, or on a dissipative scene, whose floor takes energy by
    design, what the heat counted does not explain, |E0 - E - E_heat| / scale."""
    E = energy["E"]
    if scene.system.dissipative and "E_heat" in energy:
        err = np.subtract(E0, E)
        err -= energy["E_heat"]
    else:
        err = np.subtract(E, E0)
    np.abs(err, out=err)
    with np.errstate(over="ignore"):
        err /= scale
    return err


def _inaccurate(scene: Scene, t: float, err: float, worst: tuple[float, float]) -> Verdict:
    """``inaccurate`` at ``t`` (s), where the energy error ``err`` passed the scene's
    ``run.inaccurate_energy``; ``worst`` the largest error and its time (s)."""
    top, when = worst
    return Verdict("inaccurate", t, (
        f"energy error {err:.3g} passed run.inaccurate_energy = "
        f"{scene.run.inaccurate_energy:g} and reached {top:.3g} at t = {when:.4g} s; the run "
        "stayed stable to its end"))


def accuracy_verdict(scene: Scene, t: np.ndarray, energy: Mapping[str, np.ndarray]
                     ) -> tuple[Verdict, tuple[float, float]]:
    """For a run that stayed stable (every sample kept): ``inaccurate`` at the first sample
    whose energy error (:func:`_accuracy_errors`, at the sample times ``t`` in s) passes the
    scene's ``run.inaccurate_energy``, else ``ok``; and the largest error (dimensionless)
    with its time (s)."""
    if len(t) == 0:
        return Verdict(), (0.0, 0.0)
    err = _accuracy_errors(scene, energy, float(energy["E"][0]),
                           _start_scale(energy, scene.system))
    i = int(np.argmax(err))
    worst = (float(err[i]), float(t[i]))
    if not err[i] > scene.run.inaccurate_energy:
        return Verdict(), worst
    j = int(np.flatnonzero(err > scene.run.inaccurate_energy)[0])
    return _inaccurate(scene, float(t[j]), float(err[j]), worst), worst


def energy_verdict(
    cls: type[Solver], scene: Scene, t: np.ndarray, energy: Mapping[str, np.ndarray],
    dt: float | None,
) -> tuple[Verdict, int]:
    """``unstable`` if the relative energy error of the energy columns ``energy`` (J, at the
    sample times ``t`` in s) of a run of ``cls`` passes the scene's ``run.unstable_energy``,
    else ``ok``; and how many samples to keep (up to the first bad one; all when ok). ``dt`` is
    the step (s; None for a truth solver, whose dt only sets the sample times)."""
    if len(t) == 0:
        return Verdict(), 0
    err = _energy_errors(scene, energy["E"], float(energy["E"][0]),
                         _start_scale(energy, scene.system))
    if err.max() <= scene.run.unstable_energy:  # every error within (a NaN fails this)
        return Verdict(), len(t)
    bad = np.flatnonzero(~(err <= scene.run.unstable_energy))
    j = int(bad[0])
    return _unstable(cls, scene, float(t[j]), float(err[j]), dt), j + 1


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


#: The states of steps 1, 2, ... up to the step given, in blocks: each block the step indices
#: (int array) and the state columns at those steps.
Replay = Callable[[int], Iterator[tuple[np.ndarray, Mapping[str, np.ndarray]]]]


@dataclass(frozen=True)
class RawRun:
    """What a solver hands to :func:`conclude`: the sample times ``t`` (s) and state columns,
    the impacts, its own verdict (from how it stopped), its clock (s), its notes (``info``),
    its energy columns (J) if it counted them itself, and, for a stepping solver whose samples
    skip steps, how to replay its steps (:data:`Replay`), so that a verdict is dated at the step
    where it happens. ``step_fixes``: its own ``failed`` verdict is one a smaller step cures
    (a particle held below a velocity-flip floor), so the message ends with a step to try;
    ``unstable`` and ``tunnelled`` always do."""

    t: np.ndarray
    state: Mapping[str, np.ndarray]
    events: Iterable[Impact] = ()
    verdict: Verdict = field(default_factory=Verdict)
    wall_time: float = 0.0
    info: Mapping[str, Any] = field(default_factory=dict)
    energy: Mapping[str, np.ndarray] | None = None
    replay: Replay | None = None
    step_fixes: bool = False


def judge(cls: type[Solver], scene: Scene, options: RunOptions, raw: RawRun
          ) -> tuple[Verdict, int, dict[str, np.ndarray]]:
    """The one mapping from how a run of the solver ``cls`` with ``options`` ended (``raw``)
    to its verdict:

    - a truth solver whose samples pass below the floor: ``failed`` there
      (:func:`missed_impact`);
    - ``unstable`` (the state blew up): the samples before the explosion, then the energy
      verdict if it finds the failure earlier, else the solver's;
    - ``tunnelled``, ``failed``: the solver's, all samples kept;
    - ``ok``: :func:`energy_verdict` (a truth solver's with no step), then, if the run stayed
      stable, :func:`accuracy_verdict` (``inaccurate``, all samples kept).

    An ``unstable`` or ``inaccurate`` verdict of a run that can replay its steps is dated at
    the first step whose energy error passes the scene's threshold, not at the first such
    sample. Every verdict but ``ok`` then ends with what to change (:mod:`.advice`).

    Returns the verdict, how many samples the run keeps, and the energy columns of those
    samples (from :func:`dumbbell.model.energy.partition` unless given). Changes nothing."""
    t, state, verdict = raw.t, raw.state, raw.verdict
    keep = len(t)
    dt = None if cls.is_truth else options.dt
    if cls.is_truth:
        missed = missed_impact(scene, cls.name, t, state)
        if missed is not None:
            verdict, keep = missed
    elif verdict.status == "unstable":
        # The explosion's samples (up to 1e300 J) would swamp every plot and bar scale.
        keep = finite_samples(state)
    t, state = t[:keep], head(state, keep)
    energy = (_partition(scene, t, state, tuple(raw.events)) if raw.energy is None
              else head(raw.energy, keep))
    # A state that blew up, or a step past its limit, measured no error worth scaling.
    limit = cls.step_limit
    blown = verdict.status == "unstable" or (
        dt is not None and limit is not None and step_ratio(scene, dt) >= limit)
    if verdict.ok or verdict.status == "unstable":
        judged, keep = energy_verdict(cls, scene, t, energy, dt)
        if raw.replay is not None and dt is not None and len(t) and not (
                judged.ok and verdict.ok):
            # The last step to look at: the first bad sample's, else the explosion's.
            last = round(judged.t / dt) if not judged.ok else round(verdict.t / dt)  # type: ignore[operator]
            judged = _first_bad_step(cls, scene, dt, energy, raw.replay(last)) or judged
        if not (judged.ok and verdict.status == "unstable"):
            verdict = judged
    if verdict.ok:
        verdict = _accuracy(scene, dt, (t, energy), raw)
    if not verdict.ok:
        cured = verdict.status != "failed" or raw.step_fixes
        verdict = _advised(cls, scene, options, verdict, (t, state, energy),
                           (cured, blown))
    if verdict.status == "failed" and verdict.t is not None and (
            not raw.step_fixes or verdict is raw.verdict or scene.system.elasticity < 1.0):
        # No step cures it, none was found, or a step may not: a particle held on an
        # inelastic floor may be at rest there for good.
        verdict = _ended_early(scene, verdict, held=raw.step_fixes)
    return verdict, keep, head(energy, keep)


def _accuracy(scene: Scene, dt: float | None,
              samples: tuple[np.ndarray, Mapping[str, np.ndarray]], raw: RawRun) -> Verdict:
    """The verdict of a run that stayed stable: ``ok``, or ``inaccurate`` dated at the first
    step (replayed, where the run can) whose energy error passes ``run.inaccurate_energy``."""
    t, energy = samples
    judged, worst = accuracy_verdict(scene, t, energy)
    if judged.ok or raw.replay is None or dt is None:
        return judged
    E0, scale = float(energy["E"][0]), _start_scale(energy, scene.system)
    events = tuple(raw.events) if scene.system.dissipative else ()

    def errors(steps: np.ndarray, state: Mapping[str, np.ndarray]) -> np.ndarray:
        return _accuracy_errors(scene, _partition(scene, steps * dt, state, events), E0, scale)

    found = _first_step_past(raw.replay(round(judged.t / dt)), errors,  # type: ignore[operator]
                             scene.run.inaccurate_energy)
    if found is None:
        return judged
    step, err = found
    return _inaccurate(scene, step * dt, err, worst)


def _advised(cls: type[Solver], scene: Scene, options: RunOptions, verdict: Verdict,
             samples: tuple[np.ndarray, Mapping[str, np.ndarray], Mapping[str, np.ndarray]],
             how: tuple[bool, bool]) -> Verdict:
    """``verdict`` with the step to try at the end of its reason (:func:`advice.step_text`)
    when a smaller step cures it (``how`` = (cured, blown)): from the energy error the run
    measured up to its verdict (the samples: times in s, state, energy columns in J), unless
    it blew up."""
    cured, blown = how
    if not cls.has_step or not cured:
        return verdict
    t, state, energy = samples
    measured = None
    if len(t) > 1 and not blown:
        err = _accuracy_errors(scene, energy, float(energy["E"][0]),
                               _start_scale(energy, scene.system))
        end = np.searchsorted(t, verdict.t, side="right") if verdict.t is not None else len(t)
        if verdict.status == "inaccurate":
            end = len(t)  # the run went on: all of it was measured
        if end > 1:
            until = float(t[end - 1])
            measured = (options.dt, float(np.nanmax(err[:end])), until)
    bounds = advice.step_bounds(cls, scene, measured)
    if verdict.status == "tunnelled":
        columns = ("vA", "vB") if scene.system.dimensions == 1 else ("vyA", "vyB")
        speed = max(float(np.max(np.abs(state[c]))) for c in columns) if len(t) else 0.0
        bounds.append(advice.catch_bound(cls._catch_depth(scene), speed))
    text = advice.step_text(scene, options.dt, bounds)
    if not text:
        return verdict
    return Verdict(verdict.status, verdict.t, f"{verdict.reason}; {text}")


def _ended_early(scene: Scene, verdict: Verdict, held: bool = False) -> Verdict:
    """A ``failed`` verdict that no step cures, with what to change: a run that came to rest
    on an inelastic floor (or, ``held``, is held on it) ends before it or uses a solver that
    holds contact; one stopped by a budget or by its integrator ends before that time."""
    if RESTED in verdict.reason or held:
        fix = advice.rest_text(scene, verdict.t)  # type: ignore[arg-type]
    elif SHORTER in verdict.reason:
        return Verdict("failed", verdict.t, verdict.reason.replace(
            SHORTER, f"{SHORTER} (run.t_end = {advice.seconds_below(verdict.t)} s)", 1))  # type: ignore[arg-type]
    else:
        fix = (f"end the run before it (run.t_end = {advice.seconds_below(verdict.t)} s)"  # type: ignore[arg-type]
               if verdict.t > 0 else "")  # type: ignore[operator]
    return Verdict("failed", verdict.t, f"{verdict.reason}; {fix}") if fix else verdict


def _first_step_past(blocks: Iterator[tuple[np.ndarray, Mapping[str, np.ndarray]]],
                     errors: Callable[[np.ndarray, Mapping[str, np.ndarray]], np.ndarray],
                     threshold: float) -> tuple[int, float] | None:
    """The first of the replayed steps (``blocks`` of step indices and states) whose error
    (``errors`` of the block) passes ``threshold``, and that error; None if none does."""
    for steps, state in blocks:
        err = errors(steps, state)
        bad = np.flatnonzero(~(err <= threshold))
        if bad.size:
            j = int(bad[0])
            return int(steps[j]), float(err[j])
    return None


def _first_bad_step(cls: type[Solver], scene: Scene, dt: float,
                    energy: Mapping[str, np.ndarray],
                    blocks: Iterator[tuple[np.ndarray, Mapping[str, np.ndarray]]]
                    ) -> Verdict | None:
    """``unstable`` at the first of the replayed steps (``blocks`` of step indices and states;
    step ``dt`` in s) whose energy error (against the run's first sample, ``energy``) passes
    the scene's threshold; None if none does."""
    E0, scale = float(energy["E"][0]), _start_scale(energy, scene.system)

    def errors(steps: np.ndarray, state: Mapping[str, np.ndarray]) -> np.ndarray:
        return _energy_errors(scene, _partition(scene, steps * dt, state)["E"], E0, scale)

    found = _first_step_past(blocks, errors, scene.run.unstable_energy)
    if found is None:
        return None
    step, err = found
    return _unstable(cls, scene, float(step) * dt, err, dt)


def conclude(cls: type[Solver], scene: Scene, options: RunOptions, raw: RawRun) -> Trajectory:
    """The finished run ``raw`` of the solver ``cls`` with ``options`` as its one frozen
    Trajectory: :func:`judge` decides the verdict and where the run ends, then the Trajectory
    is built from the samples kept, and the impacts up to the last of them."""
    events = tuple(raw.events)
    verdict, keep, energy = judge(cls, scene, options, raw)
    t = raw.t
    if keep < len(t):
        # The verdict cut the run: impacts after its last sample belong to the part cut off
        # (an energy blow-up may bounce on for a while before the solver's end).
        end = float(t[keep - 1]) if keep else -math.inf
        events = tuple(e for e in events if e.t <= end)
    return Trajectory._made(scene=scene, solver=cls.name, t=t[:keep],
                            state=head(raw.state, keep), events=events, verdict=verdict,
                            dt=options.dt, every=options.every, wall_time=raw.wall_time,
                            info=raw.info, energy=energy)
