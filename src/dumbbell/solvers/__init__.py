"""Solvers: each takes a Scene plus run options and returns a :class:`Trajectory`.

>>> traj = simulate(load_scene("scenes/textbook-1d.toml"), "exact", every=100)  # doctest: +SKIP

A solver module provides ``NAME``, ``supports(scene) -> str | None`` (None when it can run
the scene, else the reason it cannot) and ``solve(scene, options) -> Trajectory``. Modules
are imported only when their solver is used, so pymunk is loaded only for ``pymunk``.
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from ..errors import UsageError
from ..model.scene import SOLVER_NAMES, Scene
from ..model.trajectory import Trajectory

#: Solver name -> module that implements it.
REGISTRY: dict[str, str] = {
    "euler-cromer": "dumbbell.solvers.euler_cromer",
    "exact": "dumbbell.solvers.exact",
    "verlet": "dumbbell.solvers.verlet",
    "pymunk": "dumbbell.solvers.engine",
    "reference": "dumbbell.solvers.reference",
    "euler-cromer-2d": "dumbbell.solvers.euler_cromer_2d",
}
assert set(REGISTRY) <= set(SOLVER_NAMES)

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


def solver_module(name: str) -> ModuleType:
    """The module of solver ``name``; UsageError naming the choices when there is none."""
    if name not in REGISTRY:
        raise UsageError(f"solver {name!r}: must be one of {', '.join(available())}")
    return importlib.import_module(REGISTRY[name])


def available() -> list[str]:
    """Names of all solvers this installation has."""
    return list(REGISTRY)


def supported(scene: Scene) -> list[str]:
    """Names of the solvers that can run ``scene``."""
    return [n for n in REGISTRY if solver_module(n).supports(scene) is None]


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


def simulate(
    scene: Scene,
    solver: str | None = None,
    dt: float | None = None,
    t_end: float | None = None,
    every: int | None = None,
    quiet: bool = True,
) -> Trajectory:
    """Run ``scene`` with ``solver`` (default: the scene's). ``dt`` and ``t_end`` in s override
    the scene's ``[run]``; ``every`` keeps every N-th step. Returns a :class:`Trajectory`
    whose ``verdict`` says whether the run ended well."""
    name = scene.run.solver if solver is None else solver
    module = solver_module(name)
    reason = module.supports(scene)
    if reason is not None:
        raise UsageError(f"solver {name!r} cannot run {scene.source}: {reason}")
    return module.solve(scene, make_options(scene, dt, t_end, every, quiet))
