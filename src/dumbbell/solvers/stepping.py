"""The driver the compiled time-steppers share (euler-cromer, euler-cromer-2d, verlet).

Each has a numba kernel (contract in :mod:`dumbbell.solvers.kernels`). It stops early on a bad
status or when its impact buffer is nearly full; :func:`run_kernel` calls it chunk by chunk,
which is also what moves the progress bar; :func:`kernel_verdict` names the status it ended
with as a verdict, and :func:`finish` hands the samples to :func:`~.verdicts.conclude`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..model.scene import Scene
from ..model.trajectory import Impact, Trajectory, Verdict
from ..progress import bar
from .base import RunOptions, Solver
from .kernels import BLOWUP, EVENT_BUFFER, OK, REST, TUNNEL_A, TUNNEL_B, Params
from .verdicts import conclude, nonfinite_reason

#: Nothing public: the machinery the solver classes share.
__all__: list[str] = []


class Stepper(Solver):
    """The facts the compiled time-steppers share: a fixed step, an explicit spring step
    (stable iff w*dt < 2), a floor that reverses velocities, the cost of one Euler-Cromer
    step. A subclass adds its ``name`` and ``order`` and its ``supports`` and ``solve``."""

    has_step = True
    explicit_spring = True
    flip_floor = True
    relative_cost = 1.0
    is_truth = False
    estimates_error = False


@dataclass
class KernelRun:
    """What a chunked run ended with: steps taken, status code, impacts, loop time (s)."""

    steps: int
    status: int
    events: list[Impact]
    wall: float


def run_kernel(
    kernel: Callable, params: Params, st: np.ndarray, out: np.ndarray, options: RunOptions,
    desc: str, chunk: int, event_time_in_steps: bool,
) -> KernelRun:
    """Run ``kernel`` over ``options.n_steps`` steps in chunks of ``chunk`` steps, with a
    progress bar on a terminal for long runs. ``event_time_in_steps``: the kernel records the
    step index of an impact (its time is then index * dt) rather than the time itself."""
    dt, every, n = options.dt, options.every, options.n_steps
    ev = np.empty((EVENT_BUFFER, 4))
    scale = dt if event_time_in_steps else 1.0
    events: list[Impact] = []
    status, i = OK, 0
    t0 = time.perf_counter()
    with bar(n, desc, "step", quiet=options.quiet or n < 5 * chunk) as pb:
        while i < n and status == OK:
            i_new, status, n_ev = kernel(st, i, min(n, i + chunk), params, every, out, ev)
            events.extend(Impact(float(r[0]) * scale, "AB"[int(r[1])], float(r[2]), float(r[3]))
                          for r in ev[:n_ev])
            pb.update(i_new - i)
            i = i_new
    return KernelRun(i, status, events, time.perf_counter() - t0)


def kernel_verdict(
    scene: Scene, run: KernelRun, dt: float,
    below_floor: Callable[[str], Verdict],
    at_rest: Callable[[], Verdict] | None = None,
) -> Verdict:
    """The solver's own verdict on a kernel run that ended with ``run.status``: blown up
    (``unstable`` at the overflow, :func:`~.verdicts.judge` then looks for an earlier energy
    failure), a particle below the floor (``below_floor("A" or "B")``, the solver's own
    diagnosis), at rest on the floor (``at_rest()``), else ok. ``dt`` is the step (s)."""
    if run.status == BLOWUP:
        return Verdict("unstable", run.steps * dt, nonfinite_reason(scene, dt))
    if run.status in (TUNNEL_A, TUNNEL_B):
        return below_floor("A" if run.status == TUNNEL_A else "B")
    if run.status == REST and at_rest is not None:
        return at_rest()
    return Verdict()


def finish(
    scene: Scene, name: str, run: KernelRun, options: RunOptions, state: dict[str, np.ndarray],
    below_floor: Callable[[str], Verdict], at_rest: Callable[[], Verdict] | None = None,
) -> Trajectory:
    """The Trajectory of a kernel run whose samples are ``state`` (every ``options.every``-th
    step from the start): the verdict of :func:`kernel_verdict`, settled by
    :func:`~.verdicts.conclude`."""
    dt = options.dt
    kept = len(next(iter(state.values())))
    return conclude(scene, name, options.sample_times(kept), state, run.events,
                    kernel_verdict(scene, run, dt, below_floor, at_rest), dt=dt,
                    every=options.every, wall_time=run.wall, info={"steps": run.steps})
