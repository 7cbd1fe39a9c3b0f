"""The stability report: extreme scenes run by every solver, each result beside the theory.

>>> rows = run_cases(find_cases(default_cases()), None)       # doctest: +SKIP
>>> print(dumbbell.io.stability.markdown(StabilityResult(tuple(rows))))  # doctest: +SKIP

Theory (docs/physics.md: the stability limit, how pymunk collides), which :func:`predict` turns into an expected verdict:

- a solver's spring step is stable iff w*dt is below its ``step_limit``, with w = sqrt(k/mu):
  2 for the explicit step of Euler-Cromer, Verlet and pymunk, 2 sqrt(2) for classic
  Runge-Kutta; the exact and reference solutions take no such step;
- pymunk finds a contact only once shapes overlap, so a particle that moves farther in one
  step at impact than the floor's box is thick plus its own diameter passes through it;
- on an inelastic floor a bouncing point mass comes to rest after
  sqrt(2 h/g) (1 + e)/(1 - e), after infinitely many impacts: solvers that model impacts as
  velocity flips (exact, Euler-Cromer, Verlet, the reference) must stop there with
  ``failed``; pymunk holds resting contact.

Which rule applies to a solver is its own declaration (``step_limit``, ``flip_floor``,
``catch_depth`` on its class in :mod:`dumbbell.solvers`), not a list here; so the catalogue
runs a solver class written outside the package as it runs the registered ones.

The stability map runs a grid over (w*dt, mass ratio) for each time-stepping solver with no
floor and no gravity, so only the spring's limit counts.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import DumbbellError, UsageError
from ..model import args
from ..model.scene import Scene, load_scene, scene_from_dict, scenes_dir
from ..parallel import Backend, ordered_map
from ..solvers import Solver, solver_class, solver_classes
from ._fields import check

if TYPE_CHECKING:
    import pandas

    from .sweep import PointResult

__all__ = ["StabilityResult", "StabilityRow"]

#: :attr:`StabilityRow.agreement` when the verdict is the one the theory expects; any other
#: value says what differs.
AGREES = "agrees"
#: The stability map: w*dt values, mass ratios mB/mA, and steps per run.
MAP_WDT = tuple(round(0.05 + 0.1 * i, 2) for i in range(30))
MAP_RATIOS = tuple(float(10 ** (i / 2)) for i in range(9))
MAP_STEPS = 2000
#: Energy error that counts as a blow-up on the map: far above the bounded swing h/(2-h) of
#: a stable step (19 at w*dt = 1.9), far below what a run past w*dt = 2 reaches.
MAP_UNSTABLE_ENERGY = 1e3


#: Units of :data:`COLUMNS` ("1": dimensionless; "" for names and text).
UNITS = {"case": "", "title": "", "solver": "", "dt": "s", "w_dt": "1", "verdict": "",
         "t_fail": "s", "max_rel_energy_error": "1", "inaccurate_energy": "1",
         "dissipative": "", "predicted": "", "agreement": "", "reason": "", "theory": "",
         "wall_s": "s"}


@dataclass(frozen=True)
class StabilityRow:
    """One (case, solver) run beside the theory: one line of stability.csv, the fields in
    column order (units in :data:`UNITS`). ``inaccurate_energy`` is the case's threshold
    (``run.inaccurate_energy``): a run that stays stable is ``ok`` within it and
    ``inaccurate`` past it, dated (``t_fail``) where its energy error first passed it.

    Parameters
    ----------
    case, title : str
        The case's name and its scene's title.
    solver : str
        The solver.
    dt, w_dt : float
        The step (s) and w*dt.
    verdict : str
        How the run ended.
    t_fail : float or None
        When it failed (s).
    max_rel_energy_error : float
        The largest relative energy error.
    inaccurate_energy : float
        The case's threshold.
    dissipative : bool
        Whether the scene loses energy.
    predicted : str
        The theory's verdict.
    agreement : str
        Whether the run agrees with it.
    reason : str
        The verdict's reason.
    theory : str
        The theory's reason.
    wall_s : float
        The run time (s).

    Examples
    --------
    One case of the shipped catalogue, just past the explicit step's limit w·dt = 2:

    >>> import shutil
    >>> from pathlib import Path
    >>> import dumbbell
    >>> from dumbbell.analysis.stability import default_cases
    >>> Path("cases").mkdir()
    >>> _ = shutil.copy(default_cases() / "stiff-wdt-2.1.toml", "cases")
    >>> row = dumbbell.stability("cases", solvers=["verlet"], workers=1).rows[0]
    >>> row.case, row.verdict, row.predicted, round(row.w_dt, 2)
    ('stiff-wdt-2.1', 'unstable', 'unstable', 2.1)
    """

    case: str
    title: str
    solver: str
    dt: float
    w_dt: float
    verdict: str
    t_fail: float | None
    max_rel_energy_error: float
    inaccurate_energy: float
    dissipative: bool
    predicted: str
    agreement: str
    reason: str
    theory: str
    wall_s: float

    @property
    def agrees(self) -> bool:
        """Whether the verdict is the one the theory expects."""
        return self.agreement == AGREES


#: Report columns, in CSV order: the fields of :class:`StabilityRow`.
COLUMNS = tuple(f.name for f in fields(StabilityRow))


@dataclass(frozen=True)
class StabilityResult:
    """The catalogue's report: one row per (case, solver) run, and the pairs not run because
    the solver cannot run the scene.

    What :func:`dumbbell.stability` returns.

    Parameters
    ----------
    rows : tuple of StabilityRow
        One per run.
    skipped : tuple of str, default ()
        The pairs not run, and why.
    guard : tuple of str, default ()
        What the step-size guard said about the pymunk runs.

    Examples
    --------
    The shipped case just inside the limit (w·dt = 1.9): stable, but its energy error past
    the case's bound, as the theory expects.

    >>> import shutil
    >>> from pathlib import Path
    >>> import dumbbell
    >>> from dumbbell.analysis.stability import default_cases
    >>> inside = Path("inside")
    >>> inside.mkdir()
    >>> _ = shutil.copy(default_cases() / "stiff-wdt-1.9.toml", inside)
    >>> result = dumbbell.stability("inside", solvers=["euler-cromer", "verlet"], workers=1)
    >>> result.to_pandas()[["case", "solver", "verdict", "agreement"]].values.tolist()
    [['stiff-wdt-1.9', 'euler-cromer', 'inaccurate', 'agrees'], ['stiff-wdt-1.9', 'verlet', 'inaccurate', 'agrees']]
    """

    rows: tuple[StabilityRow, ...]
    skipped: tuple[str, ...] = ()
    guard: tuple[str, ...] = ()

    def __repr__(self) -> str:
        """One line: runs, cases, and which runs disagree with the theory."""
        from .._display import counted, one_line

        bad = self.disagreements
        which = "; ".join(f"{r.case} {r.solver}" for r in bad)
        return one_line(f"<StabilityResult: {counted(len(self.rows), 'run')} of "
                        f"{counted(len({r.case for r in self.rows}), 'case')}, "
                        f"{len(self.rows) - len(bad)} agree with the theory, {len(bad)} "
                        f"disagree{' (' + which + ')' if bad else ''}>")

    def _repr_html_(self) -> str:
        """The one-line summary above one row per run (dt in s)."""
        from .._display import html_table

        head = ["case", "solver", "dt (s)", "w*dt", "verdict", "t_fail (s)",
                "largest rel. energy error", "theory expects", "agreement"]
        rows = [(r.case, r.solver, r.dt, r.w_dt, r.verdict, r.t_fail, r.max_rel_energy_error,
                 r.predicted, r.agreement) for r in self.rows]
        return html_table(repr(self), head, rows, [f"not run: {s}" for s in self.skipped])

    @property
    def disagreements(self) -> list[StabilityRow]:
        """The runs whose verdict is not the one the theory expects."""
        return [r for r in self.rows if not r.agrees]

    def to_pandas(self) -> pandas.DataFrame:
        """One row per run with the CSV's columns, units in ``df.attrs["units"]``. Needs
        pip install 'dumbbell[pandas]'.

        Returns
        -------
        pandas.DataFrame
            The fields of :class:`StabilityRow`.

        Raises
        ------
        MissingExtraError
            pandas is not installed.
        """
        from ..frames import data_frame

        return data_frame({c: [getattr(r, c) for r in self.rows] for c in COLUMNS},
                          units=UNITS)


@dataclass(frozen=True)
class Prediction:
    """The verdict theory expects, and why in words."""

    status: str
    why: str


def default_cases() -> Path:
    """The shipped catalogue of extreme scenes."""
    return scenes_dir() / "extreme"


def find_cases(folder: str | Path) -> list[Path]:
    """The scene files in ``folder``, sorted by name (UsageError if there are none)."""
    folder = args.path(folder, "folder")
    if not os.path.isdir(folder):  # False for any error too (a name too long, a loop)
        raise UsageError(f"cases {args.show_path(folder)}: no such folder", param="cases")
    paths = sorted(folder.glob("*.toml"))
    if not paths:
        raise UsageError(f"cases {args.show_path(folder)}: no scene files (*.toml) in it",
                         param="cases")
    return paths


def default_solvers(scene: Scene) -> list[str]:
    """Solvers run on a case by default: all that can run it, but of the truth solvers only
    the scene's own (the exact solution in 1D, not the slow reference)."""
    return [cls.name for cls in _default_solvers(args.scene(scene))]


