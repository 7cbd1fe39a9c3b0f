"""Parameter sweeps: one scene run over a grid of values, on a process pool or a Dask cluster.

>>> axes = [parse_axis("k=log:1e2:1e7:50"), parse_axis("dt=log:1e-6:1e-2:50")]  # doctest: +SKIP
>>> result = run_sweep(load_scene("scenes/textbook-1d.toml"), axes, SweepOptions(t_end=1.0))  # doctest: +SKIP
>>> dumbbell.io.sweep.write_csv(result, "sweep.csv"); dumbbell.plot.sweep_map(result)  # doctest: +SKIP

A grid axis is ``NAME=SPEC``: NAME a dotted scene key (``spring.stiffness``, ``bodies.A.mass``,
``run.dt``; ``k`` and ``dt`` are short for the first and last), SPEC one of ``log:A:B:N``
(N values spaced evenly in log), ``lin:A:B:N`` or a comma-separated list. Every point is
validated as a scene before anything runs. Each point records its verdict, w*dt, the time of
failure and the largest relative energy error over its samples. Rows come back in grid order
whichever backend ran them, and :mod:`dumbbell.io.sweep` writes floats with ``repr``, so the CSV
is byte-identical on one process, a local pool or a Dask cluster.

Work is bounded: a point may take at most :data:`MAX_STEPS_PER_POINT` steps and a sweep
:data:`MAX_STEPS_TOTAL`; a point keeps at most :data:`MAX_SAMPLES` samples (every N-th step),
so the largest energy error is taken over those samples.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .._display import counted
from ..errors import DumbbellError, UsageError
from ..model import args
from ..model.scene import Scene
from ..model.trajectory import COMPLETE
from ..parallel import Backend, ordered_map
from ..solvers import Solver, scene_class, solver_class
from ._fields import check

if TYPE_CHECKING:
    import pandas

__all__ = ["Axis", "PointResult", "SweepResult"]

#: Short names accepted on the command line for the most swept keys.
SHORT_NAMES = {"k": "spring.stiffness", "dt": "run.dt"}
#: Largest number of time steps one grid point may take (about 2.5 s of Euler-Cromer).
MAX_STEPS_PER_POINT = 10**8
#: Largest number of time steps a whole sweep may take.
MAX_STEPS_TOTAL = 10**10
#: Largest number of grid points.
MAX_POINTS = 250_000
#: Samples kept per point: every N-th step with N chosen to stay below this.
MAX_SAMPLES = 20_000
#: Largest number of values on one axis.
MAX_AXIS_VALUES = 10_000


@dataclass(frozen=True)
class Axis:
    """One axis of a sweep's grid: a dotted scene key and the values it takes, in the order
    the grid runs them.

    Parameters
    ----------
    key : str
        The dotted scene key (``spring.stiffness``; ``k`` and ``dt`` are short names for it
        and ``run.dt``).
    text : str
        The text it came from (``"k=log:1e2:1e7:8"``).
    values : tuple
        Its values, in order.
    spacing : {'log', 'lin', 'list'}
        How they are spaced.

    Examples
    --------
    A list of values makes an axis spaced ``list``:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> result = dumbbell.sweep(scenes_dir() / "textbook-1d.toml",
    ...                         {"k": [200.0, 2e6], "dt": [1e-5, 1e-3]}, t_end=0.5, workers=1)
    >>> result.axes[0]
    Axis(key='spring.stiffness', text='k=200.0,2000000.0', values=(200.0, 2000000.0), spacing='list')
    """

    key: str
    text: str
    values: tuple[Any, ...]
    spacing: str

    @property
    def numeric(self) -> bool:
        return all(isinstance(v, int | float) and not isinstance(v, bool) for v in self.values)


def _show(value: Any) -> str:
    """A value of the grid for a message: quoted, at most 60 characters (a 10,000-value
    list is not echoed whole)."""
    from ..model import args

    return args.show(value)


def _number(text: str, flag: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise UsageError(f"grid {_show(flag)}: {_show(text)} is not a finite number", param="grid")
    return value


def _list_value(text: str) -> Any:
    """An explicit list item: a whole number, a number, true/false, or else a string."""
    text = text.strip()
    for kind in (int, float):
        try:
            value = kind(text)
        except ValueError:
            continue
        if isinstance(value, float) and not math.isfinite(value):
            break
        return value
    if text in ("true", "false"):
        return text == "true"
    return text


def parse_axis(text: str) -> Axis:
    """Parse one grid axis (the command's ``--grid`` item), ``NAME=log:A:B:N``, ``NAME=lin:A:B:N`` or ``NAME=v1,v2,...``
    (UsageError naming the item and what is allowed)."""
    form = "NAME=log:A:B:N, NAME=lin:A:B:N or NAME=V1,V2,..."
    if not isinstance(text, str):
        raise UsageError(f"text = {args.show(text)}: must be a grid axis, {form}", param="text")
    name, sep, spec = text.partition("=")
    name, spec = name.strip(), spec.strip()
    if not sep or not name or not spec:
        raise UsageError(f"grid {_show(text)}: must be {form}", param="grid")
    key = SHORT_NAMES.get(name, name)
    if not all(part.isidentifier() or part in ("A", "B") for part in key.split(".")):
        raise UsageError(f"grid {_show(text)}: {_show(name)} is not a dotted scene key such as "
                         "spring.stiffness, bodies.A.mass or run.dt (k and dt are short names)", param="grid")
    kind = spec.split(":", 1)[0]
    if kind in ("log", "lin"):
        return Axis(key, text, _spaced_values(text, name, kind, spec), kind)
    return Axis(key, text, _listed_values(text, spec, form), "list")


def _spaced_values(text: str, name: str, kind: str, spec: str) -> tuple[float, ...]:
    """The N values of ``spec`` = ``log:A:B:N`` (geometric) or ``lin:A:B:N`` (even) of the
    grid item ``text`` for the key ``name``."""
    parts = spec.split(":")
    if len(parts) != 4:
        raise UsageError(f"grid {_show(text)}: must be {name}={kind}:A:B:N", param="grid")
    a, b = _number(parts[1], text), _number(parts[2], text)
    try:
        n = int(parts[3])
    except ValueError:
        n = 0
    if not 2 <= n <= MAX_AXIS_VALUES:
        raise UsageError(f"grid {_show(text)}: N = {_show(parts[3])} must be a whole number from 2 "
                         f"to {MAX_AXIS_VALUES}", param="grid")
    if a == b:
        raise UsageError(f"grid {_show(text)}: A and B must differ", param="grid")
    if kind == "log":
        if a <= 0 or b <= 0:
            raise UsageError(f"grid {_show(text)}: log spacing needs A > 0 and B > 0", param="grid")
        return tuple(float(v) for v in np.geomspace(a, b, n))
    return tuple(float(v) for v in np.linspace(a, b, n))


def _listed_values(text: str, spec: str, form: str) -> tuple[Any, ...]:
    """The values of ``spec`` = ``V1,V2,...`` of the grid item ``text``, each once."""
    items = [s for s in spec.split(",")]
    if any(not s.strip() for s in items):
        raise UsageError(f"grid {_show(text)}: an empty value in the list; must be {form}", param="grid")
    if len(items) > MAX_AXIS_VALUES:
        raise UsageError(f"grid {_show(text)}: at most {MAX_AXIS_VALUES} values", param="grid")
    values = tuple(_list_value(s) for s in items)
    if len(set(map(repr, values))) != len(values):
        raise UsageError(f"grid {_show(text)}: a value is listed twice", param="grid")
    return values


def _check_axis_list(axes: Any) -> None:
    if not isinstance(axes, list | tuple) or not all(isinstance(a, Axis) for a in axes):
        raise UsageError(f"axes = {args.show(axes)}: must be a list of Axis (parse_axis)",
                         param="axes")


def check_axes(axes: Sequence[Axis]) -> None:
    """One or two axes on different keys (UsageError otherwise)."""
    _check_axis_list(axes)
    if not 1 <= len(axes) <= 2:
        raise UsageError(f"grid: give one or two axes (got {len(axes)}), e.g. "
                         "k=log:1e2:1e7:50 dt=log:1e-6:1e-2:50", param="grid")
    if len(axes) == 2 and axes[0].key == axes[1].key:
        raise UsageError(f"grid: {_show(axes[0].text)} and {_show(axes[1].text)} sweep the same key "
                         f"{axes[0].key}", param="grid")
    if math.prod(len(a.values) for a in axes) > MAX_POINTS:
        raise UsageError(f"grid: {math.prod(len(a.values) for a in axes)} points; a sweep "
                         f"allows at most {MAX_POINTS}", param="grid")


@dataclass(frozen=True)
class Point:
    """One grid point: its index in grid order and the dotted values it sets."""

    index: int
    values: dict[str, Any]


def plan(scene: Scene, axes: Sequence[Axis], solver: str | type[Solver],
         t_end: float | None = None) -> list[Point]:
    """Every grid point, validated as a scene and as a bounded run before anything runs.

    ``solver`` is a name or a Solver class; ``t_end`` (s) overrides the scene's
    ``run.t_end``. Raises UsageError naming the axis."""
    scene = args.scene(scene)
    check_axes(axes)
    return _plan(scene, axes, solver_class(solver),
                 None if t_end is None else args.real(t_end, "t_end", "s"))


def _plan(scene: Scene, axes: Sequence[Axis], cls: type[Solver], t_end: float | None
          ) -> list[Point]:
    from ..solvers.base import run_options

    fixed = {"run.t_end": t_end} if t_end is not None else {}
    points, total = [], 0
    for index, combo in enumerate(itertools.product(*(a.values for a in axes))):
        values = {**fixed, **{a.key: v for a, v in zip(axes, combo, strict=True)}}
        where = ", ".join(f"{a.key} = {_show(v)}" for a, v in zip(axes, combo, strict=True))
        try:
            point_scene = scene.with_values(values)
        except DumbbellError as exc:
            raise UsageError(f"grid at {where}: {exc}", param="grid") from None
        reason = cls._supports(point_scene)
        if reason is not None:
            raise UsageError(f"grid at {where}: solver {cls.name!r} cannot run it: {reason}",
                             param="grid")
        try:
            options = run_options(point_scene)
        except DumbbellError as exc:
            raise UsageError(f"grid at {where}: {exc}", param="grid") from None
        if options.n_steps > MAX_STEPS_PER_POINT:
            raise UsageError(
                f"grid at {where}: dt = {options.dt:g} s over t_end = {options.t_end:g} s is "
                f"{options.n_steps:.3g} steps; a sweep point may take at most "
                f"{MAX_STEPS_PER_POINT:.0e}", param="grid",
                fixes=("use a larger dt", "a smaller {t_end}"))
        total += options.n_steps
        points.append(Point(index, values))
    if total > MAX_STEPS_TOTAL:
        raise UsageError(f"grid: the sweep would take {total:.3g} steps in all; at most "
                         f"{MAX_STEPS_TOTAL:.0e}", param="grid",
                         fixes=("use fewer points ({grid})", "a larger dt", "a smaller {t_end}"))
    return points


@dataclass(frozen=True)
class PointResult:
    """One grid point's run: a row of the sweep's CSV.

    Parameters
    ----------
    values : tuple of (str, value) pairs
        The dotted scene values it set, in the order given.
    w_dt : float
        w*dt (dimensionless), w = sqrt(k/mu).
    verdict : str
        The run's verdict status.
    t_fail : float or None
        The time of failure (s; None if none).
    max_rel_energy_error : float
        The largest relative energy error over the kept samples.
    reason : str
        The verdict's reason.

    Examples
    --------
    The stiffest spring at the longest step, past the explicit step's limit:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> point = dumbbell.sweep(scene, {"k": [200.0, 2e6], "dt": [1e-5, 1e-3]}, t_end=0.5,
    ...                        workers=1).rows[-1]
    >>> point.values, round(point.w_dt, 2), point.verdict
    ((('spring.stiffness', 2000000.0), ('run.dt', 0.001)), 6.32, 'unstable')
    >>> print(point.reason)
    w*dt = 6.32 > 2 (w = sqrt(k/mu) = 6325 rad/s): the step is stable only for dt < 3.16e-4 s; try dt = ...
    """

    values: tuple[tuple[str, Any], ...]
    w_dt: float
    verdict: str
    t_fail: float | None
    max_rel_energy_error: float
    reason: str

    @property
    def cells(self) -> tuple[Any, ...]:
        """The values set, then the result fields: in a sweep's rows, one CSV line's cells in
        :attr:`SweepResult.columns` order."""
        return (*(v for _, v in self.values), *(getattr(self, c) for c in RESULT_COLUMNS))


#: CSV columns after the axes: the result fields of :class:`PointResult`.
RESULT_COLUMNS = tuple(f.name for f in fields(PointResult) if f.name != "values")


def evaluate(scene: Scene, values: dict[str, Any], solver: str | type[Solver]
             ) -> PointResult:
    """Run one grid point (``scene`` with the dotted ``values`` set) with ``solver`` (a name
    or a Solver class) and summarise it as a :class:`PointResult`. A solver error becomes the
    verdict ``failed``."""
    args.instance(scene, "scene", Scene, "a Scene")
    args.mapping(values, "values", "a dict of dotted scene keys to values")
    return _evaluate(scene, values, solver_class(solver))


def _evaluate(scene: Scene, values: dict[str, Any], cls: type[Solver]) -> PointResult:
    from ..model.energy import _relative_energy_error
    from ..solvers import runnable
    from ..solvers.base import run_options

    point = scene.with_values(values)
    pairs = tuple(values.items())
    options = run_options(point)
    every = max(1, math.ceil(options.n_steps / (MAX_SAMPLES - 1)))
    w_dt = point.system.omega * options.dt
    try:
        runnable(cls, point)
        traj = cls._solve(point, run_options(point, every=every))
        err = _relative_energy_error(traj.energy, point.system)
        finite = err[np.isfinite(err)]
        max_err = float(finite.max()) if finite.size else math.nan
        verdict = traj.verdict
        return PointResult(pairs, w_dt, verdict.status, verdict.t, max_err, verdict.reason)
    except Exception as exc:  # noqa: BLE001 - one bad point must not sink the sweep
        text = " ".join(f"{type(exc).__name__}: {exc}".split())
        return PointResult(pairs, w_dt, "failed", None, math.nan, f"solver error: {text}")


def warm_up(solver: str | type[Solver]) -> None:
    """Load a solver's compiled code (if it has any) in a worker before the work arrives."""
    solver_class(solver).warm_up()


