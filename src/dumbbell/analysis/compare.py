"""Comparing solvers on one scene against the most accurate solution available.

The truth is the ``exact`` solution in 1D and for the rigid 2D dumbbell (its flight in closed
form), and the ``reference`` (DOP853 at 1e-12) for a 2D spring; a
scene with friction has neither, so there the truth is pymunk at a ten times smaller step (the
report says so). Each other run is measured against it:

- impact times side by side, matched in order, with their differences;
- the position error (the distance of either particle from its true place) at each sample,
  its largest value over a window (default 2 s), or up to where the runs part when that comes
  sooner, and the time at which it first passes 1 mm;
- where the runs part by chaos (:func:`parting`): each impact turns a small difference in when
  it happens into a larger one, so once the position error has grown past
  :data:`PART_FRACTION` of the dumbbell's length it measures the chaos, not the method. The
  runs part at the truth's last impact before that (the impact that amplified the difference);
  the position error is reported up to there. An error that passes that distance before any
  impact is the method's own, not a parting;
- the energy error and the impacts over the whole run (drift from E(0) relative to the
  energy scale; for a dissipative scene the distance from the truth's E);
- the run time, warm: a first run also pays numba's start-up and compile (or its load from
  numba's cache), so a run shorter than :data:`TIME_AGAIN_BELOW` s, or of a step-free solver,
  is timed again and the fastest later run is the run time; what the first run paid on top
  is reported apart as its warm-up.

The measures are :mod:`dumbbell.analysis.metrics`', the same as ``bench`` reports.

>>> result = compare(load_scene("scenes/textbook-1d.toml"))       # doctest: +SKIP
>>> print(dumbbell.io.compare.text(result))                         # doctest: +SKIP
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .._display import counted
from ..errors import UsageError
from ..model import args
from ..model.scene import Scene
from ..model.trajectory import Trajectory
from ..solvers import METHODS, Solver, truth_class
from ..solvers.base import RunOptions, run_options
from ._fields import check
from .metrics import _energy_error, _position_error, _position_error_series

if TYPE_CHECKING:
    import pandas

#: Default window (s) for position errors.
WINDOW = 2.0

__all__ = ["Comparison", "Row", "Timing"]

#: Position error (m) whose first passing is reported as the divergence time.
DIVERGED = 1e-3
#: The runs have parted once the position error passes this fraction of the dumbbell's
#: length (2 mm for the textbook's 0.2 m): a difference the motion figures show.
PART_FRACTION = 0.01

#: A run shorter than this (s) is timed again, until :data:`TIMED` s are timed in all (at most
#: :data:`MAX_TIMED_RUNS` runs): the fastest later run is its warm run time.
TIME_AGAIN_BELOW = 1.0
TIMED = 0.2
MAX_TIMED_RUNS = 5


#: Columns of :meth:`Comparison.summary` and their units.
SUMMARY_UNITS = {"solver": "", "dt": "s", "wall_time": "s", "steps_per_s": "1/s",
                 "window_error": "m", "error_until": "s", "parted_at": "s",
                 "diverged_at": "s", "energy_error": "1", "impacts": "", "run_until": "s",
                 "verdict": "", "warm_up": "s"}


@dataclass(frozen=True)
class Parting:
    """Where a run and the truth part by chaos: at the truth's impact number ``impact``
    (1-based) at ``t`` (s), after which the position error passed ``distance`` (m) at
    ``passed`` (s); ``differences`` the impact-time differences (s, run minus truth) of the
    impacts matched in order up to the first after the parting (or the last there is)."""

    t: float
    impact: int
    distance: float
    passed: float
    differences: tuple[float, ...]

    @property
    def growth(self) -> float:
        """How much an impact-time difference grows per impact (the geometric mean of
        |diff[i+1] / diff[i]| over ``differences``; NaN with fewer than two non-zero ones)."""
        d = [abs(x) for x in self.differences if x != 0]
        if len(d) < 2:
            return math.nan
        return (d[-1] / d[0]) ** (1.0 / (len(d) - 1))

    def why(self, label: str, truth: str) -> str:
        """One line: when and why the run(s) ``label`` and the truth ``truth`` part."""
        shown = ", ".join(f"{abs(x) * 1e3:.3g}" for x in self.differences)
        growth = (f", about {self.growth:.2g}x per impact" if math.isfinite(self.growth)
                  else "")
        return (f"{label} part{'' if ' and ' in label else 's'} from the truth ({truth}) at "
                f"{self.t:.4g} s (the truth's impact "
                f"{self.impact}), by chaos: each impact turns a small difference in when it "
                f"happens into a larger one (|impact time - truth's|: {shown} ms at impacts "
                f"1-{len(self.differences)}{growth}), and the position error then passed "
                f"{self.distance:.3g} m ({PART_FRACTION:.0%} of the dumbbell's length) at "
                f"{self.passed:.4g} s; errors after the parting measure the chaos, not the "
                "method, so the position error is reported up to it")


def parting(traj: Trajectory, truth: Trajectory, error: np.ndarray) -> Parting | None:
    """Where ``traj`` and ``truth`` (sharing their sample times; ``error`` the position error
    series, m) part by chaos: the truth's last impact before the error first passes
    :data:`PART_FRACTION` of the dumbbell's length. None if it never passes it, or passes it
    before any impact (the method's own error, not chaos)."""
    from ..solvers.advice import length

    distance = PART_FRACTION * length(truth.scene.system)
    over = np.flatnonzero(error > distance)
    if not distance > 0 or not over.size:
        return None
    passed = float(truth.t[over[0]])
    before = [i for i, e in enumerate(truth.events) if e.t < passed]
    if not before:
        return None
    k = before[-1]
    pairs = list(zip(traj.events, truth.events, strict=False))[: k + 2]
    differences = []
    for mine, true in pairs:
        if mine.body != true.body:
            break
        differences.append(mine.t - true.t)
    return Parting(truth.events[k].t, k + 1, distance, passed, tuple(differences))


@dataclass(frozen=True)
class Timing:
    """How long a run took on the solver's own clock (``Trajectory.wall_time``): ``seconds``
    warm (the fastest of ``runs`` runs after the first, or the first when it was the only
    one), and ``warm_up``, what the first run paid on top (numba's start-up and compile, or
    the load from its cache; the solver's ``warm_up()`` included): NaN when nothing was
    measured (one run of a solver with nothing to compile).

    Parameters
    ----------
    seconds : float
        The warm run time (s).
    warm_up : float
        What the first run paid on top (s).
    runs : int, default 1
        Runs timed.

    Examples
    --------
    The hand-written method's run time, timed after a warm-up run:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> timing = dumbbell.compare(scenes_dir() / "textbook-1d.toml", solvers=["euler-cromer"],
    ...                           dts=[1e-4], t_end=1.0, window=1.0).rows[0].timing
    >>> timing.seconds > 0, timing.runs >= 1
    (True, True)
    """

    seconds: float
    warm_up: float
    runs: int = 1


@dataclass(frozen=True)
class Row:
    """One compared run: its trajectory and the measures against the truth: the position
    error series (m, at the samples both have), its largest value over [0, ``error_until``]
    s (m; inf if the run stopped before then), ``error_until`` the window's end or where the
    runs part by chaos (:class:`Parting`, ``parted``) when that comes sooner, when the error
    first passed 1 mm (s) and the energy error (dimensionless, over the whole run).

    Parameters
    ----------
    label : str
        The run's label (its solver, and its dt when several).
    traj : Trajectory
        The run.
    error : numpy.ndarray
        The position error (m) at the samples both have.
    window_error : float
        Its largest value over [0, ``error_until``] s (m).
    diverged_at : float or None
        When it first passed 1 mm (s).
    energy_error : float
        The energy error over the whole run (relative).
    timing : Timing or None, default None
        Its run time.
    error_until : float, default nan
        The window's end, or where the runs part by chaos (s).
    parted : Parting or None, default None
        Where and why the runs part, if they do.

    Examples
    --------
    One run measured against the exact truth; the runs do not part within the window:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> row = dumbbell.compare(scene, solvers=["euler-cromer"], dts=[1e-4], t_end=1.0,
    ...                        window=1.0).rows[0]
    >>> row.label, round(row.window_error, 5), row.error_until, row.parted
    ('euler-cromer', 0.00151, 1.0, None)
    """

    label: str
    traj: Trajectory
    error: np.ndarray
    window_error: float
    diverged_at: float | None
    energy_error: float
    timing: Timing | None = None
    error_until: float = math.nan
    parted: Parting | None = None

    def __repr__(self) -> str:
        from .._display import one_line

        part = f" (the runs part at {self.parted.t:.4g} s)" if self.parted else ""
        return one_line(f"<Row {self.label}: largest position error {self.window_error:.3g} m "
                        f"over [0, {self.error_until:.4g}] s{part}, energy error "
                        f"{self.energy_error:.3g} and {counted(len(self.traj.events), 'impact')}"
                        f" over the whole run, verdict {self.traj.verdict.status}>")

    def _repr_html_(self) -> str:
        from .._display import html_table

        end = f"{self.traj.t[-1]:.4g}" if len(self.traj.t) else "0"
        return html_table(repr(self), [
            "run", f"largest position error over [0, {self.error_until:.4g}] s (m)",
            "runs part at (s)", "passes 1 mm at (s)", f"energy error over [0, {end}] s",
            f"impacts in [0, {end}] s", "verdict"],
            [(self.label, self.window_error, self.parted.t if self.parted else None,
              self.diverged_at, self.energy_error, len(self.traj.events),
              self.traj.verdict.status)])


@dataclass(frozen=True)
class Comparison:
    """The truth, the compared runs and the window (s) of the position errors.

    What :func:`dumbbell.compare` returns.

    Parameters
    ----------
    scene : Scene
        The scene compared.
    truth : Trajectory
        The truth's run.
    truth_note : str
        What the truth is and how exact, in words.
    rows : list of Row
        One per compared run.
    window : float
        The position errors' window [0, window] (s).
    notes : list of str, default []
        What else to know.
    truth_timing : Timing or None, default None
        The truth's run time.

    Examples
    --------
    Its one-line summary, and its table's rows: the truth, then the run.

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> result = dumbbell.compare(scene, solvers=["euler-cromer"], dts=[1e-4], t_end=1.0,
    ...                           window=1.0)
    >>> result
    <Comparison textbook-1d: truth exact; largest position error over [0, 1] s: euler-cromer 0.00151 m>
    >>> result.to_pandas().index.tolist()
    ['exact', 'euler-cromer']
    >>> result.summary()[1]["label"], round(result.summary()[1]["window_error"], 5)   # m
    ('euler-cromer', 0.00151)
    >>> first = result.impacts()[0]                    # matched in order with the truth's
    >>> first["body"], round(first["euler-cromer_diff"] * 1e3, 3)                      # ms
    ('B', 0.046)
    >>> result.impacts_to_pandas().columns.tolist()
    ['body', 'truth_t', 'euler-cromer_t', 'euler-cromer_diff']
    """

    scene: Scene
    truth: Trajectory
    truth_note: str
    rows: list[Row]
    window: float
    notes: list[str] = field(default_factory=list)
    truth_timing: Timing | None = None

    def __repr__(self) -> str:
        """One line: the scene, the truth, and each run's largest position error."""
        from .._display import one_line

        runs = ", ".join(f"{r.label} {r.window_error:.3g} m"
                         + (f" (to {r.error_until:.3g} s, where the runs part)"
                            if r.error_until < self.window else "") for r in self.rows)
        return one_line(f"<Comparison {self.scene.name}: truth {self.truth.solver}; largest "
                        f"position error over [0, {self.window:g}] s: {runs or 'no runs'}>")

    def _repr_html_(self) -> str:
        """The one-line summary above the table ``dumbbell compare`` prints (times in s,
        position errors in m)."""
        from .._display import html_table

        head = ["run", "dt (s)", "run time (s)", "warm-up (s)", "steps/s",
                "max |dr| (m)", "... over [0, T] s: T", "runs part at (s)",
                "|dr| > 1 mm at (s)", "energy error", "impacts", "... over [0, T] s: T",
                "verdict"]
        rows = [(r["label"], r["dt"], r["wall_time"], r["warm_up"], r["steps_per_s"],
                 "(truth)" if i == 0 else r["window_error"], r["error_until"], r["parted_at"],
                 r["diverged_at"], r["energy_error"], r["impacts"], r["run_until"],
                 r["verdict"].status)
                for i, r in enumerate(self.summary())]
        return html_table(repr(self), head, rows, [f"truth: {self.truth_note}", *self.notes])

    def summary(self) -> list[dict[str, object]]:
        """One record per run, the truth first, keyed by label: solver, dt (s; None for the
        step-free truths), warm run time (s), steps/s, the largest position error (m; NaN for
        the truth) over [0, ``error_until``] s (the window, or up to where the runs part by
        chaos, ``parted_at`` s, when sooner; None if they do not), when it first passed 1 mm
        (s; None if never), energy error (the truth's own drift; NaN for a dissipative truth,
        which has nothing to be measured against) and impacts, both over the whole run,
        [0, ``run_until``] s, verdict and the first run's warm-up (s, :class:`Timing`; see
        :data:`SUMMARY_UNITS`).

        Returns
        -------
        list of dict
            One per run, the truth first.
        """
        out = []
        for row in [None, *self.rows]:
            r = self.truth if row is None else row.traj
            timing = (self.truth_timing if row is None else row.timing) or Timing(
                r.wall_time, math.nan)
            steps = r.info.get("steps")
            seconds = timing.seconds
            out.append({
                "label": r.solver if row is None else row.label, "solver": r.solver,
                "dt": r.dt if r.dt and steps is not None else None,
                "wall_time": seconds,
                "steps_per_s": steps / seconds if steps and seconds > 0 else None,
                "window_error": math.nan if row is None else row.window_error,
                "error_until": math.nan if row is None else row.error_until,
                "parted_at": None if row is None or row.parted is None else row.parted.t,
                "diverged_at": None if row is None else row.diverged_at,
                "energy_error": _energy_error(r, None) if row is None else row.energy_error,
                "impacts": len(r.events),
                "run_until": float(r.t[-1]) if len(r.t) else 0.0,
                "verdict": r.verdict, "warm_up": timing.warm_up})
        return out

    def to_pandas(self) -> pandas.DataFrame:
        """:meth:`summary` as a DataFrame indexed by label, the verdict as text, units in
        ``df.attrs["units"]``. Needs pip install 'dumbbell[pandas]'.

        Returns
        -------
        pandas.DataFrame
            One row per run.

        Raises
        ------
        MissingExtraError
            pandas is not installed.
        """
        from ..frames import data_frame

        records = self.summary()
        columns = {name: [rec[name] for rec in records] for name in ["label", *SUMMARY_UNITS]}
        columns["verdict"] = [str(v) for v in columns["verdict"]]
        columns["dt"] = [math.nan if v is None else v for v in columns["dt"]]
        return data_frame(columns, index="label", units=SUMMARY_UNITS)

    def impacts_to_pandas(self) -> pandas.DataFrame:
        """:meth:`impacts` as a DataFrame indexed by impact number (times in s).

        Returns
        -------
        pandas.DataFrame
            One row per impact.

        Raises
        ------
        MissingExtraError
            pandas is not installed.
        """
        from ..frames import data_frame

        records = self.impacts()
        names = list(records[0]) if records else ["n", "body", "truth_t"]
        return data_frame({c: [r[c] for r in records] for c in names}, index="n",
                          units={c: "" if c in ("n", "body") else "s" for c in names})

    def impacts(self) -> list[dict[str, object]]:
        """Impacts matched in order: truth time and body, then each run's time and its
        difference from the truth (s).

        Returns
        -------
        list of dict
            One per impact: ``n``, ``body``, ``truth_t``, then ``{label}_t`` and ``{label}_diff``
            per run.
        """
        out = []
        for i, ev in enumerate(self.truth.events):
            rec: dict[str, object] = {"n": i + 1, "body": ev.body, "truth_t": ev.t}
            for row in self.rows:
                other = row.traj.events[i] if i < len(row.traj.events) else None
                same = other is not None and other.body == ev.body
                rec[f"{row.label}_t"] = other.t if other else math.nan
                rec[f"{row.label}_diff"] = other.t - ev.t if same else math.nan
            out.append(rec)
        return out


def default_solvers(scene: Scene) -> list[str]:
    """The engine, and the hand-written method that shares its step order or the textbook's."""
    return [cls.name for cls in _default_solvers(args.scene(scene))]


def _default_solvers(scene: Scene) -> list[type[Solver]]:
    names = ["pymunk", "euler-cromer" if scene.system.dimensions == 1 else "euler-cromer-2d"]
    return [METHODS[n] for n in names if METHODS[n]._supports(scene) is None]


@dataclass(frozen=True)
class CompareOptions:
    """What :func:`compare` runs: ``solvers`` (names or Solver classes; None:
    :func:`default_solvers`) at each step in ``dts`` (s; None: the scene's) over ``t_end``
    (s; None: the scene's), the position error over [0, ``window``] s, quietly or with
    progress bars. Built once, checked once."""

    solvers: tuple[type[Solver], ...] | None = None
    dts: tuple[float, ...] | None = None
    window: float = WINDOW
    t_end: float | None = None
    quiet: bool = True

    def __post_init__(self) -> None:
        check(self, {"solvers": "solvers", "dts": "steps?", "window": "seconds",
                     "t_end": "seconds?", "quiet": "flag"})


def compare(scene: Scene | str | Path, options: CompareOptions) -> Comparison:
    """Run the solvers of ``options`` (:class:`CompareOptions`) at each of its steps, and
    the truth, sampled at the same times, and measure them. Raises UsageError before running
    anything if a solver cannot run the scene."""
    scene = args.scene(scene)
    options = args.instance(options, "options", CompareOptions, "CompareOptions")
    solvers = options.solvers or tuple(_default_solvers(scene))
    dts = list(options.dts or (scene.run.dt,))
    t_end = scene.run.t_end if options.t_end is None else options.t_end
    window = options.window
    for cls in solvers:
        reason = cls._supports(scene)
        if reason is not None:
            raise UsageError(f"solvers: {cls.name!r} cannot run {scene.source}: {reason}",
                             param="solvers")
    _check_work(solvers, dts, t_end)
    spacing = _spacing(scene, dts, t_end)
    _check_kept(len(solvers), len(dts), round(t_end / spacing) + 1, spacing, t_end)
    # Every run's own work budget (the exact truth's impacts), before the first run.
    truth_cls = truth_class(scene)
    for cls in [*solvers, *([truth_cls] if truth_cls else [])]:
        cls._check_work(scene, run_options(scene, spacing, t_end))
    (truth, truth_timing), truth_note = _truth(scene, truth_cls, min(dts), (spacing, t_end),
                                               options.quiet)
    rows = []
    for cls in solvers:
        for dt in dts:
            run, timing = _timed(scene, cls, replace(
                run_options(scene, dt, t_end, round(spacing / dt)), quiet=options.quiet))
            err = _position_error_series(run, truth)
            over = np.flatnonzero(err > DIVERGED)
            label = cls.name if len(dts) == 1 else f"{cls.name} dt={dt:g}"
            parted = parting(run, truth, err)
            until = min(window, t_end) if parted is None else min(window, t_end, parted.t)
            rows.append(Row(label, run, err, _position_error(run, truth, until),
                            float(run.t[over[0]]) if over.size else None,
                            _energy_error(run, truth), timing, until, parted))
    notes = []
    if t_end < window:
        notes.append(f"note: the run ends at {t_end:g} s, inside the {window:g} s window")
    # One line per parting: runs that part alike (same impact, same differences) share it.
    alike: dict[Parting, list[str]] = {}
    for row in rows:
        if row.parted is not None and row.parted.t < min(window, t_end):
            alike.setdefault(row.parted, []).append(row.label)
    for part, labels in alike.items():
        names = ", ".join(labels[:-1]) + " and " + labels[-1] if len(labels) > 1 else labels[0]
        notes.append(part.why(names, truth.solver))
    return Comparison(scene, truth, truth_note, rows, min(window, t_end), notes, truth_timing)


def timed_run(scene: Scene, name: str, **options: object) -> tuple[Trajectory, Timing]:
    """One run of solver ``name`` (``simulate``'s keywords) and its warm :class:`Timing`: the
    solver's ``warm_up()`` first, then the run that is kept; a run shorter than
    :data:`TIME_AGAIN_BELOW` s, and any run of a solver without a step, is timed again (the
    runs are deterministic) until :data:`TIMED` s are timed, at most :data:`MAX_TIMED_RUNS`
    times."""
    from ..solvers import available, make_options

    scene = args.scene(scene)
    cls = METHODS[args.choice(name, "name", available())]
    return _timed(scene, cls, make_options(scene, **options))


def _timed(scene: Scene, cls: type[Solver], options: RunOptions) -> tuple[Trajectory, Timing]:
    """:func:`timed_run` of checked values."""
    compiled = cls.warm_up()
    first = cls._solve(scene, options)
    again: list[float] = []
    # A step-free solver (exact, reference) may compile or load its code in its first run,
    # however long that took on a busy machine: it is always timed again.
    if first.wall_time < TIME_AGAIN_BELOW or not cls.has_step:
        quiet = replace(options, quiet=True)
        while sum(again) < TIMED and len(again) < MAX_TIMED_RUNS:
            again.append(cls._solve(scene, quiet).wall_time)
    seconds = min(again) if again else first.wall_time
    # Measured only: the first run's excess when there were later runs, plus the compile.
    parts = [p for p in (max(0.0, first.wall_time - seconds) if again else math.nan, compiled)
             if not math.isnan(p)]
    return first, Timing(seconds, sum(parts) if parts else math.nan, 1 + len(again))


def _check_work(solvers: list[str], dts: list[float], t_end: float) -> None:
    """UsageError before any run when solvers x steps pass the budget of runs, or their
    steps together the budget of steps (:mod:`.budget`)."""
    from .budget import check_runs, check_steps

    fixes = [f for f, n in (("fewer steps ({dts})", len(dts)),
                            ("fewer {solvers}", len(solvers))) if n > 1]
    check_runs(len(solvers) * len(dts), f"{len(solvers)} solvers x {len(dts)} steps", fixes)
    steps = len(solvers) * sum(t_end / dt for dt in dts)
    check_steps(steps, f"{len(solvers)} solvers x {len(dts)} steps over {t_end:g} s",
                [*fixes, "larger steps ({dts})", "a shorter {t_end}"])


def _check_kept(solvers: int, dts: int, samples: int, spacing: float, t_end: float) -> None:
    """UsageError before any run when ``solvers`` x ``dts`` runs and the truth, which the
    result keeps whole, would hold more samples in all than one run may keep
    (:data:`~dumbbell.solvers.MAX_SAMPLES`): memory bounded by the output, not by the
    number of steps asked for."""
    from ..solvers import MAX_SAMPLES

    runs = solvers * dts + 1
    if runs * samples > MAX_SAMPLES:
        raise UsageError(f"t_end = {t_end:g} s: {runs:,} runs of {samples:,} samples (one every "
                         f"{spacing:g} s) would keep {runs * samples:,} samples in all, past "
                         f"the budget of {MAX_SAMPLES:,}", param="t_end",
                         fixes=(["fewer steps ({dts})"] if dts > 1 else [])
                         + (["fewer {solvers}"] if solvers > 1 else []) + ["a shorter {t_end}"])


def _spacing(scene: Scene, dts: list[float], t_end: float) -> float:
    """The one sample spacing (s) of every run, so that they compare point by point: the
    largest dt or the scene's dt * every, which each dt must divide. UsageError before
    anything runs if a dt does not fit or the samples would pass the budget."""
    from ..solvers import MAX_SAMPLES

    spacing = max(max(dts), scene.run.dt * scene.run.every)
    for dt in dts:
        try:
            run_options(scene, dt, t_end)  # validates dt against t_end
        except UsageError as exc:
            raise UsageError(f"dts: {exc.reason}", param="dts", fixes=exc.fixes) from None
        ratio = spacing / dt
        if abs(ratio - round(ratio)) > 1e-6 * ratio:
            raise UsageError(f"dts: dt {dt:g}: must divide the sample spacing {spacing:g} s "
                             "(the largest dt, or the scene's dt * every) a whole number of "
                             "times", param="dts")
    # Every run keeps a sample each `spacing` s: refuse before running what would not fit.
    samples = round(t_end / spacing) + 1  # finite: t_end / dt passed the step cap above
    if samples > MAX_SAMPLES:
        raise UsageError(f"t_end = {t_end:g}: each run keeps a sample every {spacing:g} s, "
                         f"{samples:,} samples, past the budget of {MAX_SAMPLES:,}",
                         param="t_end", fixes=("lower {t_end}",))
    return spacing


def _truth(scene: Scene, cls: type[Solver] | None, dt_min: float,
           samples: tuple[float, float], quiet: bool) -> tuple[tuple[Trajectory, Timing], str]:
    """The run every solver is measured against, with samples = (spacing, t_end) in s, its
    timing, and a note saying what it is: the scene's truth solver ``cls``, or pymunk at a
    tenth of the smallest step ``dt_min`` (s) where there is none."""
    from ..solvers import no_truth_reason

    spacing, t_end = samples
    if cls is None:
        truth_dt = dt_min / 10
        timed = _timed(scene, METHODS["pymunk"], replace(run_options(
            scene, truth_dt, t_end, round(spacing / truth_dt)), quiet=quiet))
        why = no_truth_reason(scene)
        return timed, (f"pymunk at dt = {truth_dt:g} s (no exact or reference solution: "
                       f"{why}; so errors are against a ten times smaller step)")
    timed = truth, _ = _timed(scene, cls, replace(run_options(scene, spacing, t_end, 1),
                                                  quiet=quiet))
    truth_note = cls.name
    est = truth.info.get("estimated_error")
    if est:
        method = ("RK8 on d = rA - rB, no impact missed" if truth.info.get("rk_steps")
                  is not None else "DOP853, rtol 1e-12")
        truth_note += (f" ({method}; its own estimated error: "
                       f"{est['position_m_window']:.1e} m over [0, {est['window_s']:g}] s, "
                       f"energy {est['energy_relative']:.1e})")
    elif cls.name == "exact":
        truth_note += (" (closed form; each impact located to about 1e-14 s, which the "
                       "chaotic map amplifies about 10x per impact)")
    return timed, truth_note
