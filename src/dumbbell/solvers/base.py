"""What every solver is: the :class:`Solver` contract, run options and shared checks.

A solver is a class with its facts as class attributes and two class methods, ``supports``
and ``solve``. :data:`dumbbell.solvers.METHODS` maps each name to its class; adding a solver is
one module with one subclass, plus one line there. Solver modules import only light modules
at the top (numba kernels, pymunk and scipy are imported when a run needs them), so the
registry costs nothing to load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..errors import UsageError
from ..model.scene import Scene
from ..model.trajectory import Trajectory

#: Largest number of steps one run may take, so that no run can hang.
MAX_STEPS = 10**10


@dataclass(frozen=True)
class RunOptions:
    """Options of one run: ``dt`` and ``t_end`` in s, keep every ``every``-th step,
    ``quiet`` silences the progress bar."""

    dt: float
    t_end: float
    every: int = 1
    quiet: bool = True

    @property
    def n_steps(self) -> int:
        """Steps taken: round(t_end / dt)."""
        return round(self.t_end / self.dt)

    @property
    def n_samples(self) -> int:
        """Samples kept: steps 0, every, 2*every, ... up to n_steps."""
        return self.n_steps // self.every + 1

    def sample_times(self, count: int | None = None) -> np.ndarray:
        """Times of the first ``count`` samples (s; all by default): step * dt, with the step
        index j * every kept whole so every solver and every ``every`` share the same floats."""
        steps = np.arange(self.n_samples if count is None else count, dtype=np.int64)
        return (steps * self.every) * self.dt


class Solver:
    """The contract of a solver. Subclasses set every attribute below and implement
    :meth:`supports` and :meth:`solve`; they are never instantiated (all is class-level).

    Capabilities (a test checks that every registered solver declares each one):

    - ``name``: what scenes, the CLI and the outputs call it;
    - ``order``: the order p of its position error in the step, error ~ dt^p through
      impacts (None without a step);
    - ``has_step``: it advances by a fixed step ``dt`` (False: ``dt`` only spaces the samples);
    - ``explicit_spring``: its spring step is explicit, stable iff w*dt < 2 (w = sqrt(k/mu));
    - ``flip_floor``: its floor reverses velocities at impacts, so it cannot hold a particle in
      lasting contact (an inelastic floor ends the run as ``failed``);
    - ``relative_cost``: rough cost of one step (or one sample) against Euler-Cromer's, for
      scheduling work;
    - ``is_truth``: its error is far below any stepping solver's, so analysis may take it as the
      truth for scenes it supports (the first registered one that does);
    - ``estimates_error``: ``solve`` takes ``estimate_error=False`` to skip measuring its own
      error with a second, tighter run.
    """

    name: ClassVar[str]
    order: ClassVar[int | None]
    has_step: ClassVar[bool]
    explicit_spring: ClassVar[bool]
    flip_floor: ClassVar[bool]
    relative_cost: ClassVar[float]
    is_truth: ClassVar[bool]
    estimates_error: ClassVar[bool]

    #: Every capability a solver must declare itself (checked by the test suite).
    CAPABILITIES: ClassVar[tuple[str, ...]] = (
        "name", "order", "has_step", "explicit_spring", "flip_floor", "relative_cost",
        "is_truth", "estimates_error",
    )

    @classmethod
    def supports(cls, scene: Scene) -> str | None:
        """None if this solver can run ``scene``, else why not (one sentence)."""
        raise NotImplementedError

    @classmethod
    def solve(cls, scene: Scene, options: RunOptions) -> Trajectory:
        """Run ``scene`` with ``options``; the trajectory's ``verdict`` says how it ended."""
        raise NotImplementedError

    @classmethod
    def truth_for(cls, scene: Scene) -> bool:
        """Whether this (``is_truth``) solver is the truth for scenes of ``scene``'s kind,
        whether or not it can run this one (False for every other solver)."""
        return False

    @classmethod
    def catch_depth(cls, scene: Scene) -> float | None:
        """How far (m) a particle may move in one step and still be caught by a floor that is
        a body of finite thickness (beyond it, it passes through); None when the floor is not
        such a body."""
        return None

    @classmethod
    def warm_up(cls) -> float:
        """Compile or load what the first run would; returns the seconds it took, NaN when
        there is nothing to compile (the default)."""
        return math.nan


def kernel_params(scene: Scene) -> tuple[float, float, float, float, float, float, bool]:
    """The scalars the compiled time-steppers take: mA, mB (kg), k (N/m), b (m), g (m/s^2),
    the floor's elasticity, and whether there is a floor."""
    return (scene.A.mass, scene.B.mass, scene.k, scene.b, scene.g, scene.elasticity,
            scene.floor is not None)


def point_particle_limits(scene: Scene, name: str) -> str | None:
    """Why a hand-written 2D solver of two point particles, a spring and a frictionless floor
    cannot run ``scene``, or None if it can."""
    if scene.rigid is not None:
        return f"{name} handles two particles and a spring, not a rigid body"
    if scene.floor is not None and scene.floor.friction > 0:
        return f"{name} has a frictionless floor only; use pymunk for friction"
    if scene.pymunk.spin:
        return f"{name} has point particles (no spin); use pymunk for spinning particles"
    return None


def make_options(
    scene: Scene, dt: float | None = None, t_end: float | None = None, every: int | None = None,
    quiet: bool = True,
) -> RunOptions:
    """Fill run options from the scene's ``[run]`` table and check them (UsageError)."""
    dt = scene.run.dt if dt is None else dt
    t_end = scene.run.t_end if t_end is None else t_end
    every = scene.run.every if every is None else every
    for name, value, unit in (("dt", dt, "s"), ("t_end", t_end, "s")):
        if isinstance(value, bool) or not isinstance(value, int | float) or not (
            math.isfinite(value) and value > 0
        ):
            raise UsageError(f"{name} = {value!r}: must be a finite number > 0 ({unit})")
    if dt > t_end:
        raise UsageError(f"dt = {dt:g}: must be <= t_end = {t_end:g} (s)")
    if isinstance(every, bool) or not isinstance(every, int) or every < 1:
        raise UsageError(f"every = {every!r}: must be a whole number >= 1 (steps)")
    options = RunOptions(float(dt), float(t_end), int(every), quiet)
    if options.n_steps > MAX_STEPS:
        raise UsageError(
            f"t_end / dt = {options.n_steps:.3g} steps: must be at most {MAX_STEPS:.0e}"
        )
    return options
