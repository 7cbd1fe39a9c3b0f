"""Work-precision benchmarks: error against run time, one line per solver, a point per step.

The convention of DiffEqDevTools and REBOUND (docs/measurements.md):

- every solver runs the scene over its whole ``t_end`` at each step size ``dt``, keeping a
  sample every ``every = max(1, round(spacing / dt))`` steps; the spacing is SAMPLE_SPACING
  (1 ms, the textbook run's output), or 1/50 of the spring's period if that is shorter, so
  the largest error between samples is not missed (on the textbook scene the errors at 1 ms
  and at 0.1 ms spacing agree to 0.4%);
- the truth is evaluated at the same sample times: the ``exact`` solver in 1D and for the rigid
  2D dumbbell (closed-form flight), the ``reference`` solver for a 2D spring (whose own error
  estimate is reported with it);
- ``error`` is the largest position error of either particle over the window [0, T] (m): the
  motion is chaotic, so a trajectory error means something only before the divergence;
  ``energy_error`` the largest relative energy error over the whole run (for a dissipative
  scene: of E against the truth's E); ``impact_time_error`` the largest |t_i - t_i(truth)| over
  the truth's impacts before T, paired in order (inf if the solver's sequence differs there);
- ``seconds`` is the minimum, ``seconds_median`` the median of ``repeat`` runs after a warm-up
  run (the warm-up run gives the diagnostics; the runs are deterministic); runs that take
  less than MIN_TIMED s together are repeated until they do (at most MAX_REPEAT times), and
  the ``repeat`` column says how many were timed. The time is the
  solver's own clock, ``Trajectory.wall_time``, which covers the integration and the impact
  list but not the array set-up, the verdict or the energy partition (euler-cromer, verlet,
  euler-cromer-2d: the compiled loop; pymunk: the stepping loop and the reads of the bodies;
  exact: the impact search and the evaluation at the samples; reference: the integration, not
  its error-estimating second run, which the timed runs skip); ``seconds_call``, the minimum
  of the whole ``solve`` call including the verdict, is reported beside it.
  ``compile_seconds`` is the solver's ``warm_up()`` (numba compile, or load from its cache);
- a run that blows up or tunnels stays in the table with its verdict and an infinite error;
- a step whose estimated cost (steps times the cost per step measured at the previous,
  larger step) passes ``budget`` for all its runs is skipped and listed as ``skipped``.

The truth is also a point of its own: its cost for the same samples, and its error against a
tighter evaluation (exact: the same closed form in 80-bit extended precision with the impact
times refined by Newton's method there; reference: its own estimate).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from .._display import counted
from ..errors import UsageError
from ..model import args
from ..model.scene import Scene
from ..model.trajectory import Trajectory
from ..solvers import (
    MAX_SAMPLES,
    RunOptions,
    Solver,
    supporting,
    truth_class,
)
from ..solvers.base import run_options
from ._fields import check
from .bench_result import (  # noqa: F401 - the results' records and constants, re-exported
    CSV_COLUMNS,
    CSV_UNITS,
    DEFAULT_WINDOW,
    SAMPLE_SPACING,
    SKIPPED,
    TEXTBOOK_DT,
    BenchResult,
    Fit,
    Point,
    time_for_error,
)
from .extended import _exact_error, _rigid_error
from .metrics import _energy_error, _impact_time_error, _position_error

__all__ = ["BenchResult", "Fit", "Point"]

#: Default step sizes (s): half-decades from 1e-3 down to 1e-6.
DEFAULT_DTS = tuple(float(f"{10.0 ** (-k / 2):.3g}") for k in range(6, 13))
#: Default number of timed runs per point.
DEFAULT_REPEAT = 5
#: Runs shorter than this in all (s) are repeated more, up to MAX_REPEAT times.
MIN_TIMED = 0.5
MAX_REPEAT = 100
#: Default time budget for the runs of one point (s).
DEFAULT_BUDGET = 120.0
#: ... unless the spring's period divided by this is shorter.
SAMPLES_PER_PERIOD = 50
#: Points with a larger error (m) are outside the asymptotic range and left out of order fits.
FIT_MAX_ERROR = 1e-2
#: ... and points with a smaller one are at the rounding level, where dt no longer matters.
FIT_MIN_ERROR = 1e-11


def default_spacing(scene: Scene) -> float:
    """Spacing of the compared samples (s): SAMPLE_SPACING, or 1/SAMPLES_PER_PERIOD of the
    spring's period when that is shorter."""
    return _spacing(args.scene(scene))