def _default_solvers(scene: Scene) -> list[type[Solver]]:
    from ..solvers import supporting, truth_class

    truth = truth_class(scene)
    return [cls for cls in supporting(scene) if not cls.is_truth or cls is truth]


def _impact_speed(scene: Scene) -> float:
    """Speed (m/s) at which the lower particle meets the floor, as a point falling from its
    height with its starting vertical velocity (the spring's vibration is left out)."""
    low = min((scene.system.A, scene.system.B), key=lambda p: p.height)
    return math.sqrt(low.vy**2 + 2.0 * scene.system.g * max(low.height, 0.0))


def rest_time(scene: Scene) -> float:
    """When a point mass dropped like the lower particle comes to rest on an inelastic floor:
    t1 + 2 e v1 / (g (1 - e)) (s); inf on an elastic floor or without gravity."""
    scene = args.scene(scene)
    if scene.system.floor is None or scene.system.g <= 0 or scene.system.floor.elasticity >= 1.0:
        return math.inf
    low = min((scene.system.A, scene.system.B), key=lambda p: p.height)
    v1 = _impact_speed(scene)
    t1 = (low.vy + v1) / scene.system.g
    e = scene.system.floor.elasticity
    return t1 + 2.0 * e * v1 / (scene.system.g * (1.0 - e))


