"""Solvers: each takes a Scene plus run options and returns a :class:`Trajectory`.

A solver is a :class:`Solver` subclass (the contract is in :mod:`dumbbell.solvers.base`): its
facts (order, step limit, floor, cost, ...) are class attributes, and ``supports(scene)`` and
``solve(scene, options)`` are class methods. A stepping solver subclasses :class:`Stepper` and
writes only its step (a :class:`Kernel`). :func:`simulate` and the analyses take such a class
as it is, like scipy's ``method=``; :data:`METHODS` is the registry of the names scenes and
the command line know. The heavy parts (numba kernels, pymunk, scipy) load only when a solver
runs.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

from ..errors import SceneError, UsageError
from ..model import args
from ..model.scene import Scene
from ..model.trajectory import Trajectory
from .base import (
    MAX_SAMPLES,
    REGISTRY,
    RunOptions,
    Solver,
    contract_problems,
    make_options,  # noqa: F401 - the analyses import it from here
    scene_options,
)
from .engine import Pymunk
from .euler_cromer import EulerCromer
from .euler_cromer_2d import EulerCromer2D
from .exact import Exact
from .kernels import Kernel
from .reference import Reference
from .stepping import Stepper
from .verlet import Verlet

#: Solver name -> class, in the order listings show them (the one dict, ``base.REGISTRY``,
#: that the solvers' own modules read).
METHODS: dict[str, type[Solver]] = REGISTRY
METHODS.update({
    cls.name: cls for cls in (EulerCromer, Exact, Verlet, Pymunk, Reference, EulerCromer2D)
})

__all__ = ["METHODS", "Kernel", "RunOptions", "Solver", "Stepper", "available", "simulate"]


def solver_class(solver: str | type[Solver]) -> type[Solver]:
    """The class of the solver named ``solver``, or ``solver`` itself when it is a
    :class:`Solver` subclass that keeps the contract (like scipy's ``method=``, which takes a
    name or an ``OdeSolver`` subclass); UsageError naming the choices otherwise."""
    if isinstance(solver, str):
        if solver not in METHODS:
            raise UsageError(f"solver {args.show(solver)}: must be one of "
                             f"{', '.join(available())}")
        return METHODS[solver]
    return _solver(solver, "solver")


def _solver(solver: Any, param: str) -> type[Solver]:
    """``solver`` (a registered name or a Solver subclass) as a class; UsageError naming
    ``param`` when it is neither, or a class that breaks the contract."""
    if isinstance(solver, str) and solver in METHODS:
        return METHODS[solver]
    if isinstance(solver, type) and issubclass(solver, Solver):
        problems = contract_problems(solver)
        if problems:
            raise UsageError(f"{param} = {solver.__qualname__}: does not keep the solver "
                             f"contract: {'; '.join(problems)}", param=param)
        return solver
    raise UsageError(f"{param} = {args.show(solver)}: must be one of {', '.join(available())}"
                     " (or a Solver subclass)", param=param)


def solver_classes(solvers: Any, param: str = "solvers") -> list[type[Solver]] | None:
    """None (the caller's default set), or one solver or a list of them (names or classes,
    see :func:`solver_class`) as a list of classes, each once; UsageError naming ``param``."""
    if solvers is None or (isinstance(solvers, list | tuple) and not solvers):
        return None
    if isinstance(solvers, str | type):
        solvers = [solvers]
    if not isinstance(solvers, list | tuple):
        raise UsageError(f"{param} = {args.show(solvers)}: must be a list of solvers (names "
                         f"among {', '.join(available())}, or Solver subclasses)", param=param)
    return list(dict.fromkeys(_solver(s, param) for s in solvers))


def scene_solver(scene: Scene) -> type[Solver]:
    """The class of the solver the scene's ``run.solver`` names; SceneError naming the file
    and key when no solver has that name."""
    return scene_class(args.scene(scene))


def scene_class(scene: Scene) -> type[Solver]:
    """:func:`scene_solver` of a Scene."""
    name = scene.run.solver
    if name not in METHODS:
        raise SceneError(f"{scene.source}: run.solver = {args.show(name)}: must be one of "
                         f"{', '.join(available())}")
    return METHODS[name]


def available() -> list[str]:
    """Names of all solvers this installation has (``dumbbell.available_solvers()``).

    Returns
    -------
    list of str
        In the order listings show them.

    Examples
    --------
    >>> import dumbbell
    >>> dumbbell.available_solvers()
    ['euler-cromer', 'exact', 'verlet', 'pymunk', 'reference', 'euler-cromer-2d']
    """
    return list(METHODS)


def supported(scene: Scene) -> list[str]:
    """Names of the solvers that can run ``scene``."""
    return [cls.name for cls in supporting(args.scene(scene))]


def supporting(scene: Scene) -> list[type[Solver]]:
    """The registered solvers that can run the Scene ``scene``, in registry order."""
    return [cls for cls in METHODS.values() if cls._supports(scene) is None]


def _truth_class(scene: Scene) -> type[Solver] | None:
    """The truth solver for scenes of ``scene``'s kind, whether or not it can run this one."""
    return next((cls for cls in METHODS.values() if cls.is_truth and cls._truth_for(scene)),
                None)


