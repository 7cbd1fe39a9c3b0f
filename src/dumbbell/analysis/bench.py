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

import csv
import itertools
import json
import math
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import UsageError
from ..model.energy import energy_scale, relative_energy_error
from ..model.scene import Scene
from ..model.trajectory import Trajectory
from ..solvers import RunOptions, Solver, make_options, solver_class, supported, truth_solver

if TYPE_CHECKING:
    import pandas

#: Default step sizes (s): half-decades from 1e-3 down to 1e-6.
DEFAULT_DTS = tuple(float(f"{10.0 ** (-k / 2):.3g}") for k in range(6, 13))
#: Default window of the position error (s): the textbook figures' 0-2 s.
DEFAULT_WINDOW = 2.0
#: Default number of timed runs per point.
DEFAULT_REPEAT = 5
#: Runs shorter than this in all (s) are repeated more, up to MAX_REPEAT times.
MIN_TIMED = 0.5
MAX_REPEAT = 100
#: Default time budget for the runs of one point (s).
DEFAULT_BUDGET = 120.0
#: Default target spacing of the compared samples (s): the textbook run's output interval.
SAMPLE_SPACING = 1e-3
#: ... unless the spring's period divided by this is shorter.
SAMPLES_PER_PERIOD = 50
#: Points with a larger error (m) are outside the asymptotic range and left out of order fits.
FIT_MAX_ERROR = 1e-2
#: ... and points with a smaller one are at the rounding level, where dt no longer matters.
FIT_MIN_ERROR = 1e-11
#: The step of the textbook listing (s): the accuracy the README compares against.
TEXTBOOK_DT = 1e-5

CSV_COLUMNS = (
    "solver", "dt", "seconds", "error", "seconds_median", "seconds_call", "energy_error",
    "impact_time_error", "impacts_compared", "impacts_truth", "verdict", "verdict_t",
    "compile_seconds", "steps", "every", "repeat", "window", "t_end", "truth", "reason",
)


@dataclass
class Point:
    """One (solver, dt) point. Times in s, ``error`` in m, ``energy_error`` relative."""

    solver: str
    dt: float | None
    seconds: float = math.nan
    error: float = math.nan
    seconds_median: float = math.nan
    seconds_call: float = math.nan
    energy_error: float = math.nan
    impact_time_error: float = math.nan
    impacts_compared: int = 0
    impacts_truth: int = 0
    verdict: str = "ok"
    verdict_t: float | None = None
    compile_seconds: float = math.nan
    steps: int = 0
    every: int = 1
    repeat: int = 0
    window: float = DEFAULT_WINDOW
    t_end: float = 0.0
    truth: str = ""
    reason: str = ""

    @property
    def ran(self) -> bool:
        return self.verdict != "skipped"

    @property
    def ok(self) -> bool:
        return self.verdict == "ok"


@dataclass
class Fit:
    """A fitted convergence order: error ~ C dt^order over the steps ``dts`` (s)."""

    solver: str
    order: float
    log10_c: float
    dts: list[float] = field(default_factory=list)


#: Units of :data:`CSV_COLUMNS` ("1": dimensionless; "" for names and counts).
CSV_UNITS = {"solver": "", "dt": "s", "seconds": "s", "error": "m", "seconds_median": "s",
             "seconds_call": "s", "energy_error": "1", "impact_time_error": "s",
             "impacts_compared": "", "impacts_truth": "", "verdict": "", "verdict_t": "s",
             "compile_seconds": "s", "steps": "", "every": "", "repeat": "", "window": "s",
             "t_end": "s", "truth": "", "reason": ""}
assert set(CSV_UNITS) == set(CSV_COLUMNS)