def predict(scene: Scene, solver: str | type[Solver], dt: float, t_end: float) -> Prediction:
    """The verdict theory expects for ``scene`` run by ``solver`` (a name or a Solver class)
    at step ``dt`` up to ``t_end`` (s); see the module docstring."""
    return _predict(args.scene(scene), solver_class(solver), args.real(dt, "dt", "s"),
                    args.real(t_end, "t_end", "s"))


def _predict(scene: Scene, cls: type[Solver], dt: float, t_end: float) -> Prediction:
    w_dt = scene.system.omega * dt
    limit = cls.step_limit if scene.system.spring is not None else None
    if limit is not None and w_dt >= limit:
        return Prediction("unstable", f"w*dt = {w_dt:.2f} >= {limit:.3g}")
    reach = cls._catch_depth(scene)
    if reach is not None and scene.system.floor is not None and scene.system.g > 0:
        v = _impact_speed(scene)
        if v * dt > reach:
            return Prediction("tunnelled", f"moves {v * dt:.3g} m per step at impact "
                                           f"({v:.3g} m/s), more than the floor box and a "
                                           f"diameter, {reach:.3g} m")
    t_rest = rest_time(scene)
    if cls.flip_floor and t_rest < t_end:
        return Prediction("failed", f"a point mass comes to rest at {t_rest:.2f} s "
                                    f"< t_end = {t_end:g} s")
    if limit is not None:
        swing = _swing_share(scene, cls, w_dt)
        if swing is not None and swing > scene.run.unstable_energy:
            return Prediction("unstable", (
                f"w*dt = {w_dt:.2g} < {limit:.3g}: stable, but the step moves the energy by "
                f"up to {swing:.3g} of its scale > run.unstable_energy = "
                f"{scene.run.unstable_energy:g}"))
        if swing is not None and swing > scene.run.inaccurate_energy:
            return Prediction("inaccurate", (
                f"w*dt = {w_dt:.2g} < {limit:.3g}: stable, but the step moves the energy by "
                f"up to {swing:.3g} of its scale > run.inaccurate_energy = "
                f"{scene.run.inaccurate_energy:g}"))
        return Prediction("ok", f"w*dt = {w_dt:.2g} < {limit:.3g}")
    return Prediction("ok", "no step limit applies")


