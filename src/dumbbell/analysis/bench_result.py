"""What a benchmark gives: each (solver, step) measured (:class:`Point`), the fitted order
of each solver's error (:class:`Fit`) and the whole frozen result (:class:`BenchResult`), as
:func:`dumbbell.analysis.bench.run_bench` builds them."""

from __future__ import annotations

import itertools
import math
import numbers
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

from .._display import counted
from ..errors import UsageError
from ..model import args
from ..model.trajectory import COMPLETE

if TYPE_CHECKING:
    import pandas

#: Default step sizes (s): half-decades from 1e-3 down to 1e-6.
#: No public names here: the records are :mod:`dumbbell.analysis.bench`'s.
__all__: list[str] = []

#: Default window of the position error (s): the textbook figures' 0-2 s.
DEFAULT_WINDOW = 2.0
#: What the tables print in a point's verdict column for a step that was not run (its
#: runs would have passed the budget). Not a verdict: such a point's ``verdict`` is None.
SKIPPED = "skipped"
#: Default target spacing of the compared samples (s): the textbook run's output interval.
SAMPLE_SPACING = 1e-3
#: The step of the textbook listing (s): the accuracy the README compares against.
TEXTBOOK_DT = 1e-5
CSV_COLUMNS = (
    "solver", "dt", "seconds", "error", "seconds_median", "seconds_call", "energy_error",
    "impact_time_error", "impacts_compared", "impacts_truth", "verdict", "verdict_t",
    "compile_seconds", "steps", "every", "repeat", "window", "t_end", "truth", "reason",
)

@dataclass
class Point:
    """One (solver, dt) point of a benchmark: a row of its CSV (the module's docstring says
    how each is measured).

    Parameters
    ----------
    solver : str
        The solver's name.
    dt : float or None
        The step (s; None for a solver without one).
    seconds, seconds_median : float
        The fastest and the median of the timed runs (s, the solver's own clock).
    error : float
        The largest position error over [0, ``window``] s (m).
    seconds_call : float
        The fastest whole ``solve`` call, verdict included (s).
    energy_error : float
        The largest relative energy error over the run.
    impact_time_error : float
        The largest impact-time difference from the truth's before ``window`` (s).
    impacts_compared, impacts_truth : int
        Impacts compared, and the truth's impacts before ``window``.
    verdict : str or None
        The run's verdict status; None when the step was skipped (not run).
    verdict_t : float or None
        When a run that failed failed (s).
    compile_seconds : float
        The solver's ``warm_up()`` (s): numba compile, or load from its cache.
    steps, every, repeat : int
        Steps per run, steps per sample, timed runs.
    window, t_end : float
        The error's window and the run's end (s).
    truth : str
        The truth's solver.
    reason : str
        Why a run failed or a step was skipped.

    Examples
    --------
    The first point: the hand-written method at the longest step, against the exact truth.

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> point = dumbbell.bench(scenes_dir() / "textbook-1d.toml", solvers=["euler-cromer"],
    ...                        dts=[1e-3, 1e-4], window=1.0, t_end=1.0, repeat=1).points[0]
    >>> point.solver, point.dt, point.steps, point.verdict, point.truth
    ('euler-cromer', 0.001, 1000, 'ok', 'exact')
    """

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
    verdict: str | None = "ok"
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
        """True unless the step was skipped."""
        return self.verdict is not None

    @property
    def ok(self) -> bool:
        """The run ended ``ok``: stable, and its energy error within its scene's
        ``run.inaccurate_energy``."""
        return self.verdict == "ok"

    @property
    def complete(self) -> bool:
        """The run reached its end (``ok`` or ``inaccurate``): its errors are measured."""
        return self.verdict in COMPLETE

    @property
    def status(self) -> str:
        """The verdict, or :data:`SKIPPED` for a step not run: what the tables print."""
        return SKIPPED if self.verdict is None else self.verdict


@dataclass
class Fit:
    """A fitted convergence order: error ~ C dt^order, beside the order the solver declares.

    Parameters
    ----------
    solver : str
        The solver's name.
    order : float
        The measured order (the slope of log error against log dt).
    log10_c : float
        log10 of C (C in m / s^order).
    dts : list of float
        The steps (s) the fit is over.
    expected : int or None
        The order the solver declares (None: it declares none).

    Examples
    --------
    Verlet's method is of second order, as it declares:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> fit = dumbbell.bench(scene, solvers=["verlet"], dts=[1e-3, 1e-4, 1e-5], window=1.0,
    ...                      t_end=1.0, repeat=1).fits["verlet"]
    >>> round(fit.order, 2), fit.expected, fit.dts
    (2.0, 2, [1e-05, 0.0001, 0.001])
    """

    solver: str
    order: float
    log10_c: float
    dts: list[float] = field(default_factory=list)
    expected: int | None = None


#: Units of :data:`CSV_COLUMNS` ("1": dimensionless; "" for names and counts).
CSV_UNITS = {"solver": "", "dt": "s", "seconds": "s", "error": "m", "seconds_median": "s",
             "seconds_call": "s", "energy_error": "1", "impact_time_error": "s",
             "impacts_compared": "", "impacts_truth": "", "verdict": "", "verdict_t": "s",
             "compile_seconds": "s", "steps": "", "every": "", "repeat": "", "window": "s",
             "t_end": "s", "truth": "", "reason": ""}