@dataclass(frozen=True)
class BenchResult:
    """Everything one benchmark measured."""

    scene: str
    source: str
    truth: str | None
    window: float
    t_end: float
    repeat: int
    budget: float
    points: list[Point]
    fits: dict[str, Fit]
    notes: list[str] = field(default_factory=list)
    spacing: float = SAMPLE_SPACING

    def speedups(self, target: float | None = None) -> dict[str, Any]:
        """Run time each solver needs for the error ``target`` (m; default: Euler-Cromer's at
        the textbook's dt), read off its work-precision line by log-log interpolation, and the
        speed-up against Euler-Cromer (2D: euler-cromer-2d) there."""
        base_name = self.baseline
        ref = next((p for p in self.points if p.solver == base_name and p.ok
                    and p.dt is not None and math.isclose(p.dt, TEXTBOOK_DT)), None)
        if target is None:
            if ref is None:
                return {}
            target = ref.error
        times = {}
        for name in dict.fromkeys(p.solver for p in self.points):
            line = sorted(((p.seconds, p.error) for p in self.points
                           if p.solver == name and p.ok and p.dt is not None
                           and math.isfinite(p.error) and p.error > 0),
                          key=lambda se: se[0])
            t = _time_for_error(line, target)
            if name == base_name and ref is not None and target == ref.error:
                t = ref.seconds  # the baseline's own point, not a crossing of its line
            if t is not None:
                times[name] = t
        base = times.get(base_name)
        return {"target_error": target, "baseline": base_name,
                "seconds": times,
                "speedup": {n: base / t for n, t in times.items()} if base else {}}

    def to_pandas(self) -> pandas.DataFrame:
        """One row per point with the CSV's columns (numbered from 0), units in
        ``df.attrs["units"]``. Needs pip install 'dumbbell[pandas]'."""
        from ..io.frames import data_frame

        rows = [asdict(p) for p in self.points]
        return data_frame({c: [r[c] for r in rows] for c in CSV_COLUMNS}, units=CSV_UNITS)

    @property
    def baseline(self) -> str:
        """The textbook's method for this scene: euler-cromer (1D) or euler-cromer-2d."""
        names = {p.solver for p in self.points}
        return "euler-cromer-2d" if "euler-cromer-2d" in names else "euler-cromer"


def _time_for_error(line: list[tuple[float, float]], target: float) -> float | None:
    """The run time (s) at which a (seconds, error) line first reaches ``target`` (m)."""
    for (t0, e0), (t1, e1) in itertools.pairwise(line):
        if e0 >= target >= e1 and e0 > e1:
            f = math.log(e0 / target) / math.log(e0 / e1)
            return math.exp(math.log(t0) + f * math.log(t1 / t0))
    reached = [t for t, e in line if e <= target]
    return min(reached) if reached else None


def default_spacing(scene: Scene) -> float:
    """Spacing of the compared samples (s): SAMPLE_SPACING, or 1/SAMPLES_PER_PERIOD of the
    spring's period when that is shorter."""
    if scene.omega > 0:
        return min(SAMPLE_SPACING, 2 * math.pi / scene.omega / SAMPLES_PER_PERIOD)
    return SAMPLE_SPACING


def default_solvers(scene: Scene) -> list[str]:
    """Every solver that can run ``scene``, except the truth."""
    truth = truth_solver(scene)
    return [n for n in supported(scene) if n != truth]


def check_request(scene: Scene, solvers: list[str], dts: list[float], window: float,
                  t_end: float, spacing: float = SAMPLE_SPACING) -> None:
    """UsageError naming the flag and what is allowed, before anything runs."""
    for name in solvers:
        reason = solver_class(name).supports(scene)
        if reason is not None:
            raise UsageError(f"--solvers {name}: cannot run {scene.source}: {reason}")
    if not solvers:
        raise UsageError(f"--solvers: no solver to benchmark for {scene.source}")
    for dt in dts:
        make_options(scene, dt=dt, t_end=t_end)
    if window > t_end:
        raise UsageError(f"--window {window:g}: must be <= the run's t_end = {t_end:g} (s)")
    if not 0 < spacing <= window:
        raise UsageError(f"--sample-spacing {spacing:g}: must be > 0 and <= the window "
                         f"{window:g} (s)")