def _swing_share(scene: Scene, cls: type[Solver], w_dt: float) -> float | None:
    """How far (relative to the energy scale) a stable run of ``cls`` at ``w_dt`` moves the
    energy of a scene where only the spring acts (no floor, no gravity), whose vibration
    energy then stays what it was at the start: the solver's swing or drift over the run
    (:func:`dumbbell.solvers.advice.step_error`) times the vibration's share of the scale.
    None where the theory says nothing of the accuracy (a floor or gravity feeds energy into
    and out of the vibration) or the solver states neither."""
    from ..solvers.advice import step_error

    if scene.system.floor is not None or scene.system.g != 0 or not w_dt > 0:
        return None
    swing = step_error(cls, w_dt, scene.system.omega * scene.run.t_end)
    if swing is None:
        return None
    import numpy as np

    from ..model.energy import _partition, _start_scale, state_columns
    from ..solvers.stepping import initial_state

    state = {c: np.array([v]) for c, v in zip(state_columns(scene), initial_state(scene),
                                               strict=True)}
    if scene.system.discs:
        state |= {"omegaA": np.array([scene.system.A.spin]),
                  "omegaB": np.array([scene.system.B.spin])}
    energy = _partition(scene, np.zeros(1), state)
    vibration = sum(float(energy[c][0]) for c in ("K_int", "K_vib", "U_spring") if c in energy)
    return swing * vibration / _start_scale(energy, scene.system)


def run_case(path: str, cls: type[Solver]) -> StabilityRow:
    """Run one case with the solver ``cls`` and put the result beside the theory (one
    report row)."""
    from .sweep import _evaluate

    scene = load_scene(path)
    t0 = time.perf_counter()
    result = _evaluate(scene, {}, cls)
    wall = time.perf_counter() - t0
    expected = _predict(scene, cls, scene.run.dt, scene.run.t_end)
    if result.verdict == expected.status:
        agreement = AGREES
    else:
        agreement = f"DISAGREES: theory expects {expected.status}, got {result.verdict}"
    return StabilityRow(case=scene.name, title=scene.title, solver=cls.name, dt=scene.run.dt,
                        w_dt=result.w_dt, verdict=result.verdict,
                        t_fail=result.t_fail,
                        max_rel_energy_error=result.max_rel_energy_error,
                        inaccurate_energy=scene.run.inaccurate_energy,
                        dissipative=scene.system.dissipative, predicted=expected.status,
                        agreement=agreement, reason=result.reason, theory=expected.why,
                        wall_s=wall)


#: One run of the catalogue: a case's path and the solver that runs it.
Run = tuple[str, type[Solver]]