def _spacing(scene: Scene) -> float:
    if scene.system.omega > 0:
        return min(SAMPLE_SPACING, 2 * math.pi / scene.system.omega / SAMPLES_PER_PERIOD)
    return SAMPLE_SPACING


def default_solvers(scene: Scene) -> list[str]:
    """Every solver that can run ``scene``, except the truth."""
    return [cls.name for cls in _default_solvers(args.scene(scene))]


def _default_solvers(scene: Scene) -> list[type[Solver]]:
    truth = truth_class(scene)
    return [cls for cls in supporting(scene) if cls is not truth]


@dataclass(frozen=True)
class BenchOptions:
    """What :func:`run_bench` measures: ``solvers`` (names or Solver classes; None: every
    solver that can run the scene but the truth) at the steps ``dts`` (s, kept largest first)
    over ``t_end`` (s; None: the scene's); the position error over [0, ``window``] s;
    ``repeat`` timed runs after a warm-up; a step whose runs would take more than ``budget``
    s in all is skipped; samples about every ``spacing`` s (None: :func:`default_spacing`);
    a progress bar unless ``quiet``. Built once, checked once."""

    solvers: tuple[type[Solver], ...] | None = None
    dts: tuple[float, ...] = DEFAULT_DTS
    window: float = DEFAULT_WINDOW
    repeat: int = DEFAULT_REPEAT
    t_end: float | None = None
    budget: float = DEFAULT_BUDGET
    spacing: float | None = None
    quiet: bool = True

    def __post_init__(self) -> None:
        check(self, {"solvers": "solvers", "dts": "steps", "window": "seconds",
                     "t_end": "seconds?", "budget": "seconds", "spacing": "seconds?",
                     "quiet": "flag"})
        object.__setattr__(self, "dts", tuple(sorted(self.dts, reverse=True)))
        if not (type(self.repeat) is int and 1 <= self.repeat <= MAX_REPEAT):
            object.__setattr__(self, "repeat", args.whole(self.repeat, "repeat", "runs",
                                                          hi=MAX_REPEAT))


@dataclass(frozen=True)
class _Plan:
    """What every point of one benchmark shares: the options resolved for the scene (its
    solvers, ``t_end`` and ``spacing`` filled in) and the truth solver (None: none)."""

    options: BenchOptions
    truth: type[Solver] | None

    @property
    def solvers(self) -> tuple[type[Solver], ...]:
        return self.options.solvers or ()

    @property
    def truth_name(self) -> str:
        return self.truth.name if self.truth is not None else ""


def check_request(scene: Scene, plan: _Plan) -> None:
    """UsageError naming the argument and what is allowed, before anything runs."""
    options = plan.options
    _check_solvers(scene, plan)
    t_end, window, spacing = options.t_end, options.window, options.spacing
    assert t_end is not None and spacing is not None  # filled in by the plan
    from .budget import check_runs

    steppers = sum(cls.has_step for cls in plan.solvers)
    check_runs(steppers * len(options.dts) + len(plan.solvers) - steppers + 1,
               f"{steppers} stepping solvers x {len(options.dts)} steps (+ the others and the "
               "truth)",
               ["fewer steps ({dts})"] + (["fewer {solvers}"] if len(plan.solvers) > 1 else []))
    for dt in options.dts:
        try:
            run_options(scene, dt, t_end)
        except UsageError as exc:
            raise UsageError(f"dts: {exc.reason}", param="dts", fixes=exc.fixes) from None
    if window > t_end:
        raise UsageError(f"window {window:g}: must be <= the run's t_end = {t_end:g} (s)",
                         param="window")
    if not 0 < spacing <= window:
        raise UsageError(f"sample_spacing {spacing:g}: must be > 0 and <= the window "
                         f"{window:g} (s)", param="sample_spacing")
    _check_samples(scene, plan)
    # Every solver's own work budget (the exact solver's impacts), before the first run.
    for cls in [*plan.solvers, *([plan.truth] if plan.truth else [])]:
        cls._check_work(scene, run_options(scene, spacing, t_end))