@dataclass(frozen=True)
class BenchResult:
    """Everything one benchmark measured: what :func:`dumbbell.bench` returns.

    Parameters
    ----------
    scene, source : str
        The scene's name and its file.
    truth : str or None
        The truth's solver (None: none).
    window, t_end : float
        The position error's window [0, window] and the runs' end (s).
    repeat : int
        Timed runs per point asked for.
    budget : float
        Seconds a step's runs may take before it is skipped.
    points : list of Point
        One per (solver, dt), the truth's last.
    fits : dict of str to Fit
        The measured order of each solver with enough points in its line.
    notes : list of str
        What the benchmark says about itself (skipped steps, ...).
    spacing : float
        The sample spacing (s) errors are measured at.

    Examples
    --------
    Two solvers at three steps, and the truth: seven points, one fit.

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> result = dumbbell.bench(scene, solvers=["euler-cromer", "verlet"],
    ...                         dts=[1e-3, 1e-4, 1e-5], window=1.0, t_end=1.0, repeat=1)
    >>> len(result.points), sorted(result.fits)
    (7, ['verlet'])
    >>> result.to_pandas()["solver"].tolist()[:2]
    ['euler-cromer', 'euler-cromer']
    >>> timing = result.speedups(1e-5)          # the run time each needs for 1e-5 m
    >>> sorted(timing["seconds"])
    ['verlet']
    """

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

    def __repr__(self) -> str:
        """One line: the scene, the points and how many ran ok, and the speed-ups at the
        textbook's accuracy."""
        from .._display import one_line

        ok = sum(p.ok for p in self.points)
        solvers = list(dict.fromkeys(p.solver for p in self.points))
        speed = self.speedups().get("speedup", {})
        fast = ", ".join(f"{n} {v:.3g}x" for n, v in speed.items() if n != self.baseline)
        return one_line(f"<BenchResult {self.scene}: {counted(len(self.points), 'point')} of "
                        f"{counted(len(solvers), 'solver')} ({ok} ok), truth {self.truth or '-'}, error "
                        f"over [0, {self.window:g}] s"
                        + (f"; speed-up at {self.baseline}'s error: {fast}" if fast else "")
                        + ">")

    def _repr_html_(self) -> str:
        """The one-line summary above one row per point (times in s, errors in m)."""
        from .._display import html_table

        head = ["solver", "dt (s)", "steps", "run time min (s)", "median (s)",
                "position error (m)", "energy error", "impact time error (s)", "verdict"]
        rows = [(p.solver, p.dt, p.steps, p.seconds, p.seconds_median, p.error,
                 p.energy_error, p.impact_time_error, p.status) for p in self.points]
        fits = [f"fitted order: {n} {f.order:.2f}" for n, f in self.fits.items()]
        return html_table(repr(self), head, rows, [*fits, *self.notes])

    def speedups(self, target: float | None = None) -> dict[str, Any]:
        """Run time each solver needs for an error, read off its work-precision line by
        log-log interpolation, and the speed-up against Euler-Cromer (2D: euler-cromer-2d)
        there.

        Parameters
        ----------
        target : float or None, default None
            The error (m); None: Euler-Cromer's at the textbook's dt (1e-5 s).

        Returns
        -------
        dict
            ``target_error`` (m), ``baseline`` (the solver compared against), ``seconds``
            (solver -> s) and ``speedup`` (solver -> times faster than the baseline); empty
            when there is no target (no baseline point at the textbook's dt).

        Raises
        ------
        UsageError
            A target that is not a finite number.
        """
        target = None if target is None else args.real(target, "target", "m")
        base_name = self.baseline
        ref = next((p for p in self.points if p.solver == base_name and p.complete
                    and p.dt is not None and math.isclose(p.dt, TEXTBOOK_DT)), None)
        if target is None:
            if ref is None:
                return {}
            target = ref.error
        times = {}
        for name in dict.fromkeys(p.solver for p in self.points):
            line = sorted(((p.seconds, p.error) for p in self.points
                           if p.solver == name and p.complete and p.dt is not None
                           and math.isfinite(p.error) and p.error > 0),
                          key=lambda se: se[0])
            t = time_for_error(line, target)
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
        ``df.attrs["units"]``. Needs pip install 'dumbbell[pandas]'.

        Returns
        -------
        pandas.DataFrame
            The columns of :class:`Point`.

        Raises
        ------
        MissingExtraError
            pandas is not installed.
        """
        from ..frames import data_frame

        rows = [asdict(p) for p in self.points]
        return data_frame({c: [r[c] for r in rows] for c in CSV_COLUMNS}, units=CSV_UNITS)

    @property
    def baseline(self) -> str:
        """The textbook's method for this scene: euler-cromer (1D) or euler-cromer-2d."""
        names = {p.solver for p in self.points}
        return "euler-cromer-2d" if "euler-cromer-2d" in names else "euler-cromer"


def time_for_error(line: list[tuple[float, float]], target: float) -> float | None:
    """The run time (s) at which a (seconds, error) line first reaches ``target`` (m)."""
    target = args.real(target, "target", "m")
    if not isinstance(line, list | tuple) or not all(
            isinstance(p, tuple | list) and len(p) == 2 and isinstance(p[0], numbers.Real)
            for p in line):
        raise UsageError(f"line = {args.show(line)}: must be a list of (seconds, error) "
                         "pairs of numbers (s, m), errors > 0", param="line")
    line = [(float(t), args.real(e, "line", "m")) for t, e in line]
    for (t0, e0), (t1, e1) in itertools.pairwise(line):
        if e0 >= target >= e1 and e0 > e1:
            f = math.log(e0 / target) / math.log(e0 / e1)
            return math.exp(math.log(t0) + f * math.log(t1 / t0))
    reached = [t for t, e in line if e <= target]
    return min(reached) if reached else None