#: Units of :data:`RESULT_COLUMNS` ("1": dimensionless).
RESULT_UNITS = {"w_dt": "1", "verdict": "", "t_fail": "s", "max_rel_energy_error": "1",
                "reason": ""}


@dataclass(frozen=True)
class SweepResult:
    """The rows of a sweep in grid order, with the axes, the scene and how long it took: what
    :func:`dumbbell.sweep` returns.

    Parameters
    ----------
    scene : Scene
        The scene swept.
    axes : list of Axis
        One or two.
    solver : str
        The solver's name.
    t_end : float
        Each run's end (s).
    rows : list of PointResult
        One per grid point, the last axis varying fastest.
    wall_time : float, default 0.0
        The sweep's run time (s).
    backend : str, default ""
        Where it ran (serial, processes, a Dask cluster).

    Examples
    --------
    Four points; one is unstable:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> result = dumbbell.sweep(scene, {"k": [200.0, 2e6], "dt": [1e-5, 1e-3]}, t_end=0.5,
    ...                         workers=1)
    >>> result.counts()
    {'ok': 3, 'unstable': 1}
    >>> result.to_pandas()["verdict"].tolist()
    ['ok', 'ok', 'ok', 'unstable']
    >>> [(line["spring.stiffness"], float(line["largest_ok_dt"])) for line in result.boundary()]
    [(200.0, 0.001), (2000000.0, 1e-05)]
    """

    scene: Scene
    axes: list[Axis]
    solver: str
    t_end: float
    rows: list[PointResult]
    wall_time: float = 0.0
    backend: str = ""

    @property
    def columns(self) -> list[str]:
        return [a.key for a in self.axes] + list(RESULT_COLUMNS)

    def __repr__(self) -> str:
        """One line: the scene, the grid, the solver, and how many points ended each way."""
        from .._display import one_line

        grid = " x ".join(f"{a.key} ({len(a.values)})" for a in self.axes)
        counts = ", ".join(f"{n:,} {v}" for v, n in sorted(self.counts().items()))
        took = f"; {self.wall_time:.3g} s on {self.backend}" if self.backend else ""
        points = counted(len(self.rows), "point", grouped=True)
        return one_line(f"<SweepResult {self.scene.name}: {points} over "
                        f"{grid}, solver {self.solver}, t_end {self.t_end:g} s: "
                        f"{counts or 'none'}{took}>")

    def _repr_html_(self) -> str:
        """The one-line summary above the points that did not end ok (all points when every
        one did), a table row each."""
        from .._display import html_table

        bad = [r for r in self.rows if r.verdict != "ok"]
        shown = bad or self.rows
        note = (f"the {counted(len(bad), 'point', grouped=True)} that did not end ok" if bad
                else "every point ended ok")
        return html_table(repr(self), self.columns, (r.cells for r in shown), [note])

    def to_pandas(self) -> pandas.DataFrame:
        """One row per grid point in grid order, the CSV's columns, units in
        ``df.attrs["units"]`` (an axis's unit is left empty: any scene key can be swept).
        Needs pip install 'dumbbell[pandas]'.

        Returns
        -------
        pandas.DataFrame
            The axes' values, then the fields of :class:`PointResult`.

        Raises
        ------
        MissingExtraError
            pandas is not installed.
        """
        from ..frames import data_frame

        units = {a.key: "" for a in self.axes} | RESULT_UNITS
        cells = list(zip(*(row.cells for row in self.rows))) or [()] * len(self.columns)
        return data_frame({c: list(v) for c, v in zip(self.columns, cells, strict=True)},
                          units=units)

    def counts(self) -> dict[str, int]:
        """How many points ended with each verdict.

        Returns
        -------
        dict of str to int
            Verdict status -> points.
        """
        out: dict[str, int] = {}
        for row in self.rows:
            out[row.verdict] = out.get(row.verdict, 0) + 1
        return out

    def boundary(self) -> list[dict[str, float]]:
        """Where a (something, run.dt) sweep stops being stable.

        Returns
        -------
        list of dict
            For each value of the other axis: that value, ``largest_ok_dt`` (the largest dt
            below which every point reached its end, ``ok`` or ``inaccurate``: the stability
            boundary, not the accuracy's; s), its ``w_dt``, ``first_failing_dt`` (s; nan if
            none) and ``theory_dt``, the theory's 2/w (s). Empty unless one of two axes is
            run.dt.
        """
        if len(self.axes) != 2 or "run.dt" not in (a.key for a in self.axes):
            return []
        di = [a.key for a in self.axes].index("run.dt")
        other = self.axes[1 - di]
        table = np.array(self.rows, dtype=object).reshape([len(a.values) for a in self.axes])
        if di == 0:
            table = table.T
        out = []
        dts = np.array(self.axes[di].values, dtype=float)
        order = np.argsort(dts)
        for value, line in zip(other.values, table, strict=True):
            ok_dt, w_dt = math.nan, math.nan
            for j in order:
                if line[j].verdict not in COMPLETE:
                    break
                ok_dt, w_dt = dts[j], line[j].w_dt
            first_bad = next((dts[j] for j in order if line[j].verdict not in COMPLETE),
                             math.nan)
            w = line[order[0]].w_dt / dts[order[0]]
            out.append({other.key: value, "largest_ok_dt": ok_dt, "w_dt": w_dt,
                        "first_failing_dt": first_bad,
                        "theory_dt": 2.0 / w if w > 0 else math.inf})
        return out