def plan_cases(paths: list[Path], solvers: list[type[Solver]] | None
               ) -> tuple[list[Run], list[str]]:
    """The (case, solver) runs to make, every scene validated first, and the pairs skipped
    (with why). ``solvers`` (names or classes) None means :func:`default_solvers` per
    case."""
    from ..solvers.base import run_options

    solvers = solver_classes(solvers)
    runs, skipped, steps = [], [], 0
    for path in paths:
        scene = load_scene(path)
        try:
            run_options(scene)  # the step cap, before any case runs
        except DumbbellError as exc:
            fixes = exc.fixes if isinstance(exc, UsageError) else ()
            raise UsageError(f"{path}: {getattr(exc, 'reason', exc)}", fixes=fixes).named(
                {"dt": "run.dt", "t_end": "run.t_end"}) from None
        for cls in _default_solvers(scene) if solvers is None else solvers:
            reason = cls._supports(scene)
            if reason is None:
                runs.append((str(path), cls))
                steps += run_options(scene).n_steps
            else:
                skipped.append(f"{scene.name} with {cls.name}: {reason}")
    from .budget import check_runs, check_steps

    fixes = ["fewer scene files in {cases}"] + (["fewer {solvers}"] if solvers and
                                                len(solvers) > 1 else [])
    check_runs(len(runs), f"{len(paths)} cases x their solvers", fixes)
    check_steps(steps, f"the {len(runs)} runs of {len(paths)} cases", fixes)
    return runs, skipped


def run_cases(runs: list[Run], workers: int | None = None, quiet: bool = True
              ) -> list[StabilityRow]:
    """Every (case path, solver) run as a report row, in the given order."""
    workers = workers or os.cpu_count() or 1
    # The longest runs first keep the pool busy to the end; results keep the given order.
    cost = [_cost(*run) for run in runs]
    order = sorted(range(len(runs)), key=lambda i: -cost[i])
    done = ordered_map(run_case, [runs[i] for i in order],
                       Backend(workers, quiet=quiet, desc="stability cases"))
    results: list[StabilityRow | None] = [None] * len(runs)
    for i, row in zip(order, done, strict=True):
        results[i] = row
    return [r for r in results if r is not None]


def _cost(path: str, cls: type[Solver]) -> float:
    """A rough cost of one run: its steps, weighted by how slow the solver's step is."""
    scene = load_scene(path)
    return scene.run.t_end / scene.run.dt * cls.relative_cost


def guard_lines(runs: list[Run]) -> list[str]:
    """What the step-size guard (:func:`dumbbell.spaces.check`, stability only: no energy
    swing tolerance) says about each case run by pymunk, on the space the solver builds, at
    the case's dt: its findings and the sub-steps that clear them, or that it finds
    nothing."""
    import math

    from ..solvers.engine import build
    from ..spaces.guard import check, substeps

    lines = []
    for path in sorted({p for p, cls in runs if cls.name == "pymunk"}):
        scene = load_scene(path)
        space = build(scene).space
        dt = scene.run.dt
        found = check(space, dt, tolerance=math.inf)
        if not found:
            lines.append(f"- {scene.name} (dt = {dt:g} s): nothing to fix")
            continue
        what = "; ".join(f"{f.kind} {f.subject} {f.value:.3g} > {f.limit:.3g}" for f in found)
        n = substeps(space, dt, tolerance=math.inf)
        fix = (f"{n} sub-steps (dt = {dt / n:.3g} s) clear it" if n > 1
               else "settings, not the step: " + "; ".join(f.fix for f in found))
        lines.append(f"- {scene.name} (dt = {dt:g} s): {what}; {fix}")
    return lines


# --- the stability map ----------------------------------------------------------------------