def run_bench(
    scene: Scene,
    solvers: list[str] | None = None,
    dts: list[float] | None = None,
    window: float = DEFAULT_WINDOW,
    repeat: int = DEFAULT_REPEAT,
    t_end: float | None = None,
    budget: float = DEFAULT_BUDGET,
    spacing: float | None = None,
    quiet: bool = True,
) -> BenchResult:
    """Measure error against run time for ``solvers`` (default: all but the truth) at the
    steps ``dts`` (s; default half-decades 1e-3..1e-6) over the scene's ``t_end`` (s).
    ``window`` (s) bounds the position error; ``repeat`` timed runs follow a warm-up run;
    a step whose runs would take more than ``budget`` s in all is skipped. Samples are kept
    about every ``spacing`` s (default :func:`default_spacing`; the step-free solvers:
    exactly)."""
    from ..progress import bar

    t_end = scene.run.t_end if t_end is None else t_end
    spacing = default_spacing(scene) if spacing is None else spacing
    solvers = default_solvers(scene) if solvers is None else list(dict.fromkeys(solvers))
    dts = sorted(DEFAULT_DTS if dts is None else dts, reverse=True)
    check_request(scene, solvers, dts, window, t_end, spacing)
    truth = truth_solver(scene)
    notes: list[str] = []
    if truth is None:
        notes.append("no truth solver for this scene (2D needs 'reference'): position and "
                      "impact-time errors are not computed")
    truths: dict[tuple[float, int], Trajectory] = {}

    def truth_at(options: RunOptions) -> Trajectory | None:
        if truth is None:
            return None
        key = (options.dt, options.every)
        if key not in truths:
            truths[key] = solver_class(truth).solve(scene, replace(options, quiet=True),
                                                    **_no_estimate(solver_class(truth)))
        return truths[key]

    points: list[Point] = []
    # A solver without a step is one point: dt only sets its sample times.
    steppers = [n for n in solvers if solver_class(n).has_step]
    single = [n for n in solvers if not solver_class(n).has_step and n != truth]
    total = len(steppers) * len(dts) + len(single) + (truth is not None)
    with bar(total, f"bench {scene.name}", "point", quiet=quiet) as pb:
        for name in steppers:
            cls = solver_class(name)
            compile_s = cls.warm_up()
            cost_per_step = None
            for dt in dts:
                pb.set_postfix_str(f"{name} dt={dt:g}")
                options = make_options(scene, dt=dt, t_end=t_end, every=_every(dt, spacing))
                base = Point(name, dt, window=window, t_end=t_end, truth=truth or "",
                             steps=options.n_steps, every=options.every,
                             compile_seconds=compile_s)
                estimate = None if cost_per_step is None else cost_per_step * options.n_steps
                if estimate is not None and estimate * (repeat + 1) > budget:
                    base.verdict, base.seconds = "skipped", estimate
                    base.reason = (f"estimated {estimate:.3g} s per run x {repeat + 1} runs > "
                                   f"budget {budget:g} s")
                    points.append(base)
                    pb.update(1)
                    continue
                traj, point = _measure(cls, scene, options, repeat, base)
                _score(point, traj, truth_at(options), window)
                points.append(point)
                if point.ok and point.steps:
                    cost_per_step = point.seconds_call / point.steps
                pb.update(1)
        for name in single:
            pb.set_postfix_str(name)
            points.append(_single_point(scene, name, t_end, window, repeat, truth, truth_at,
                                        spacing))
            pb.update(1)
        if truth is not None:
            pb.set_postfix_str(f"{truth} (truth)")
            points.append(_single_point(scene, truth, t_end, window, repeat, truth, None,
                                        spacing))
            pb.update(1)
    fits = {}
    for name in steppers:
        fit = fit_order([p for p in points if p.solver == name])
        if fit is not None:
            fits[name] = fit
    return BenchResult(scene.name, scene.source, truth, window, t_end, repeat, budget, points,
                       fits, notes, spacing)


def _every(dt: float, spacing: float) -> int:
    return max(1, round(spacing / dt))


def _no_estimate(cls: type[Solver]) -> dict[str, Any]:
    """Keyword that spares a solver that estimates its own error its second run."""
    return {"estimate_error": False} if cls.estimates_error else {}


def _measure(cls: type[Solver], scene: Scene, options: RunOptions, repeat: int, point: Point,
             **first: Any) -> tuple[Trajectory, Point]:
    """Warm-up run (kept for the diagnostics; ``first`` are its extra keywords), then
    ``repeat`` timed runs."""
    traj = cls.solve(scene, options, **first)
    own, call = [], []
    # Short runs are repeated until MIN_TIMED s are timed (at most MAX_REPEAT runs), so that
    # one busy moment of a shared machine cannot hold all of them.
    while len(own) < repeat or (sum(call) < MIN_TIMED and len(own) < MAX_REPEAT):
        t0 = time.perf_counter()
        again = cls.solve(scene, options, **_no_estimate(cls))
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


