"""Comparing solvers on one scene against the most accurate solution available.

The truth is the ``exact`` solution in 1D and for the rigid 2D dumbbell (its flight in closed
form), and the ``reference`` (DOP853 at 1e-12) for a 2D spring; a
scene with friction has neither, so there the truth is pymunk at a ten times smaller step (the
report says so). Each other run is measured against it:

- impact times side by side, matched in order, with their differences;
- the position error (the distance of either particle from its true place) at each sample,
  its largest value over a window (default 2 s): the motion is chaotic, so later errors say
  nothing about the method (docs/physics.md, on chaos), and the time at which it first passes
  1 mm;
- the energy error over the whole run (drift from E(0) relative to the energy scale; for a
  dissipative scene the distance from the truth's E);
- the run time.

The measures are :mod:`dumbbell.analysis.metrics`', the same as ``bench`` reports.

>>> result = compare(load_scene("scenes/textbook-1d.toml"))       # doctest: +SKIP
>>> print(dumbbell.io.compare.text(result))                         # doctest: +SKIP
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import UsageError
from ..model.scene import Scene
from ..model.trajectory import Trajectory
from ..solvers import no_truth_reason, solver_class, truth_solver
from .metrics import energy_error, position_error, position_error_series

if TYPE_CHECKING:
    import pandas

#: Default window (s) for position errors.
WINDOW = 2.0

__all__ = ["Comparison", "Row", "compare", "default_solvers"]

#: Position error (m) whose first passing is reported as the divergence time.
DIVERGED = 1e-3


#: Columns of :meth:`Comparison.summary` and their units.
SUMMARY_UNITS = {"solver": "", "dt": "s", "wall_time": "s", "steps_per_s": "1/s",
                 "window_error": "m", "diverged_at": "s", "energy_error": "1", "impacts": "",
                 "verdict": ""}


@dataclass(frozen=True)
class Row:
    """One compared run: its trajectory and the measures against the truth: the position
    error series (m, at the samples both have), its largest value over the window (m; inf if
    the run stopped before the window ended), when it first passed 1 mm (s) and the energy
    error (dimensionless)."""

    label: str
    traj: Trajectory
    error: np.ndarray
    window_error: float
    diverged_at: float | None
    energy_error: float


@dataclass(frozen=True)
class Comparison:
    """The truth, the compared runs and the window (s) of the position errors."""

    scene: Scene
    truth: Trajectory
    truth_note: str
    rows: list[Row]
    window: float
    notes: list[str] = field(default_factory=list)

    def summary(self) -> list[dict[str, object]]:
        """One record per run, the truth first, keyed by label: solver, dt (s; None for the
        step-free truths), run time (s), steps/s, the largest position error over the window
        (m; NaN for the truth), when it first passed 1 mm (s; None if never), energy error
        (the truth's own drift; NaN for a dissipative truth, which has nothing to be measured
        against), impacts and verdict (see :data:`SUMMARY_UNITS`)."""
        out = []
        for row in [None, *self.rows]:
            r = self.truth if row is None else row.traj
            steps = r.info.get("steps")
            out.append({
                "label": r.solver if row is None else row.label, "solver": r.solver,
                "dt": r.dt if r.dt and solver_class(r.solver).has_step else None,
                "wall_time": r.wall_time,
                "steps_per_s": steps / r.wall_time if steps and r.wall_time > 0 else None,
                "window_error": math.nan if row is None else row.window_error,
                "diverged_at": None if row is None else row.diverged_at,
                "energy_error": energy_error(r, None) if row is None else row.energy_error,
                "impacts": len(r.events),
                "verdict": r.verdict})
        return out

    def to_pandas(self) -> pandas.DataFrame:
        """:meth:`summary` as a DataFrame indexed by label, the verdict as text, units in
        ``df.attrs["units"]``. Needs pip install 'dumbbell[pandas]'."""
        from ..io.frames import data_frame

        records = self.summary()
        columns = {name: [rec[name] for rec in records] for name in ["label", *SUMMARY_UNITS]}
        columns["verdict"] = [str(v) for v in columns["verdict"]]
        columns["dt"] = [math.nan if v is None else v for v in columns["dt"]]
        return data_frame(columns, index="label", units=SUMMARY_UNITS)

    def impacts_to_pandas(self) -> pandas.DataFrame:
        """:meth:`impacts` as a DataFrame indexed by impact number (times in s)."""
        from ..io.frames import data_frame

        records = self.impacts()
        names = list(records[0]) if records else ["n", "body", "truth_t"]
        return data_frame({c: [r[c] for r in records] for c in names}, index="n",
                          units={c: "" if c in ("n", "body") else "s" for c in names})

    def impacts(self) -> list[dict[str, object]]:
        """Impacts matched in order: truth time and body, then each run's time and its
        difference from the truth (s)."""
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
    from ..model import args

    scene = args.scene(scene)
    names = ["pymunk", "euler-cromer" if scene.system.dimensions == 1 else "euler-cromer-2d"]
    return [n for n in names if solver_class(n).supports(scene) is None]


def compare(scene: Scene | str | Path, solvers: list[str] | None = None,
            dts: list[float] | None = None, window: float = WINDOW, t_end: float | None = None, quiet: bool = True
            ) -> Comparison:
    """Run ``solvers`` (default :func:`default_solvers`) at each step in ``dts`` (s; default
    the scene's) and the truth, sampled at the same times, and measure them. Raises
    UsageError before running anything if a solver cannot run the scene."""
    from ..model import args
    from ..solvers import available, simulate

    scene = args.scene(scene)
    solvers = default_solvers(scene) if solvers is None else args.names(solvers, "solvers",
                                                                         available())
    dts = [scene.run.dt] if dts is None else args.positives(dts, "dts", "s")
    t_end = scene.run.t_end if t_end is None else args.real(t_end, "t_end", "s")
    window = args.real(window, "window", "s")
    quiet = args.flag(quiet, "quiet")
    for name in solvers:
        reason = solver_class(name).supports(scene)
        if reason is not None:
            raise UsageError(f"solvers: {name!r} cannot run {scene.source}: {reason}", param="solvers")
    if not (window > 0 and math.isfinite(window)):
        raise UsageError(f"window = {window!r}: must be a finite number > 0 (s)", param="window")
    _check_work(solvers, dts, t_end)
    spacing = _spacing(scene, dts, t_end)
    _check_kept(len(solvers), len(dts), round(t_end / spacing) + 1, spacing, t_end)
    # Every run's own work budget (the exact truth's impacts), before the first run.
    from ..solvers import make_options

    truth_name = truth_solver(scene)
    for name in [*solvers, *([truth_name] if truth_name else [])]:
        solver_class(name).check_work(scene, make_options(scene, spacing, t_end))
    truth, truth_note = _truth(scene, min(dts), spacing, t_end, quiet)
    rows = []
    for name in solvers:
        for dt in dts:
            run = simulate(scene, name, dt=dt, t_end=t_end, every=round(spacing / dt),
                           quiet=quiet)
            err = position_error_series(run, truth)
            over = np.flatnonzero(err > DIVERGED)
            label = name if len(dts) == 1 else f"{name} dt={dt:g}"
            rows.append(Row(label, run, err, position_error(run, truth, window),
                            float(run.t[over[0]]) if over.size else None,
                            energy_error(run, truth)))
    notes = []
    if t_end < window:
        notes.append(f"note: the run ends at {t_end:g} s, inside the {window:g} s window")
    return Comparison(scene, truth, truth_note, rows, min(window, t_end), notes)



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
    from ..solvers import MAX_SAMPLES, make_options

    spacing = max(max(dts), scene.run.dt * scene.run.every)
    for dt in dts:
        try:
            make_options(scene, dt, t_end)  # validates dt against t_end
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


def _truth(scene: Scene, dt_min: float, spacing: float, t_end: float,
           quiet: bool) -> tuple[Trajectory, str]:
    """The run every solver is measured against, sampled every ``spacing`` (s), and a note
    saying what it is: the scene's truth solver, or pymunk at a tenth of the smallest step
    ``dt_min`` (s) where there is none."""
    from ..solvers import simulate

    truth_name = truth_solver(scene)
    if truth_name is None:
        truth_dt = dt_min / 10
        truth = simulate(scene, "pymunk", dt=truth_dt, t_end=t_end,
                         every=round(spacing / truth_dt), quiet=quiet)
        why = no_truth_reason(scene)
        return truth, (f"pymunk at dt = {truth_dt:g} s (no exact or reference solution: "
                       f"{why}; so errors are against a ten times smaller step)")
    truth = simulate(scene, truth_name, dt=spacing, t_end=t_end, every=1, quiet=quiet)
    truth_note = truth_name
    est = truth.info.get("estimated_error")
    if est:
        method = ("RK8 on d = rA - rB, no impact missed" if truth.info.get("rk_steps")
                  is not None else "DOP853, rtol 1e-12")
        truth_note += (f" ({method}; its own estimated error: "
                       f"{est['position_m_window']:.1e} m over [0, {est['window_s']:g}] s, "
                       f"energy {est['energy_relative']:.1e})")
    elif truth_name == "exact":
        truth_note += (" (closed form; each impact located to about 1e-14 s, which the "
                       "chaotic map amplifies about 10x per impact)")
    return truth, truth_note
