"""Solvers: each takes a Scene plus run options and returns a :class:`Trajectory`.

>>> traj = simulate(load_scene("scenes/textbook-1d.toml"), "exact", every=100)  # doctest: +SKIP

A solver is a :class:`Solver` subclass (the contract is in :mod:`dumbbell.solvers.base`): its
facts (order, step, floor, cost, ...) are class attributes, and ``supports(scene)`` and
``solve(scene, options)`` are class methods. :data:`METHODS` is the registry. Adding a solver
is one module with one subclass and one line in :data:`METHODS`; the heavy parts (numba
kernels, pymunk, scipy) load only when that solver runs.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import SceneError, UsageError
from ..model import args
from ..model.scene import Scene
from ..model.trajectory import Trajectory
from .base import MAX_SAMPLES, MAX_STEPS, RunOptions, Solver, make_options
from .engine import Pymunk
from .euler_cromer import EulerCromer
from .euler_cromer_2d import EulerCromer2D
from .exact import Exact
from .reference import Reference
from .verlet import Verlet

#: Solver name -> class, in the order listings show them.
METHODS: dict[str, type[Solver]] = {
    cls.name: cls for cls in (EulerCromer, Exact, Verlet, Pymunk, Reference, EulerCromer2D)
}
#: Another name for :data:`METHODS`.
REGISTRY = METHODS

__all__ = [
    "MAX_SAMPLES",
    "MAX_STEPS",
    "METHODS",
    "REGISTRY",
    "RunOptions",
    "Solver",
    "available",
    "make_options",
    "no_truth_reason",
    "scene_solver",
    "simulate",
    "solver_class",
    "supported",
    "truth_solver",
]


def solver_class(solver: str) -> type[Solver]:
    """The class of the solver named ``solver``; UsageError naming the choices when there is
    none."""
    if not isinstance(solver, str):
        raise UsageError(f"solver = {args.show(solver)}: must be a solver name, one of "
                         f"{', '.join(available())}", param="solver")
    if solver not in METHODS:
        raise UsageError(f"solver {args.show(solver)}: must be one of {', '.join(available())}")
    return METHODS[solver]


def scene_solver(scene: Scene) -> type[Solver]:
    """The class of the solver the scene's ``run.solver`` names; SceneError naming the file
    and key when no solver has that name."""
    scene = args.scene(scene)
    name = scene.run.solver
    if name not in METHODS:
        raise SceneError(f"{scene.source}: run.solver = {args.show(name)}: must be one of "
                         f"{', '.join(available())}")
    return METHODS[name]


def available() -> list[str]:
    """Names of all solvers this installation has."""
    return list(METHODS)


def supported(scene: Scene) -> list[str]:
    """Names of the solvers that can run ``scene``."""
    scene = args.scene(scene)
    return [n for n, cls in METHODS.items() if cls.supports(scene) is None]


def _truth_class(scene: Scene) -> type[Solver] | None:
    """The truth solver for scenes of ``scene``'s kind, whether or not it can run this one."""
    return next((cls for cls in METHODS.values() if cls.is_truth and cls.truth_for(scene)),
                None)


def truth_solver(scene: Scene) -> str | None:
    """The solver analysis takes as truth for ``scene`` (``exact`` in 1D and for the rigid 2D
    dumbbell, ``reference`` for a 2D spring); None when it cannot run the scene."""
    scene = args.scene(scene)
    cls = _truth_class(scene)
    return cls.name if cls is not None and cls.supports(scene) is None else None


def no_truth_reason(scene: Scene) -> str | None:
    """Why there is no truth for ``scene`` (its truth solver's reason), or None if there is."""
    scene = args.scene(scene)
    cls = _truth_class(scene)
    if cls is None:
        return "no solver is the truth for this kind of scene"
    return cls.supports(scene)


def simulate(
    scene: Scene | str | Path,
    solver: str | None = None,
    dt: float | None = None,
    t_end: float | None = None,
    every: int | None = None,
    quiet: bool = True,
    max_samples: int | None = MAX_SAMPLES,
) -> Trajectory:
    """Run ``scene`` (a Scene or the path of a scene file) with ``solver`` (default: the
    scene's). ``dt`` and ``t_end`` in s override the scene's ``[run]``; ``every`` keeps every
    N-th step; a run that would keep more than ``max_samples`` samples is refused before it
    starts (None: no budget). Returns a :class:`Trajectory` whose ``verdict`` says whether
    the run ended well."""
    scene = args.scene(scene)
    cls = scene_solver(scene) if solver is None else solver_class(solver)
    name = cls.name
    reason = cls.supports(scene)
    if reason is not None:
        raise UsageError(f"solver {name!r} cannot run {scene.source}: {reason}")
    return cls.solve(scene, make_options(scene, dt, t_end, every, quiet, max_samples))