def position_error(traj: Trajectory, truth: Trajectory, window: float) -> float:
    """Largest distance |r - r_truth| of either particle over the samples in [0, window] (m);
    inf if the run stopped before the window ended. Both must share their sample times."""
    n = int(np.searchsorted(truth.t, window * (1 + 1e-12), side="right"))
    if len(traj.t) < n:
        return math.inf
    if not np.array_equal(traj.t[:n], truth.t[:n]):
        raise ValueError("position_error: the trajectories do not share their sample times")
    worst = 0.0
    for body in "AB":
        cols = [c for c in (f"x{body}", f"y{body}") if c in traj.state]
        sq = sum((traj.state[c][:n] - truth.state[c][:n]) ** 2 for c in cols)
        worst = max(worst, float(np.sqrt(np.max(sq))))
    return worst


def impact_time_error(traj: Trajectory, truth: Trajectory, window: float
                      ) -> tuple[float, int, int]:
    """(largest |t_i - t_i(truth)| in s, impacts compared, truth's impacts in [0, window]).

    Impacts are paired in order; inf if the solver's sequence misses one or names another
    body before the window ends."""
    wanted = [e for e in truth.events if e.t <= window]
    worst, compared = 0.0, 0
    for mine, true in zip(traj.events, wanted):
        if mine.body != true.body:
            return math.inf, compared, len(wanted)
        worst = max(worst, abs(mine.t - true.t))
        compared += 1
    if compared < len(wanted):
        return math.inf, compared, len(wanted)
    return (worst if compared else math.nan), compared, len(wanted)


def energy_error(traj: Trajectory, truth: Trajectory | None) -> float:
    """Largest relative energy error over the whole run: drift from E(0), or for a
    dissipative scene the distance from the truth's E at the same times (dimensionless)."""
    if len(traj.t) == 0:
        return math.nan
    if not traj.scene.dissipative:
        return float(np.max(relative_energy_error(traj)))
    if truth is None:
        return math.nan
    n = min(len(traj.t), len(truth.t))
    E, E_true = traj["E"][:n], truth["E"][:n]
    terms = {k: float(v[0]) for k, v in truth.energy.items() if k not in ("E", "E_lost")}
    return float(np.max(np.abs(E - E_true)) / energy_scale(float(E_true[0]), terms))


def _score(point: Point, traj: Trajectory, truth: Trajectory | None, window: float) -> None:
    point.energy_error = energy_error(traj, truth)
    if truth is None:
        return
    if not point.ok:
        point.error = math.inf
    else:
        point.error = position_error(traj, truth, window)
    if traj.scene.floor is not None:
        point.impact_time_error, point.impacts_compared, point.impacts_truth = (
            impact_time_error(traj, truth, window))


def _single_point(scene: Scene, name: str, t_end: float, window: float, repeat: int,
                  truth: str | None, truth_at, spacing: float) -> Point:
    """A solver without a step as one point: its cost for the bench's samples
    (every ``spacing`` s over t_end) and its error; for the truth itself, against a tighter
    evaluation (exact: extended precision) or its own estimate (reference)."""
    cls = solver_class(name)
    options = make_options(scene, dt=spacing, t_end=t_end, every=1)
    is_truth = name == truth
    base = Point(name, None, window=window, t_end=t_end, truth="self" if is_truth else truth
                 or "", steps=0, every=1,
                 compile_seconds=cls.warm_up())
    first = {} if is_truth else _no_estimate(cls)
    traj, point = _measure(cls, scene, options, repeat, base, **first)
    if not is_truth:
        _score(point, traj, truth_at(options) if truth_at else None, window)
        return point
    point.energy_error = energy_error(traj, None)
    if not cls.estimates_error:
        check = extended_precision_rigid if scene.rigid is not None else extended_precision_exact
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