# --- backends -------------------------------------------------------------------------------


@dataclass(frozen=True)
class SweepOptions:
    """How :func:`run_sweep` runs a grid: with ``solver`` (a name or a Solver class; None:
    the scene's ``run.solver``), over ``t_end`` (s; None: the scene's), on ``workers`` local
    processes (default 1: this process; None: one per CPU; capped at one per point) or a Dask ``scheduler`` ('local'
    for a new LocalCluster, of processes unless ``processes`` is False; ``connect_timeout``
    s to reach one), quietly or with a progress bar."""

    solver: type[Solver] | None = None
    t_end: float | None = None
    workers: int | None = 1
    scheduler: str | None = None
    quiet: bool = True
    processes: bool = True
    connect_timeout: float = 10.0

    def __post_init__(self) -> None:
        check(self, {"solver": "solver?", "t_end": "seconds?", "workers": "workers?",
                     "scheduler": "text?", "quiet": "flag", "processes": "flag",
                     "connect_timeout": "seconds"})


def run_sweep(scene: Scene, axes: Sequence[Axis], options: SweepOptions,
              points: list[Point] | None = None) -> SweepResult:
    """Run ``scene`` (a Scene or a scene file's path) over the grid ``axes`` as ``options``
    say; ``points`` are the grid's points when :func:`plan` has made them already. One worker
    runs in this process; more use a process pool of at most one process per CPU and per
    point, or a Dask cluster. Rows come back in grid order."""
    from ..parallel import cap_workers

    scene = args.scene(scene)
    _check_axis_list(axes)
    options = args.instance(options, "options", SweepOptions, "SweepOptions")
    if points is not None and (not isinstance(points, list | tuple)
                               or not all(isinstance(p, Point) for p in points)):
        raise UsageError(f"points = {args.show(points)}: must be a list of Point (from plan) "
                         "or None", param="points")
    cls = options.solver or scene_class(scene)
    if points is None:
        check_axes(axes)
        points = _plan(scene, axes, cls, options.t_end)
    workers, _ = cap_workers(options.workers, len(points))
    scheduler = options.scheduler
    if scheduler is not None:
        backend, desc = f"dask {scheduler}", f"sweep {scene.name} (dask)"
        workers = workers if scheduler == "local" else 0
    elif workers == 1 or len(points) == 1:
        backend, desc, workers = "serial", f"sweep {scene.name}", 1
    else:
        backend = f"process pool of {workers}"
        desc = f"sweep {scene.name} ({workers} processes)"
    t0 = time.perf_counter()
    results = ordered_map(_evaluate, [(p.values, cls) for p in points],
                          Backend(workers, scheduler, options.processes, warm_up, (cls,),
                                  options.quiet, desc, connect_timeout=options.connect_timeout),
                          shared=scene)
    wall = time.perf_counter() - t0
    by_index = {p.index: r for p, r in zip(points, results, strict=True)}
    # A row's values are its grid coordinates only (not the t_end every point shares).
    rows = [replace(by_index[i],
                    values=tuple((a.key, v) for a, v in zip(axes, combo, strict=True)))
            for i, combo in enumerate(itertools.product(*(a.values for a in axes)))]
    t_end = options.t_end if options.t_end is not None else scene.run.t_end
    return SweepResult(scene, list(axes), cls.name, t_end, rows, wall, backend)