def _check_solvers(scene: Scene, plan: _Plan) -> None:
    """UsageError naming ``solvers`` unless there are some and each can run ``scene``."""
    for cls in plan.solvers:
        reason = cls._supports(scene)
        if reason is not None:
            raise UsageError(f"solvers {cls.name}: cannot run {scene.source}: {reason}",
                             param="solvers")
    if not plan.solvers:
        raise UsageError(f"solvers: no solver to benchmark for {scene.source}", param="solvers")


def _check_samples(scene: Scene, plan: _Plan) -> None:
    """UsageError unless the samples one run keeps, and the truths kept for every step,
    fit in the budget of :data:`MAX_SAMPLES`."""
    options = plan.options
    t_end, spacing = options.t_end, options.spacing
    assert t_end is not None and spacing is not None  # filled in by the plan
    # The samples one run keeps, before anything runs: a stepping solver keeps every
    # round(spacing / dt)-th step, a solver without a step one sample per spacing.
    ratio = t_end / spacing  # a float: inf when the quotient passes the largest float
    counts = [run_options(scene, dt, t_end, _every(dt, spacing)).n_samples
              for dt in options.dts]
    if not (ratio + 1 <= MAX_SAMPLES and max(counts, default=0) <= MAX_SAMPLES):
        most = max([*counts, round(ratio) + 1]) if math.isfinite(ratio) else None
        count = f"{most:,} samples" if most is not None else "more than 1e308 samples"
        raise UsageError(f"t_end = {t_end:g} s with samples every {spacing:g} s: a run would "
                         f"keep {count}, past the budget of {MAX_SAMPLES:,}",
                         fixes=("keep fewer with a larger {spacing}", "a shorter {t_end}"))
    # The truth is kept for each step (its samples fall on that step's grid): all together
    # they may hold no more than one run may.
    dts = options.dts
    truths = sum(dict(zip(dts, counts, strict=True)).values()) if plan.truth else 0
    if truths > MAX_SAMPLES:
        raise UsageError(f"t_end = {t_end:g} s with samples every {spacing:g} s: the truth "
                         f"kept for each of {len(dts)} steps would hold {truths:,} samples in "
                         f"all, past the budget of {MAX_SAMPLES:,}",
                         fixes=(["fewer steps ({dts})"] if len(set(dts)) > 1 else [])
                         + ["a larger {spacing}", "a shorter {t_end}"])