def extended_precision_exact(traj: Trajectory, window: float) -> tuple[float, float]:
    """Largest position error (m) and impact time error (s) over [0, window] of an ``exact``
    trajectory against the same
    closed form evaluated in numpy's extended precision (80-bit on x86: 64-bit mantissa),
    with each impact time refined by Newton's method in that precision. It checks the
    rounding of the double-precision solution, given its sequence of impacts."""
    L = np.longdouble
    scene = traj.scene
    mA, mB, g = L(scene.A.mass), L(scene.B.mass), L(scene.g)
    M = mA + mB
    k = L(scene.spring.stiffness) if scene.spring else L(0)
    b = L(scene.spring.rest_length) if scene.spring else L(0)
    w = np.sqrt(k * M / (mA * mB))
    e = L(scene.floor.elasticity) if scene.floor else L(1)

    def state(seg, tau):
        _t0, X0, V0, s0, sd0 = seg
        X = X0 + V0 * tau - g * tau * tau / 2
        V = V0 - g * tau
        if w > 0:
            c, s = np.cos(w * tau), np.sin(w * tau)
            st, sdt = s0 * c + sd0 / w * s, -s0 * w * s + sd0 * c
        else:
            st, sdt = s0 + sd0 * tau, sd0 + 0 * tau
        return (X + mB / M * (b + st), V + mB / M * sdt, X - mA / M * (b + st), V - mA / M * sdt)

    def segment(t0, xA, vA, xB, vB):
        return (t0, (mA * xA + mB * xB) / M, (mA * vA + mB * vB) / M, xA - xB - b, vA - vB)

    seg = segment(L(0), L(scene.A.height), L(scene.A.vy), L(scene.B.height), L(scene.B.vy))
    n = int(np.searchsorted(traj.t, window * (1 + 1e-12), side="right"))
    t = traj.t[:n].astype(L)
    worst = worst_t = 0.0
    starts = [e_.t for e_ in traj.events if e_.t <= window] + [math.inf]
    events = [e_ for e_ in traj.events if e_.t <= window]
    lo = 0
    for j, stop in enumerate(starts):
        hi = int(np.searchsorted(traj.t[:n], stop, side="left"))
        if hi > lo:
            xA, _, xB, _ = state(seg, t[lo:hi] - seg[0])
            worst = max(worst, float(np.max(np.abs(xA - traj["xA"][lo:hi]))),
                        float(np.max(np.abs(xB - traj["xB"][lo:hi]))))
        lo = hi
        if j == len(events):
            break
        hit = events[j]
        tau = L(hit.t) - seg[0]
        idx = 0 if hit.body == "A" else 2
        for _ in range(8):
            s = state(seg, tau)
            tau = tau - s[idx] / s[idx + 1]
        worst_t = max(worst_t, abs(float(seg[0] + tau - L(hit.t))))
        xA, vA, xB, vB = state(seg, tau)
        if hit.body == "A":
            xA, vA = L(0), -e * vA
        else:
            xB, vB = L(0), -e * vB
        seg = segment(seg[0] + tau, xA, vA, xB, vB)
    return worst, (worst_t if events else math.nan)