def truth_solver(scene: Scene) -> str | None:
    """The solver analysis takes as truth for ``scene`` (``exact`` in 1D and for the rigid 2D
    dumbbell, ``reference`` for a 2D spring); None when it cannot run the scene."""
    cls = truth_class(args.scene(scene))
    return None if cls is None else cls.name


def truth_class(scene: Scene) -> type[Solver] | None:
    """:func:`truth_solver` of a Scene, as its class."""
    cls = _truth_class(scene)
    return cls if cls is not None and cls._supports(scene) is None else None


def no_truth_reason(scene: Scene) -> str | None:
    """Why there is no truth for ``scene`` (its truth solver's reason), or None if there is."""
    scene = args.scene(scene)
    cls = _truth_class(scene)
    if cls is None:
        return "no solver is the truth for this kind of scene"
    return cls._supports(scene)


def simulate(
    scene: Scene | str | Path,
    solver: str | type[Solver] | None = None,
    dt: float | None = None,
    t_end: float | None = None,
    every: int | None = None,
    quiet: bool = True,
    max_samples: int | None = MAX_SAMPLES,
) -> Trajectory:
    """Run a scene with a solver (``dumbbell.simulate``).

    Parameters
    ----------
    scene : Scene or str or pathlib.Path
        The scene, or its file.
    solver : str or Solver subclass or None, default None
        A name of :func:`available`, or a :class:`Solver` subclass; None: the scene's.
    dt, t_end : float or None, default None
        The step and the run's end (s); None: the scene's ``[run]``.
    every : int or None, default None
        Keep every N-th step (None: the scene's), so memory follows the samples, not the
        steps.
    quiet : bool, default True
        No progress bar.
    max_samples : int or None, default MAX_SAMPLES
        A run that would keep more samples is refused before it starts (None: no budget).

    Returns
    -------
    Trajectory
        The run; its ``verdict`` says whether it ended well.

    Raises
    ------
    SceneError
        A scene file that is missing or not valid.
    UsageError
        A solver that does not exist or cannot run the scene, an argument that is not
        allowed, or a run past the budget (one line saying what would do).

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> traj = dumbbell.simulate(scenes_dir() / "textbook-1d.toml", solver="exact",
    ...                          dt=1e-5, t_end=2.0, every=100)
    >>> traj.events[0].t, traj.verdict.status
    (0.4517539514526256, 'ok')
    >>> dumbbell.simulate(scenes_dir() / "textbook-1d.toml", solver="rk45")
    Traceback (most recent call last):
    ...
    dumbbell.errors.UsageError: solver 'rk45': must be one of euler-cromer, exact, verlet, pymunk, reference, euler-cromer-2d
    """
    scene = args.scene(scene)
    cls = scene_class(scene) if solver is None else solver_class(solver)
    runnable(cls, scene)
    options = scene_options(scene, dt, t_end, every, max_samples)
    if quiet is not True:
        options = replace(options, quiet=args.flag(quiet, "quiet"))
    return cls._solve(scene, options)


def run_scene(scene: Scene, solver: str | type[Solver] | None, options: RunOptions
              ) -> Trajectory:
    """:func:`simulate` of a Scene and its run options (both checked already: the commands'
    path, from the scene file they read)."""
    cls = scene_class(scene) if solver is None else solver_class(solver)
    runnable(cls, scene)
    return cls._solve(scene, options)


def runnable(cls: type[Solver], scene: Scene) -> None:
    """UsageError when the solver ``cls`` cannot run ``scene``, saying why."""
    reason = cls._supports(scene)
    if reason is not None:
        raise UsageError(f"solver {cls.name!r} cannot run {scene.source}: {reason}")