def run_bench(scene: Scene | str | Path, options: BenchOptions) -> BenchResult:
    """Measure error against run time as ``options`` say (:class:`BenchOptions()`: every
    solver but the truth at half-decades of dt from 1e-3 to 1e-6 s over the scene's
    ``t_end``)."""
    from ..progress import bar

    scene = args.scene(scene)
    options = args.instance(options, "options", BenchOptions, "BenchOptions")
    truth = truth_class(scene)
    solvers = options.solvers or tuple(_default_solvers(scene))
    plan = _Plan(replace(options, solvers=solvers,
                         t_end=scene.run.t_end if options.t_end is None else options.t_end,
                         spacing=options.spacing or _spacing(scene)), truth)
    check_request(scene, plan)
    o = plan.options
    notes: list[str] = []
    if truth is None:
        notes.append("no truth solver for this scene (2D needs 'reference'): position and "
                      "impact-time errors are not computed")
    truths: dict[tuple[float, int], Trajectory] = {}

    def truth_at(run: RunOptions) -> Trajectory | None:
        if truth is None:
            return None
        key = (run.dt, run.every)
        if key not in truths:
            truths[key] = truth._solve(scene, replace(run, quiet=True), **_no_estimate(truth))
        return truths[key]

    points: list[Point] = []
    # A solver without a step is one point: dt only sets its sample times.
    steppers = [cls for cls in solvers if cls.has_step]
    single = [cls for cls in solvers if not cls.has_step and cls is not truth]
    total = len(steppers) * len(o.dts) + len(single) + (truth is not None)
    with bar(total, f"bench {scene.name}", "point", quiet=o.quiet) as pb:
        for cls in steppers:
            points += _stepper_points(scene, cls, plan, truth_at, pb)
        for cls in single:
            pb.set_postfix_str(cls.name)
            points.append(_single_point(scene, cls, plan, truth_at))
            pb.update(1)
        if truth is not None:
            pb.set_postfix_str(f"{truth.name} (truth)")
            points.append(_single_point(scene, truth, plan, None))
            pb.update(1)
    fits = {}
    for cls in steppers:
        fit = fit_order([p for p in points if p.solver == cls.name])
        if fit is not None:
            fits[cls.name] = replace(fit, expected=cls.order)
    return BenchResult(scene.name, scene.source, plan.truth_name or None, o.window,
                       o.t_end, o.repeat, o.budget, points, fits, notes,  # type: ignore[arg-type]
                       o.spacing)  # type: ignore[arg-type]


def _stepper_points(scene: Scene, cls: type[Solver], plan: _Plan, truth_at: Any,
                    pb: Any) -> list[Point]:
    """One point per step in the plan's dts for the stepping solver ``cls``. A step whose
    runs the cost per step measured so far says would pass the budget is skipped."""
    o = plan.options
    compile_s = cls.warm_up()
    cost_per_step = None
    points = []
    for dt in o.dts:
        pb.set_postfix_str(f"{cls.name} dt={dt:g}")
        options = run_options(scene, dt, o.t_end, _every(dt, o.spacing))  # type: ignore[arg-type]
        base = Point(cls.name, dt, window=o.window, t_end=o.t_end,  # type: ignore[arg-type]
                     truth=plan.truth_name, steps=options.n_steps, every=options.every,
                     compile_seconds=compile_s)
        estimate = None if cost_per_step is None else cost_per_step * options.n_steps
        if estimate is not None and estimate * (o.repeat + 1) > o.budget:
            base.verdict, base.seconds = None, estimate
            base.reason = (f"estimated {estimate:.3g} s per run x {counted(o.repeat + 1, 'run')} > "
                           f"budget {o.budget:g} s")
            points.append(base)
            pb.update(1)
            continue
        traj, point = _measure(cls, scene, options, o.repeat, base)
        _score(point, traj, truth_at(options), o.window)
        points.append(point)
        if point.complete and point.steps:
            cost_per_step = point.seconds_call / point.steps
        pb.update(1)
    return points


def _every(dt: float, spacing: float) -> int:
    return max(1, round(spacing / dt))


def _no_estimate(cls: type[Solver]) -> dict[str, Any]:
    """Keyword that spares a solver that estimates its own error its second run."""
    return {"estimate_error": False} if cls.estimates_error else {}


def _measure(cls: type[Solver], scene: Scene, options: RunOptions, repeat: int, point: Point,
             **first: Any) -> tuple[Trajectory, Point]:
    """Warm-up run (kept for the diagnostics; ``first`` are its extra keywords), then
    ``repeat`` timed runs."""
    traj = cls._solve(scene, options, **first)
    own, call = [], []
    # Short runs are repeated until MIN_TIMED s are timed (at most MAX_REPEAT runs), so that
    # one busy moment of a shared machine cannot hold all of them.
    while len(own) < repeat or (sum(call) < MIN_TIMED and len(own) < MAX_REPEAT):
        t0 = time.perf_counter()
        again = cls._solve(scene, options, **_no_estimate(cls))
        call.append(time.perf_counter() - t0)
        own.append(again.wall_time if again.wall_time > 0 else call[-1])
    point.seconds = min(own)
    point.seconds_median = float(np.median(own))
    point.seconds_call = min(call)
    point.repeat = len(own)
    point.verdict = traj.verdict.status
    point.verdict_t = traj.verdict.t
    point.reason = traj.verdict.reason
    return traj, point


