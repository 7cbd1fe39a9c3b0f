"""What every solver is: the :class:`Solver` contract, run options and shared checks.

A solver is a class with its facts as class attributes and two class methods, ``supports``
and ``solve``. :data:`dumbbell.solvers.METHODS` maps each name to its class; adding a solver is
one module with one subclass, plus one line there. Solver modules import only light modules
at the top (numba kernels, pymunk and scipy are imported when a run needs them), so the
registry costs nothing to load.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from os import PathLike
from typing import Any, ClassVar

import numpy as np

from ..errors import UsageError
from ..model import args
from ..model.scene import Scene, System
from ..model.trajectory import Impact, Trajectory, Verdict
from .kernels import Params

#: Largest number of steps one run may take, so that no run can hang.
MAX_STEPS = 10**10
#: Impacts the root-searching (exact) solvers may locate in one run: each costs about
#: 0.2-0.8 ms here, so a run that reaches the budget ends (``failed``) within a minute or so.
MAX_IMPACTS = 100_000
#: Work their impact search may do in one run, in units of one interval split (a few us here);
#: a block of 64 intervals scanned at once counts :data:`BLOCK_WORK` (about 70 us). A stiff
#: spring or a fast spin makes the intervals short; a graze makes the splits deep.
MAX_SEARCH_WORK = 10_000_000
BLOCK_WORK = 10

__all__ = ["RunOptions", "Solver"]

#: Samples :func:`~dumbbell.solvers.simulate` keeps unless told otherwise (``max_samples``,
#: ``--max-samples``): 5e6 rows of about ten float64 columns are about 400 MB.
MAX_SAMPLES = 5_000_000


@dataclass(frozen=True)
class RunOptions:
    """Options of one run, as a solver's ``solve`` takes them (checked when built).

    Parameters
    ----------
    dt : float
        The step (s).
    t_end : float
        The run's end (s).
    every : int, default 1
        Keep every ``every``-th step as a sample.
    quiet : bool, default True
        No progress bar.

    Raises
    ------
    UsageError
        A field that is not allowed (the message names it and what is).

    Examples
    --------
    >>> from dumbbell.solvers import RunOptions
    >>> options = RunOptions(1e-3, 0.01, every=5)
    >>> options.n_steps, options.n_samples, options.sample_times()
    (10, 3, array([0.   , 0.005, 0.01 ]))
    >>> RunOptions(0.0, 1.0)
    Traceback (most recent call last):
    ...
    dumbbell.errors.UsageError: dt = 0.0: must be a finite number > 0 (s)
    """

    dt: float
    t_end: float
    every: int = 1
    quiet: bool = True

    def __post_init__(self) -> None:
        # What the package builds (checked floats and ints) passes this first test alone; a
        # value built by hand is looked at field by field, where a wrong one names itself.
        if (type(self.dt) is float and type(self.t_end) is float and type(self.every) is int
                and type(self.quiet) is bool and 0 < self.dt < math.inf
                and 0 < self.t_end < math.inf and self.every >= 1):
            return
        from ..model import args

        args.real(self.dt, "dt", "s")
        args.real(self.t_end, "t_end", "s")
        args.whole(self.every, "every", "steps")
        args.flag(self.quiet, "quiet")

    @property
    def n_steps(self) -> int:
        """Steps taken: round(t_end / dt)."""
        return round(self.t_end / self.dt)

    @property
    def n_samples(self) -> int:
        """Samples kept: steps 0, every, 2*every, ... up to n_steps."""
        return self.n_steps // self.every + 1

    def sample_times(self, count: int | None = None) -> np.ndarray:
        """Times of the samples: step * dt, with the step index j * every kept whole so every
        solver and every ``every`` share the same floats.

        Parameters
        ----------
        count : int or None, default None
            How many of the first samples (None: all).

        Returns
        -------
        numpy.ndarray
            The times (s).

        Raises
        ------
        UsageError
            A count that is not a whole number >= 0.
        """
        if count is not None and type(count) is not int:
            from ..model import args

            count = args.whole(count, "count", "samples", lo=0)
        if count is not None and count < 0:
            raise UsageError(f"count = {count}: must be a whole number >= 0 (samples)",
                             param="count")
        count = self.n_samples if count is None else count
        # The step indices j * every, made whole (one array), then times dt.
        steps = np.arange(0, count * self.every, self.every, dtype=np.int64)
        return steps * self.dt


#: The class methods of the contract whose arguments a call from outside has checked (the
#: scene, and for ``solve`` and ``check_work`` the RunOptions and the scene's support).
CHECKED = ("supports", "solve", "check_work", "truth_for", "catch_depth")


class Solver:
    """The contract of a solver. Subclasses set every attribute below and implement
    :meth:`supports` and :meth:`solve`; they are never instantiated (all is class-level). Like
    scipy's ``solve_ivp(method=)``, :func:`~dumbbell.solvers.simulate` and the analyses take
    such a class as well as a registered name, checked against this contract
    (:func:`contract_problems`).

    Facts (a test checks that every registered solver declares each one):

    - ``name``: what scenes, the CLI and the outputs call it;
    - ``order``: the order p of its position error in the step, error ~ dt^p (None without a
      step); bench fits the order it measures beside it and draws this slope;
    - ``has_step``: it advances by a fixed step ``dt`` (False: ``dt`` only spaces the samples);
    - ``step_limit``: the largest w*dt (w = sqrt(k/mu)) at which its spring step is stable: 2
      for an explicit step (Euler-Cromer, Verlet, pymunk), 2*sqrt(2) for classic Runge-Kutta;
      None where no step limits it. The stability theory, the verdicts' messages and the
      stability catalogue read it;
    - ``flip_floor``: its floor reverses velocities at impacts, so it cannot hold a particle in
      lasting contact (an inelastic floor ends the run as ``failed``);
    - ``relative_cost``: rough cost of one step (or one sample) against Euler-Cromer's, for
      scheduling work;
    - ``is_truth``: its error is far below any stepping solver's, so analysis may take it as the
      truth for scenes it supports (the first registered one that does);
    - ``estimates_error``: ``solve`` takes ``estimate_error=False`` to skip measuring its own
      error with a second, tighter run.

    A subclass writes :meth:`_supports` and :meth:`_solve` (and optionally
    :meth:`_check_work`, :meth:`_truth_for`, :meth:`_catch_depth`), as scipy's ``OdeSolver``
    subclasses write ``_step_impl``: the public methods (:data:`CHECKED`) check their
    arguments and call them; the package, which has checked them at its border, calls them
    directly (``cls._solve(scene, options)``).

    Examples
    --------
    The registered solvers are such classes, in :data:`dumbbell.solvers.METHODS`:

    >>> from dumbbell.solvers import METHODS, RunOptions
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> verlet = METHODS["verlet"]
    >>> verlet.name, verlet.order, verlet.step_limit, verlet.supports(scene)
    ('verlet', 2, 2.0, None)
    >>> verlet.solve(scene, RunOptions(1e-3, 0.01, every=5))
    <Trajectory textbook-1d: solver=verlet, dt=0.001 s, t=0..0.01 s, 3 samples, 0 impacts, verdict: ok>
    >>> verlet.swing(1.0)             # the largest energy swing of a stable run at w*dt = 1
    1.0
    >>> verlet.drift(1.0, 1000) is None           # a symplectic step: no steady drift
    True
    >>> exact = METHODS["exact"]
    >>> exact.truth_for(scene), verlet.truth_for(scene), exact.catch_depth(scene)
    (True, False, None)
    >>> METHODS["pymunk"].catch_depth(scene)          # m: its floor is a thick segment
    1.04
    >>> exact.check_work(scene, RunOptions(1e-3, 1e7))
    Traceback (most recent call last):
    ...
    dumbbell.errors.UsageError: t_end = 1e+07 s: the exact solution would locate at least ... impacts ...
    >>> verlet.warm_up() >= 0                         # s spent compiling or loading
    True
    """

    name: ClassVar[str]
    order: ClassVar[int | None]
    has_step: ClassVar[bool]
    step_limit: ClassVar[float | None]
    flip_floor: ClassVar[bool]
    relative_cost: ClassVar[float]
    is_truth: ClassVar[bool]
    estimates_error: ClassVar[bool]

    #: Every fact a solver must declare itself, with the types it may have.
    CAPABILITIES: ClassVar[dict[str, tuple[type, ...]]] = {
        "name": (str,), "order": (int, type(None)), "has_step": (bool,),
        "step_limit": (float, type(None)), "flip_floor": (bool,), "relative_cost": (float,),
        "is_truth": (bool,), "estimates_error": (bool,),
    }

    # The contract's methods, as scipy's OdeSolver.step calls the _step_impl its subclass
    # writes: each public one checks its arguments (the scene, or a scene file's path; for
    # solve and check_work also RunOptions and a scene the solver supports), then calls the
    # method of the same name with a leading underscore, which the subclass writes and the
    # package calls directly, having checked at its border.

    @classmethod
    def supports(cls, scene: Scene | str | PathLike) -> str | None:
        """Whether this solver can run a scene (the subclass's :meth:`_supports`, the scene
        checked first).

        Parameters
        ----------
        scene : Scene
            The scene (or a scene file's path).

        Returns
        -------
        str or None
            None if it can; else why not, in one sentence.
        """
        return cls._supports(_scene(scene))

    @classmethod
    def solve(cls, scene: Scene | str | PathLike, options: RunOptions, **keywords: Any
              ) -> Trajectory:
        """Run a scene (the subclass's :meth:`_solve`, the arguments checked first).

        Parameters
        ----------
        scene : Scene
            A scene this solver supports (or a scene file's path).
        options : RunOptions
            The step, the end, the samples kept.
        **keywords
            What the solver's own ``_solve`` takes besides (``estimate_error`` of the
            reference solver).

        Returns
        -------
        Trajectory
            The run; its ``verdict`` says how it ended.
        """
        scene = cls._runnable(scene, options)
        return cls._solve(scene, options, **keywords)

    @classmethod
    def check_work(cls, scene: Scene | str | PathLike, options: RunOptions) -> None:
        """Refuse, before any work, a run known to exceed this solver's work budget (the
        subclass's :meth:`_check_work`; the default: no such estimate). :meth:`solve` calls
        it first; callers that plan several runs call it for each before the first.

        Parameters
        ----------
        scene : Scene
            A scene this solver supports (or a scene file's path).
        options : RunOptions
            The run planned.

        Raises
        ------
        UsageError
            The run is past the budget; the message says what would do.
        """
        cls._check_work(cls._runnable(scene, options), options)

    @classmethod
    def truth_for(cls, scene: Scene | str | PathLike) -> bool:
        """Whether this (``is_truth``) solver is the truth for scenes of a scene's kind,
        whether or not it can run this one (the subclass's :meth:`_truth_for`).

        Parameters
        ----------
        scene
            As for :meth:`supports`.

        Returns
        -------
        bool
            False for every solver that is not a truth.
        """
        return cls._truth_for(_scene(scene))

    @classmethod
    def catch_depth(cls, scene: Scene | str | PathLike) -> float | None:
        """How far a particle may move in one step and still be caught by a floor that is a
        body of finite thickness (beyond it, it passes through); the subclass's
        :meth:`_catch_depth`.

        Parameters
        ----------
        scene : Scene
            The scene whose floor is asked about (or a scene file's path).

        Returns
        -------
        float or None
            The depth (m); None when the floor is not such a body.
        """
        return cls._catch_depth(_scene(scene))

    @classmethod
    def _runnable(cls, scene: Any, options: Any) -> Scene:
        """``scene`` checked, with ``options`` a RunOptions and a scene this solver runs."""
        from ..model import args

        scene = _scene(scene)
        args.instance(options, "options", RunOptions,
                      "RunOptions (from dumbbell.solvers.make_options)")
        reason = cls._supports(scene)
        if reason is not None:
            raise UsageError(f"scene = {scene.name}: {cls.name} cannot run it: {reason}",
                             param="scene")
        return scene

    # What a subclass writes: _supports and _solve (both required), and optionally the rest.

    @classmethod
    def _check_work(cls, scene: Scene, options: RunOptions) -> None:
        """The work budget's check as the subclass writes it (the default: none)."""

    @classmethod
    def _truth_for(cls, scene: Scene) -> bool:
        """Whether this solver is the truth for ``scene``'s kind, as written (default False)."""
        return False

    @classmethod
    def _catch_depth(cls, scene: Scene) -> float | None:
        """A floor's catch depth (m) as written (default None: no floor of finite thickness)."""
        return None

    @classmethod
    def swing(cls, ratio: float) -> float | None:
        """The largest relative swing of the vibration energy that a *stable* run of this
        solver makes at a given w*dt, for the verdict's message near the step limit.

        Parameters
        ----------
        ratio : float
            w*dt, w = sqrt(k/mu).

        Returns
        -------
        float or None
            The swing (relative); None where the theory gives no such bound (the default).
        """
        return None

    @classmethod
    def drift(cls, ratio: float, steps: float) -> float | None:
        """How far (relative) the vibration energy has moved after ``steps`` stable steps
        at w*dt = ``ratio``, for a step that loses or gains energy steadily rather than
        swinging about it (classic Runge-Kutta loses it: 1 - |R(i h)|^(2 steps)); None for a
        step that keeps it (the default). The accuracy theory reads it beside :meth:`swing`.

        Parameters
        ----------
        ratio : float
            w*dt, w = sqrt(k/mu).
        steps : float
            Stable steps taken.

        Returns
        -------
        float or None
            The drift (relative); None for a step that keeps the energy.
        """
        return None

    @classmethod
    def warm_up(cls) -> float:
        """Compile or load what the first run would.

        Returns
        -------
        float
            The seconds it took; NaN when there is nothing to compile (the default).
        """
        return math.nan


class ExplicitSpring:
    """The fact of an explicit, symplectic spring step (Euler-Cromer, Verlet, pymunk's
    impulse): stable iff w*dt < 2, and while stable the vibration energy swings by at most
    h/(2 - h) times itself at w*dt = h (a 19-fold swing at 1.9), without growing. A solver
    class lists it before its base class."""

    step_limit: ClassVar[float | None] = 2.0

    @classmethod
    def swing(cls, ratio: float) -> float | None:
        if type(ratio) is not float:
            from ..model import args

            ratio = args.real(ratio, "ratio", "1", lo=0.0)
        return ratio / (2.0 - ratio) if ratio < 2.0 else math.inf


class Truth(Solver):
    """The facts the truth solvers share (the exact solution, the reference integrator): no
    step (``dt`` only spaces the samples, so no order and no step limit), a floor that reverses
    velocities at impacts, and an error far below any stepping solver's, so that analysis may
    take them as the truth for the scenes they claim (:meth:`Solver.truth_for`)."""

    order = None
    has_step = False
    step_limit = None
    flip_floor = True
    is_truth = True


#: The registered solvers by name: :data:`dumbbell.solvers.METHODS` is this dict, filled
#: there; kept here so that the solvers' own modules can read it without importing the
#: package that imports them.
REGISTRY: dict[str, type[Solver]] = {}


def contract_problems(cls: Any) -> list[str]:
    """What keeps ``cls`` from being a solver: not a :class:`Solver` subclass, a fact left out
    or of the wrong type (:attr:`Solver.CAPABILITIES`) or out of its range, ``_supports`` or
    ``_solve`` not written, a public contract method written over the base's. Empty for a solver that keeps the contract."""
    if not (isinstance(cls, type) and issubclass(cls, Solver)) or cls is Solver:
        return ["not a subclass of dumbbell.solvers.Solver"]
    problems = []
    for fact, kinds in Solver.CAPABILITIES.items():
        value = getattr(cls, fact, _MISSING)
        if value is _MISSING:
            problems.append(f"{fact} is not declared")
        elif isinstance(value, bool) and bool not in kinds or not isinstance(value, kinds):
            problems.append(f"{fact} = {value!r} must be {' or '.join(k.__name__ for k in kinds)}")
    problems += [] if problems else _range_problems(cls)
    problems += [f"{method} is not written" for method in ("_supports", "_solve")
                 if not hasattr(cls, method)]
    problems += [f"{name} is written in place of _{name} (Solver.{name} checks the arguments "
                 f"and calls _{name})" for name in CHECKED
                 if any(name in vars(k) for k in cls.__mro__[:cls.__mro__.index(Solver)])]
    return problems


def _range_problems(cls: type[Solver]) -> list[str]:
    """The facts of ``cls`` (each of the right type) that are out of their range."""
    checks = [
        (bool(cls.name), "name is empty"),
        (cls.order is None or cls.order >= 1, f"order = {cls.order} must be >= 1 or None"),
        (cls.step_limit is None or 0 < cls.step_limit < math.inf,
         f"step_limit = {cls.step_limit} must be > 0 and finite, or None"),
        (cls.has_step or (cls.order is None and cls.step_limit is None),
         "a solver without a step has no order and no step limit"),
        (cls.relative_cost > 0, f"relative_cost = {cls.relative_cost} must be > 0"),
    ]
    return [problem for fine, problem in checks if not fine]


_MISSING = object()


class OverBudget(Exception):
    """A run reached its work budget (:class:`SearchBudget`); the solver turns it into the
    verdict ``failed`` with this message as the reason."""


class SearchBudget:
    """Counts the work of one run's impact search (blocks scanned, intervals split) and
    raises :class:`OverBudget` past ``limit`` units (default :data:`MAX_SEARCH_WORK`), so
    that no search can hang."""

    def __init__(self, limit: int | None = None):
        self.limit = MAX_SEARCH_WORK if limit is None else limit
        self.work = 0

    def spend(self, units: int = 1) -> None:
        self.work += units
        if self.work > self.limit:
            raise OverBudget(
                f"the impact search's budget was reached: {self.limit:,} units of work (a "
                f"split interval is 1, a block of 64 scanned intervals {BLOCK_WORK}; a stiff "
                "spring or a fast spin makes intervals short); a shorter t_end fits")


def within_budget(search: Callable[[list[Any], list[Impact]], tuple[list[Any], list[Impact],
                                                                    Verdict]],
                  start_time: Callable[[Any], float]) -> tuple[list[Any], list[Impact], Verdict]:
    """Run an impact search ``search(segments, impacts)``, which fills both lists as it goes
    and returns them with its verdict. When it reaches its work budget (:class:`OverBudget`),
    what it found so far is kept and the verdict is ``failed`` at the start of the last
    segment (``start_time(segment)``, s), with the budget's message as the reason."""
    segments: list[Any] = []
    impacts: list[Impact] = []
    try:
        return search(segments, impacts)
    except OverBudget as exc:
        return segments, impacts, Verdict("failed", start_time(segments[-1]), str(exc))


def impact_budget_reason(count: int) -> str:
    """The reason of a run stopped at :data:`MAX_IMPACTS`-like ``count`` impacts."""
    return (f"the impact budget was reached: {count:,} impacts located, the most one run may "
            "locate; a shorter t_end fits")


def min_impacts(scene: Scene, t_end: float, vertical_energy: float) -> tuple[float, float]:
    """(a lower bound on the impacts of ``scene`` in [0, ``t_end``] (s), the longest gap
    between two (s)); (0, inf) where no bound holds. With an elastic floor (e = 1) and
    gravity g the vertical energy E (J; ``vertical_energy``: vertical kinetic, potential
    above the floor, internal) is conserved, so (1/2) V^2 + g Y <= E / M for the centre of
    mass, which falls freely between impacts; an end is at or below the floor by the time Y
    reaches it, so no gap between impacts lasts longer than 2 sqrt(2 E / M) / g. No bound is
    claimed for e < 1: a run can end early, at rest."""
    system = scene.system
    if system.floor is None or system.floor.elasticity < 1 or not system.g > 0:
        return 0.0, math.inf
    gap = 2.0 * math.sqrt(2.0 * max(vertical_energy, 0.0) / system.M) / system.g
    return (math.floor(t_end / gap) if gap > 0 and math.isfinite(t_end / gap) else math.inf,
            gap)


def check_impacts(scene: Scene, options: RunOptions, vertical_energy: float,
                  limit: int) -> None:
    """UsageError when a run of ``scene`` over ``options.t_end`` (s) must locate more than
    ``limit`` impacts by :func:`min_impacts`."""
    count, gap = min_impacts(scene, options.t_end, vertical_energy)
    if count <= limit:
        return
    shown = f"{count:,}" if math.isfinite(count) else "more than 1e308"
    raise UsageError(
        f"t_end = {options.t_end:g} s: the exact solution would locate at least {shown} "
        f"impacts (on this elastic floor the centre of mass stays at most {gap:.3g} s in the "
        f"air between two), past the budget of {limit:,} per run", param="t_end",
        fixes=("lower {t_end}",))

def _scene(scene: Any) -> Scene:
    """``scene`` checked: a Scene, or a scene file's path loaded."""
    from ..model import args

    return args.scene(scene)


def kernel_params(system: System, dt: float) -> Params:
    """The record of scalars a compiled time-stepper reads: the step ``dt`` (s) and the
    system's masses (kg), spring (N/m, m), gravity (m/s^2), elasticity, floor and radii (m),
    as floats, so a scene's integers do not compile a second kernel."""
    A, B = system.A, system.B
    return Params(float(dt), float(A.mass), float(B.mass), float(system.k), float(system.b),
                  float(system.g), float(system.elasticity), system.floor is not None,
                  float(A.radius), float(B.radius))


def point_particle_limits(scene: Scene, name: str) -> str | None:
    """Why a hand-written 2D solver of two point particles, a spring and a frictionless floor
    cannot run ``scene``, or None if it can."""
    if scene.system.rigid is not None:
        return f"{name} handles two particles and a spring, not a rigid body"
    if scene.system.floor is not None and scene.system.floor.friction > 0:
        return f"{name} has a frictionless floor only; use pymunk for friction"
    if scene.system.discs:
        return f"{name} has point particles (no spin); use pymunk for spinning particles"
    return None


def make_options(
    scene: Scene, dt: float | None = None, t_end: float | None = None, every: int | None = None,
    max_samples: int | None = None,
) -> RunOptions:
    """Fill (quiet) run options from the scene's ``[run]`` table and check them (UsageError):
    ``dt`` and ``t_end`` in s, ``every`` in steps (each checked if given; None: the scene's).
    The step count is checked against :data:`MAX_STEPS` and, when ``max_samples`` is given,
    the samples kept against it, both as exact integers before anything is allocated."""
    from ..model import args

    return scene_options(args.scene(scene), dt, t_end, every, max_samples)


def scene_options(scene: Scene, dt: float | None = None, t_end: float | None = None,
                  every: int | None = None, max_samples: int | None = None) -> RunOptions:
    """:func:`make_options` of a Scene (checked already, when it was read)."""
    from ..model import args

    if dt is not None:
        dt = args.real(dt, "dt", "s")
    if t_end is not None:
        t_end = args.real(t_end, "t_end", "s")
    if every is not None:
        every = args.whole(every, "every", "steps", hi=MAX_STEPS)
    options = run_options(scene, dt, t_end, every)
    if max_samples is not None:
        # The default needs no check (simulate's budget, MAX_SAMPLES).
        budget = (max_samples if max_samples is MAX_SAMPLES
                  else args.whole(max_samples, "max_samples", "samples"))
        check_samples(scene, options, budget)
    return options


def run_options(scene: Scene, dt: float | None = None, t_end: float | None = None,
                every: int | None = None) -> RunOptions:
    """The (quiet) run options of ``scene`` with the values given, checked already (None:
    the scene's ``[run]``): UsageError when ``dt`` passes ``t_end`` or the run would take
    more than :data:`MAX_STEPS` steps, counted before anything is allocated."""
    dt = scene.run.dt if dt is None else float(dt)
    t_end = scene.run.t_end if t_end is None else float(t_end)
    every = scene.run.every if every is None else int(every)
    if dt > t_end:
        raise UsageError(f"dt = {dt:g}: must be <= t_end = {t_end:g} (s)", param="dt")
    if every > MAX_STEPS:
        raise UsageError(f"every = {args.show(every)}: must be a whole number from 1 to "
                         f"{MAX_STEPS:,} (steps)", param="every")
    ratio = t_end / dt  # a float; inf when the quotient passes the largest float
    if not ratio <= MAX_STEPS:
        count = f"{round(ratio):,} steps" if math.isfinite(ratio) else "more than 1e308 steps"
        raise UsageError(f"t_end / dt = {t_end:g} s / {dt:g} s = {count}: a run may take at "
                         f"most {MAX_STEPS:,} steps", fixes=("raise {dt}", "lower {t_end}"))
    return RunOptions(dt, t_end, every, True)


def check_samples(scene: Scene, options: RunOptions, max_samples: int) -> None:
    """UsageError when ``options`` would keep more than ``max_samples`` samples: the count is
    exact integer arithmetic on the run options, so the refusal costs no time or memory."""
    samples = options.n_samples
    if samples <= max_samples:
        return
    from ..model.energy import energy_columns, state_columns

    columns = 1 + len(state_columns(scene)) + len(energy_columns(scene))
    size = samples * columns * 8  # float64 columns: t, the state, the energy terms
    raise UsageError(
        f"{options.n_steps:,} steps with every = {options.every:,} would keep "
        f"{samples:,} samples (about {_bytes(size)} in memory), past the budget of "
        f"{max_samples:,}",
        fixes=("keep fewer with a larger {every}", "raise the budget {max_samples}"))


def _bytes(size: int) -> str:
    """``size`` bytes in words: '8.0 GB'."""
    for unit, scale in (("TB", 10**12), ("GB", 10**9), ("MB", 10**6), ("kB", 10**3)):
        if size >= scale:
            return f"{size / scale:.1f} {unit}"
    return f"{size} B"
