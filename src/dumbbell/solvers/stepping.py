"""What the compiled time-steppers share (euler-cromer, euler-cromer-2d, verlet, and any
:class:`Stepper` written outside the package): everything but the step.

A stepping solver is a :class:`Stepper` subclass that declares its facts and returns its
compiled step from :meth:`Stepper.kernel` (a :class:`~dumbbell.solvers.kernels.Kernel`);
:mod:`.kernels.driver` wraps the step in the one loop that handles the floor, the sampling and
the stops. Here, :meth:`Stepper.solve` runs that loop chunk by chunk (which moves the progress
bar), names the status it stopped with as a verdict (:func:`kernel_verdict`), and hands the
samples to :func:`~.verdicts.conclude` with a replay of the steps, so that an energy failure
between two samples is dated at its step.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from .._install import compiling
from ..model.energy import _partition, state_columns
from ..model.scene import Scene
from ..model.trajectory import Impact, Trajectory, Verdict
from ..progress import bar
from .base import RunOptions, Solver, kernel_params, point_particle_limits
from .kernels import BLOWUP, EVENT_BUFFER, OK, REST, TUNNEL_A, TUNNEL_B, Kernel, Params
from .verdicts import (
    RawRun,
    Sinking,
    below_floor_verdict,
    conclude,
    nonfinite_reason,
    rest_reason,
)

#: Nothing public: the machinery the solver classes share.
__all__: list[str] = []

#: Steps per replayed block when a verdict is dated (a few MB of states).
REPLAY_BLOCK = 1 << 16


class Stepper(Solver):
    """A solver that advances by a fixed step with a compiled kernel. A subclass declares
    ``name``, ``order`` and ``step_limit`` and writes :meth:`kernel`; ``supports`` and
    ``solve`` are written here, from the kernels it has (``no_step`` says what to use where it
    has none; a subclass may say more in its own ``_supports``). Its floor reverses velocities (``flip_floor``), and its step costs about
    Euler-Cromer's (``relative_cost``; a costlier step says so).

    Examples
    --------
    A solver whose step leaves every particle where it is (numba compiles it on first use):

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> from dumbbell.solvers import Kernel, Stepper
    >>> def still(s, p):
    ...     return s
    >>> class Still(Stepper):
    ...     name = "still"
    ...     order = 1
    ...     step_limit = None
    ...     @staticmethod
    ...     def kernel(dimensions):
    ...         return Kernel(still) if dimensions == 1 else None
    >>> Still.supports(dumbbell.load_scene(scenes_dir() / "tilted-2d.toml"))
    'still has no step for 2D scenes'
    >>> Still.kernel(2) is None
    True
    >>> traj = dumbbell.simulate(scenes_dir() / "textbook-1d.toml", Still, t_end=0.01)
    >>> traj.solver, bool(traj["xA"][-1] == traj["xA"][0])
    ('still', True)
    >>> from dumbbell.solvers import RunOptions
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> len(Still.solve(scene, RunOptions(1e-3, 0.01)).t)     # the class, called directly
    11
    >>> Still.warm_up() >= 0                       # compiled already: loads at once
    True
    """

    has_step = True
    flip_floor = True
    relative_cost = 1.0
    is_truth = False
    estimates_error = False
    #: Steps per kernel call: the progress bar moves between calls.
    chunk: ClassVar[int] = 2_000_000
    #: What :meth:`supports` says of a scene whose dimensions it has no step for (None: "NAME
    #: has no step for ND scenes").
    no_step: ClassVar[str | None] = None

    @classmethod
    def kernel(cls, dimensions: int) -> Kernel | None:
        """The compiled step for scenes of some dimensions: the one thing a stepping solver
        writes.

        Parameters
        ----------
        dimensions : {1, 2}
            The scene's.

        Returns
        -------
        Kernel or None
            The step; None where there is none.
        """
        raise NotImplementedError

    @classmethod
    def _supports(cls, scene: Scene) -> str | None:
        """Whether this solver has a step for the scene's dimensions (in 2D: two point
        particles, a spring and a frictionless floor).

        Parameters
        ----------
        scene : Scene
            The scene.

        Returns
        -------
        str or None
            None if it can run it; else why not.
        """
        if cls.kernel(scene.system.dimensions) is None:
            return cls.no_step or f"{cls.name} has no step for {scene.system.dimensions}D scenes"
        return point_particle_limits(scene, cls.name) if scene.system.dimensions == 2 else None

    @classmethod
    def _solve(cls, scene: Scene, options: RunOptions) -> Trajectory:
        """Run a scene at step ``options.dt``. ``wall_time`` covers the kernel calls and the
        impact list, not the compiling, the array set-up, the verdict or the energy.

        Parameters
        ----------
        scene : Scene
            A scene this solver supports.
        options : RunOptions
            The step (s), the end (s), the samples kept.

        Returns
        -------
        Trajectory
            The run; its ``verdict`` says how it ended.
        """
        with compiling(f"the {cls.name} solver's kernels", options.quiet):
            run = _Steps.of(cls, scene, options.dt)
            if scene.system.dimensions == 1:
                _ready_partition()  # used once the run is done: compiled (or loaded) with it
        columns = state_columns(scene)
        # One contiguous row per column, so the Trajectory's columns are views, not copies.
        out = np.empty((len(columns), options.n_samples))
        out[:, 0] = run.st
        t0 = time.perf_counter()
        with bar(options.n_steps, f"{cls.name} {scene.name}", "step",
                 quiet=options.quiet or options.n_steps < 5 * cls.chunk) as pb:
            steps, status = run.drive((0, options.n_steps), (out, 0, options.every),
                                      cls.chunk, pb.update)
        wall = time.perf_counter() - t0
        kept = steps // options.every + 1
        state = {name: out[c, :kept] for c, name in enumerate(columns)}
        t = options.sample_times(kept)
        verdict = kernel_verdict(cls, scene, run, (steps, status), (t, state))

        def replay(last: int) -> Iterator[tuple[np.ndarray, dict[str, np.ndarray]]]:
            return _Steps.of(cls, scene, options.dt).replay(columns, last)

        # A particle held below the floor is the step's doing (it flipped too late).
        held = status in (TUNNEL_A, TUNNEL_B)
        return conclude(cls, scene, options, RawRun(t, state, run.events, verdict, wall,
                                                    {"steps": steps}, replay=replay,
                                                    step_fixes=held))

    @classmethod
    def warm_up(cls) -> float:
        """Compile (or load from numba's cache) the loop of every kernel the solver has, and
        the 1D energy partition.

        Returns
        -------
        float
            The seconds it took.
        """
        t0 = time.perf_counter()
        params = Params(1e-5, 0.1, 0.1, 200.0, 0.2, 9.8, 1.0, True, 0.02, 0.02)
        for dimensions, width in ((1, 4), (2, 8)):
            if cls.kernel(dimensions) is not None:
                _ready(_loop(cls, dimensions), params, width)
        if cls.kernel(1) is not None:
            _ready_partition()
        return time.perf_counter() - t0


def _ready_partition() -> None:
    """Compile (or load) the 1D energy partition's loop."""
    from ..model.energy import _loop_1d

    _loop_1d()((0.1, 0.1, 200.0, 0.2, 9.8), *np.ones((4, 1)))


def _loop(cls: type[Stepper], dimensions: int) -> Callable[..., Any]:
    """The compiled loop of ``cls``'s kernel in ``dimensions``."""
    from .kernels.driver import advance

    return advance(cls.kernel(dimensions), dimensions)  # type: ignore[arg-type]


def _ready(loop: Callable[..., Any], params: Params, width: int) -> None:
    """Compile (or load) ``loop`` for these types by running it over no step."""
    loop(np.zeros(width), 0, 0, params, 1, np.empty((width, 1)), 0, np.empty((EVENT_BUFFER, 4)))


def initial_state(scene: Scene) -> np.ndarray:
    """The scene's starting state in the kernels' layout (see :mod:`.kernels`)."""
    A, B = scene.system.A, scene.system.B
    if scene.system.dimensions == 1:
        return np.array([A.height, A.vy, B.height, B.vy], dtype=np.float64)
    return np.array([A.x, A.height, A.vx, A.vy, B.x, B.height, B.vx, B.vy], dtype=np.float64)


@dataclass
class _Steps:
    """A stepping solver's compiled loop, the run's scalars (``params``), its state (changed
    in place) and the impacts recorded so far."""

    loop: Callable[..., Any]
    params: Params
    st: np.ndarray
    events: list[Impact] = field(default_factory=list)

    @classmethod
    def of(cls, solver: type[Stepper], scene: Scene, dt: float) -> _Steps:
        """The loop of ``solver`` for ``scene`` at step ``dt`` (s), compiled or loaded (not
        part of a run's time), from the scene's starting state."""
        loop = _loop(solver, scene.system.dimensions)
        st = initial_state(scene)
        params = kernel_params(scene.system, dt)
        _ready(loop, params, len(st))
        return cls(loop, params, st)

    def drive(self, span: tuple[int, int], samples: tuple[np.ndarray, int, int], chunk: int,
              progress: Callable[[int], Any] | None = None) -> tuple[int, int]:
        """Steps ``span`` = (first, stop) in calls of at most ``chunk`` steps, keeping every
        ``every``-th step in ``samples`` = (array, index of the sample in its column 0,
        every), until the stop step or a bad status. Returns (step reached, status)."""
        (i, stop), (array, j0, every) = span, samples
        ev = np.empty((EVENT_BUFFER, 4))
        status = OK
        while i < stop and status == OK:
            i_new, status, n_ev = self.loop(self.st, i, min(stop, i + chunk), self.params,
                                            every, array, j0, ev)
            self.events.extend(Impact(float(r[0]), "AB"[int(r[1])], float(r[2]), float(r[3]))
                               for r in ev[:n_ev])
            if progress is not None:
                progress(i_new - i)
            i = i_new
        return i, status

    def replay(self, columns: list[str], last: int
               ) -> Iterator[tuple[np.ndarray, dict[str, np.ndarray]]]:
        """Steps 1..``last`` of a run from the starting state, in blocks of
        :data:`REPLAY_BLOCK`: each block's step indices and states (the kernel is
        deterministic, so they are the run's own floats)."""
        i = 0
        block = np.empty((len(columns), REPLAY_BLOCK))
        while i < last:
            stop = min(last, i + REPLAY_BLOCK)
            reached, _ = self.drive((i, stop), (block, i + 1, 1), REPLAY_BLOCK)
            steps = np.arange(i + 1, reached + 1)
            yield steps, {name: block[c, : len(steps)] for c, name in enumerate(columns)}
            if reached < stop:
                return
            i = stop


def kernel_verdict(cls: type[Solver], scene: Scene, run: _Steps, end: tuple[int, int],
                   samples: tuple[np.ndarray, dict[str, np.ndarray]]) -> Verdict:
    """The solver's own verdict on a ``run`` that stopped at ``end`` = (step, status), with
    the ``samples`` (times, state) it kept: blown up (``unstable`` at that step,
    :func:`~.verdicts.judge` then looks for an earlier energy failure), a particle below the
    floor (:func:`~.verdicts.below_floor_verdict`), at rest on the floor (``failed`` at its
    last impact), else ok."""
    steps, status = end
    dt = run.params.dt
    if status == BLOWUP:
        return Verdict("unstable", steps * dt, nonfinite_reason(scene, dt, cls.step_limit))
    if status in (TUNNEL_A, TUNNEL_B):
        t, state = samples
        E = _partition(scene, t[[0, -1]], {k: v[[0, -1]] for k, v in state.items()})["E"]
        return below_floor_verdict(scene, steps * dt, dt, sinking(scene, run.st, status), E=E)
    if status == REST:
        last = run.events[-1] if run.events else None
        return Verdict("failed", last.t if last else steps * dt,
                       rest_reason(last.body if last else "a particle",
                                   last.v_before if last else 0.0))
    return Verdict()


def sinking(scene: Scene, st: np.ndarray, status: int) -> Sinking:
    """The particle that the status ``TUNNEL_A`` or ``TUNNEL_B`` names, in the state ``st``:
    its height and vertical velocity, the spring's downward push on it, and (for a kernel
    that catches a circle while it overlaps the floor) its radius."""
    system = scene.system
    one = system.dimensions == 1
    hA, vA, hB, vB = (0, 1, 2, 3) if one else (1, 3, 5, 7)
    if one:
        f = system.k * (st[0] - st[2] - system.b)  # the spring's pull, down on A
    else:
        L = math.hypot(st[0] - st[4], st[1] - st[5])
        f = system.k * (L - system.b) * (st[1] - st[5]) / L if L > 0 else 0.0
    body = "A" if status == TUNNEL_A else "B"
    h, v = (hA, vA) if body == "A" else (hB, vB)
    push = f / system.A.mass if body == "A" else -f / system.B.mass
    return Sinking(body, float(st[h]), float(st[v]), push)