def _score(point: Point, traj: Trajectory, truth: Trajectory | None, window: float) -> None:
    point.energy_error = _energy_error(traj, truth)
    if truth is None:
        return
    if not point.complete:
        point.error = math.inf
    else:
        point.error = _position_error(traj, truth, window)
    if traj.scene.system.floor is not None:
        point.impact_time_error, point.impacts_compared, point.impacts_truth = (
            _impact_time_error(traj, truth, window))


def _single_point(scene: Scene, cls: type[Solver], plan: _Plan, truth_at: Any) -> Point:
    """A solver without a step as one point: its cost for the bench's samples
    (every ``spacing`` s over t_end) and its error; for the truth itself, against a
    tighter evaluation (exact: extended precision) or its own estimate (reference)."""
    o = plan.options
    window = o.window
    options = run_options(scene, o.spacing, o.t_end, 1)
    is_truth = cls is plan.truth
    base = Point(cls.name, None, window=window, t_end=o.t_end,  # type: ignore[arg-type]
                 truth="self" if is_truth else plan.truth_name, steps=0, every=1,
                 compile_seconds=cls.warm_up())
    first = {} if is_truth else _no_estimate(cls)
    traj, point = _measure(cls, scene, options, o.repeat, base, **first)
    if not is_truth:
        _score(point, traj, truth_at(options) if truth_at else None, window)
        return point
    point.energy_error = _energy_error(traj, None)
    if not cls.estimates_error:
        rigid = scene.system.rigid is not None
        check = _rigid_error if rigid else _exact_error
        point.error, point.impact_time_error = check(traj, window)
        point.reason = "errors against the same closed form in extended precision"
    else:
        est = traj.info.get("estimated_error", {})
        point.error = float(est.get("position_m_window", math.nan))
        point.impact_time_error = float(est.get("impact_time_s_window", math.nan))
        point.window = float(est.get("window_s", math.nan))
        point.reason = (f"its own estimate over [0, {point.window:g}] s: against a run at 10x "
                        "tighter tolerance")
    point.impacts_compared = point.impacts_truth = sum(e.t <= window for e in traj.events)
    return point


def fit_order(points: list[Point]) -> Fit | None:
    """Least-squares slope of log10(error) against log10(dt) over the points that reached
    their end (ok or inaccurate) with an error between FIT_MIN_ERROR and FIT_MAX_ERROR (m);
    None with fewer than 3 such points."""
    if not isinstance(points, list | tuple) or not all(isinstance(p, Point) for p in points):
        raise UsageError(f"points = {args.show(points)}: must be a list of bench Points "
                         "(BenchResult.points)", param="points")
    use = [p for p in points if p.complete and p.dt is not None and math.isfinite(p.error)
           and FIT_MIN_ERROR < p.error < FIT_MAX_ERROR]
    if len(use) < 3:
        return None
    x = np.log10([p.dt for p in use])
    y = np.log10([p.error for p in use])
    slope, icpt = np.polyfit(x, y, 1)
    return Fit(use[0].solver, float(slope), float(icpt), sorted(p.dt for p in use))


# ----------------------------------------------------------------------------- outputs


def dt_label(dt: float) -> str:
    """'1e-5', '3.2e-6': a step size as written beside a point (s)."""
    dt = args.real(dt, "dt", "s")
    mantissa, exponent = f"{dt:.1e}".split("e")
    mantissa = mantissa.rstrip("0").rstrip(".")
    return f"{mantissa}e{int(exponent)}"