def extended_precision_rigid(traj: Trajectory, window: float) -> tuple[float, float]:
    """:func:`extended_precision_exact` for the rigid 2D dumbbell: the parabola-and-rotation
    closed form and the impulse law in numpy's extended precision, each impact time refined
    by Newton's method there; largest position error (m) and impact time error (s)."""
    from ..model.energy import rigid_moment

    L = np.longdouble
    scene = traj.scene
    mA, mB, g = L(scene.A.mass), L(scene.B.mass), L(scene.g)
    M = mA + mB
    length = L(scene.rigid.length)  # type: ignore[union-attr]
    arm = {"A": mB / M * length, "B": -mA / M * length}
    moment = L(rigid_moment(scene))
    e = L(scene.floor.elasticity) if scene.floor else L(1)
    A, B = scene.A, scene.B
    d = (L(A.x) - L(B.x), L(A.height) - L(B.height))
    w = (L(A.vx) - L(B.vx), L(A.vy) - L(B.vy))
    seg = [L(0), (mA * L(A.x) + mB * L(B.x)) / M, (mA * L(A.height) + mB * L(B.height)) / M,
           (mA * L(A.vx) + mB * L(B.vx)) / M, (mA * L(A.vy) + mB * L(B.vy)) / M,
           np.arctan2(d[1], d[0]), (d[0] * w[1] - d[1] * w[0]) / (d[0] ** 2 + d[1] ** 2)]

    def at(seg, tau):
        t0, X, Y, VX, VY, th, om = seg
        return [t0 + tau, X + VX * tau, Y + VY * tau - g * tau * tau / 2, VX, VY - g * tau,
                th + om * tau, om]

    n = int(np.searchsorted(traj.t, window * (1 + 1e-12), side="right"))
    t = traj.t[:n].astype(L)
    events = [e_ for e_ in traj.events if e_.t <= window]
    worst = worst_t = 0.0
    lo = 0
    for j, stop in enumerate([e_.t for e_ in events] + [math.inf]):
        hi = int(np.searchsorted(traj.t[:n], stop, side="left"))
        if hi > lo:
            _, X, Y, _, _, th, _ = at(seg, t[lo:hi] - seg[0])
            for body in "AB":
                worst = max(worst,
                            float(np.max(np.abs(X + arm[body] * np.cos(th) - traj[f"x{body}"][lo:hi]))),
                            float(np.max(np.abs(Y + arm[body] * np.sin(th) - traj[f"y{body}"][lo:hi]))))
        lo = hi
        if j == len(events):
            break
        hit = events[j]
        a = arm[hit.body]
        tau = L(hit.t) - seg[0]
        if tau != 0:  # ends that hit together share the time: no new root to refine
            for _ in range(8):
                _, _, Y, _, VY, th, om = at(seg, tau)
                tau = tau - (Y + a * np.sin(th)) / (VY + a * om * np.cos(th))
        worst_t = max(worst_t, abs(float(seg[0] + tau - L(hit.t))))
        seg = at(seg, tau)
        rx = a * np.cos(seg[5])
        J = -(1 + e) * (seg[4] + seg[6] * rx) / (1 / M + rx * rx / moment)
        seg[4] += J / M
        seg[6] += rx * J / moment
    return worst, (worst_t if events else math.nan)


def fit_order(points: list[Point]) -> Fit | None:
    """Least-squares slope of log10(error) against log10(dt) over the ok points with an error
    between FIT_MIN_ERROR and FIT_MAX_ERROR (m); None with fewer than 3 such points."""
    use = [p for p in points if p.ok and p.dt is not None and math.isfinite(p.error)
           and FIT_MIN_ERROR < p.error < FIT_MAX_ERROR]
    if len(use) < 3:
        return None
    x = np.log10([p.dt for p in use])
    y = np.log10([p.error for p in use])
    slope, icpt = np.polyfit(x, y, 1)
    return Fit(use[0].solver, float(slope), float(icpt), sorted(p.dt for p in use))


# ----------------------------------------------------------------------------- outputs