def map_scene() -> Scene:
    """The map's base scene: k = 200 N/m, mB = 0.1 kg, the spring 1 cm stretched, no floor,
    no gravity, so only the spring's step limit counts."""
    return scene_from_dict({
        "title": "stability map",
        "bodies": {"A": {"mass": 0.1, "height": 1.21}, "B": {"mass": 0.1, "height": 1.0}},
        "spring": {"stiffness": 200.0, "rest_length": 0.2},
        "run": {"t_end": 1.0, "dt": 1e-3, "unstable_energy": MAP_UNSTABLE_ENERGY},
    }, source="stability-map.toml")


def map_points(scene: Scene) -> list[Any]:
    """The map's grid points, w*dt outer and mass ratio mB/mA inner: A's mass, dt = (w*dt)/w
    and t_end = MAP_STEPS * dt."""
    from .sweep import Point

    points = []
    for h in MAP_WDT:
        for ratio in MAP_RATIOS:
            mA = scene.system.B.mass / ratio
            mu = mA * scene.system.B.mass / (mA + scene.system.B.mass)
            dt = h / math.sqrt(scene.system.spring.stiffness / mu)  # type: ignore[union-attr]
            points.append(Point(len(points), {"bodies.A.mass": mA, "run.dt": dt,
                                              "run.t_end": MAP_STEPS * dt}))
    return points


def map_rows(solver: str | type[Solver], workers: int | None = None, quiet: bool = True
             ) -> list[PointResult]:
    """The map's rows for one solver (a name or a class), in grid order."""
    cls = solver_class(solver)
    workers = None if workers is None else args.whole(workers, "workers", "processes")
    quiet = args.flag(quiet, "quiet")
    return _map_rows(cls, workers, quiet)


def _map_rows(cls: type[Solver], workers: int | None, quiet: bool) -> list[PointResult]:
    from .sweep import _evaluate, warm_up

    scene = map_scene()
    points = map_points(scene)
    return ordered_map(_evaluate, [(p.values, cls) for p in points],
                       Backend(workers or os.cpu_count() or 1, initializer=warm_up,
                               initargs=(cls,), quiet=quiet,
                               desc=f"stability map {cls.name}"), shared=scene)


def map_solvers(solvers: list[str | type[Solver]] | None) -> list[type[Solver]]:
    """The time-stepping solvers a map is drawn for: those asked for (names or classes; all
    registered ones by default) whose spring step has a limit and that can run the 1D map
    scene."""
    from ..solvers import METHODS

    classes = solver_classes(solvers) or list(METHODS.values())
    scene = map_scene()
    return [cls for cls in classes if cls.step_limit is not None and cls._supports(scene) is None]


@dataclass(frozen=True)
class StabilityOptions:
    """What :func:`run_stability` runs: the scenes in the folder ``cases`` (None: the
    shipped catalogue), with ``solvers`` (names or Solver classes; None: every solver that
    can run each case), on ``workers`` local processes (None: one per CPU), quietly or with
    a progress bar."""

    cases: Path | None = None
    solvers: tuple[type[Solver], ...] | None = None
    workers: int | None = None
    quiet: bool = True

    def __post_init__(self) -> None:
        check(self, {"cases": "path?", "solvers": "solvers", "workers": "workers?",
                     "quiet": "flag"})


def run_stability(options: StabilityOptions) -> StabilityResult:
    """Run every case of ``options`` with its solvers and put each verdict beside the
    theory's. Everything is validated before anything runs; nothing is written."""
    options = args.instance(options, "options", StabilityOptions, "StabilityOptions")
    runs, skipped = plan_runs(options)
    return StabilityResult(tuple(run_cases(runs, options.workers, options.quiet)),
                           tuple(skipped), tuple(guard_lines(runs)))


def plan_runs(options: StabilityOptions) -> tuple[list[Run], list[str]]:
    """:func:`plan_cases` for the folder ``options.cases`` (default: the catalogue) and
    ``options.solvers``; at least one run."""
    runs, skipped = plan_cases(find_cases(options.cases if options.cases is not None
                                          else default_cases()), options.solvers)
    if not runs:
        raise UsageError("solvers: none of them can run any of the cases", param="solvers")
    return runs, skipped