def _fmt(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return "nan" if math.isnan(value) else repr(value)
    return str(value)


def write_csv(result: BenchResult, path: Path) -> Path:
    """One row per point, columns CSV_COLUMNS (s, m, dimensionless)."""
    from ..io.files import atomic_output

    with atomic_output(path) as tmp, open(tmp, "w", newline="") as fh:
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(CSV_COLUMNS)
        for p in result.points:
            row = asdict(p)
            writer.writerow([_fmt(row[c]) for c in CSV_COLUMNS])
    return path


def _json_value(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: _json_value(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_json_value(v) for v in value]
    return value


def to_json(result: BenchResult) -> dict[str, Any]:
    """The result as plain JSON data (inf as the string "inf", nan as null)."""
    data = {
        "scene": result.scene, "source": result.source, "truth": result.truth,
        "window_s": result.window, "t_end_s": result.t_end, "repeat": result.repeat,
        "budget_s": result.budget, "sample_spacing_s": result.spacing,
        "fit_max_error_m": FIT_MAX_ERROR, "fit_min_error_m": FIT_MIN_ERROR,
        "notes": result.notes,
        "points": [asdict(p) for p in result.points],
        "orders": {n: asdict(f) for n, f in result.fits.items()},
        "matched_error": result.speedups(),
    }
    return _json_value(data)


def write_json(result: BenchResult, path: Path) -> Path:
    from ..io.files import atomic_output

    with atomic_output(path) as tmp:
        tmp.write_text(json.dumps(to_json(result), indent=1) + "\n")
    return path


def _sci(x: float | None, digits: int = 2) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    if isinstance(x, float) and math.isinf(x):
        return "inf"
    return f"{x:.{digits}e}"


def dt_label(dt: float) -> str:
    """'1e-5', '3.2e-6': a step size as written beside a point (s)."""
    mantissa, exponent = f"{dt:.1e}".split("e")
    mantissa = mantissa.rstrip("0").rstrip(".")
    return f"{mantissa}e{int(exponent)}"


def markdown(result: BenchResult) -> str:
    """The table, fitted orders and matched-error speed-ups as markdown."""
    lines = [
        (f"Work-precision benchmark of `{result.source}` over t_end = {result.t_end:g} s; "
        f"truth: `{result.truth}`; position error over [0, {result.window:g}] s; time: min "
        f"(median) of at least {result.repeat} runs after a warm-up; short runs are "
        f"repeated until {MIN_TIMED:g} s are timed."),
        "",
        ("| solver | dt (s) | steps | run time min (median) | position error (m) "
        "| energy error (rel.) | impact time error (s) | verdict |"),
        "|---|---|---|---|---|---|---|---|",
    ]
    for p in result.points:
        dt = dt_label(p.dt) if p.dt is not None else f"(samples every {result.spacing:g} s)"
        if p.ran:
            time_s = f"{_ms(p.seconds)} ({_ms(p.seconds_median)})"
        else:
            time_s = f"~{_ms(p.seconds)} (estimate)"
        verdict = p.verdict if p.ok else f"**{p.verdict}**" + (
            f" at {p.verdict_t:.3g} s" if p.verdict_t is not None else "")
        imp = _sci(p.impact_time_error)
        if p.impacts_truth:
            imp += f" ({p.impacts_compared}/{p.impacts_truth})"
        steps = f"{p.steps:,}" if p.dt is not None else "-"
        lines.append(f"| {p.solver} | {dt} | {steps} | {time_s} | {_sci(p.error)} "
                     f"| {_sci(p.energy_error)} | {imp} | {verdict} |")
    lines.append("")
    if result.fits:
        fit_text = "; ".join(
            f"{n} {f.order:.2f} (dt {dt_label(min(f.dts))}..{dt_label(max(f.dts))} s, "
            f"{len(f.dts)} points)" for n, f in result.fits.items())
        lines.append(f"Fitted order of the position error over [0, {result.window:g}] s "
                     f"(least squares in log-log over the ok points with error between "
                     f"{FIT_MIN_ERROR:g} and {FIT_MAX_ERROR:g} m): {fit_text}.")
    sp = result.speedups()
    if sp and sp.get("seconds"):
        parts = [f"{n} {_ms(t)} ({sp['speedup'].get(n, math.nan):.3g}x)"
                 for n, t in sp["seconds"].items()]
        lines.append(f"Run time to reach {sp['baseline']}'s error at dt = 1e-5 s "
                     f"({sp['target_error']:.2e} m), interpolated along each line "
                     f"(speed-up against {sp['baseline']}): {'; '.join(parts)}.")
    compile_parts = {p.solver: p.compile_seconds for p in result.points
                     if math.isfinite(p.compile_seconds)}
    if compile_parts:
        lines.append("JIT compile (or load from numba's cache) before the runs, not in the "
                     "times above: "
                     + "; ".join(f"{n} {v:.3g} s" for n, v in compile_parts.items())
                     + " (the first numba solver also pays numba's one-time start-up).")
    for p in result.points:
        if p.ran and p.window != result.window:
            lines.append(f"The {p.solver} row's errors are {p.reason}.")
    lines.extend(result.notes)
    return "\n".join(lines) + "\n"


def _ms(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "-"
    if seconds >= 1:
        return f"{seconds:.3g} s"
    if seconds >= 1e-3:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds * 1e6:.3g} µs"


def write_markdown(result: BenchResult, path: Path) -> Path:
    from ..io.files import atomic_output

    with atomic_output(path) as tmp:
        tmp.write_text(markdown(result))
    return path


def write_all(result: BenchResult, out: Path) -> list[Path]:
    """CSV, JSON and markdown into ``out``, named bench-SCENE*. (The figures are
    :mod:`dumbbell.plot`'s: :func:`~dumbbell.plot.work_precision` and
    :func:`~dumbbell.plot.convergence`; the command saves them.)"""
    stem = f"bench-{result.scene}"
    return [
        write_csv(result, out / f"{stem}.csv"),
        write_json(result, out / f"{stem}.json"),
        write_markdown(result, out / f"{stem}.md"),
    ]
