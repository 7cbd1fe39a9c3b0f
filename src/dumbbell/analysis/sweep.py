"""Parameter sweeps: one scene run over a grid of values, on a process pool or a Dask cluster.

>>> axes = [parse_axis("k=log:1e2:1e7:50"), parse_axis("dt=log:1e-6:1e-2:50")]  # doctest: +SKIP
>>> result = run_sweep(load_scene("scenes/textbook-1d.toml"), axes, "euler-cromer", 1.0)  # doctest: +SKIP
>>> result.write_csv("sweep.csv"); result.draw_map("sweep.png")                 # doctest: +SKIP

A grid axis is ``NAME=SPEC``: NAME a dotted scene key (``spring.stiffness``, ``bodies.A.mass``,
``run.dt``; ``k`` and ``dt`` are short for the first and last), SPEC one of ``log:A:B:N``
(N values spaced evenly in log), ``lin:A:B:N`` or a comma-separated list. Every point is
validated as a scene before anything runs. Each point records its verdict, w*dt, the time of
failure and the largest relative energy error over its samples. Rows come back in grid order
whichever backend ran them, and floats are written with ``repr``, so the CSV is byte-identical
on one process, a local pool or a Dask cluster.

Work is bounded: a point may take at most :data:`MAX_STEPS_PER_POINT` steps and a sweep
:data:`MAX_STEPS_TOTAL`; a point keeps at most :data:`MAX_SAMPLES` samples (every N-th step),
so the largest energy error is taken over those samples.
"""

from __future__ import annotations

import csv
import io
import itertools
import math
import os
import time
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Future
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import DumbbellError, UsageError
from ..io.files import atomic_output
from ..model.scene import Scene

if TYPE_CHECKING:
    import pandas

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
#: Verdicts other than ok, and how the maps paint them.
FAIL_COLOURS = {"unstable": "#bdbdbd", "tunnelled": "#f4a582", "failed": "#4d4d4d"}
#: CSV columns after the axes.
RESULT_COLUMNS = ("w_dt", "verdict", "t_fail", "max_rel_energy_error", "reason")


@dataclass(frozen=True)
class Axis:
    """One grid axis: the dotted scene key, the text it came from, its values and how they
    are spaced ('log', 'lin' or 'list')."""

    key: str
    text: str
    values: tuple[Any, ...]
    spacing: str

    @property
    def numeric(self) -> bool:
        return all(isinstance(v, int | float) and not isinstance(v, bool) for v in self.values)


def _number(text: str, flag: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise UsageError(f"--grid {flag!r}: {text!r} is not a finite number")
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
    """Parse one ``--grid`` item, ``NAME=log:A:B:N``, ``NAME=lin:A:B:N`` or ``NAME=v1,v2,...``
    (UsageError naming the item and what is allowed)."""
    form = "NAME=log:A:B:N, NAME=lin:A:B:N or NAME=V1,V2,..."
    name, sep, spec = text.partition("=")
    name, spec = name.strip(), spec.strip()
    if not sep or not name or not spec:
        raise UsageError(f"--grid {text!r}: must be {form}")
    key = SHORT_NAMES.get(name, name)
    if not all(part.isidentifier() or part in ("A", "B") for part in key.split(".")):
        raise UsageError(f"--grid {text!r}: {name!r} is not a dotted scene key such as "
                         "spring.stiffness, bodies.A.mass or run.dt (k and dt are short names)")
    kind = spec.split(":", 1)[0]
    if kind in ("log", "lin"):
        parts = spec.split(":")
        if len(parts) != 4:
            raise UsageError(f"--grid {text!r}: must be {name}={kind}:A:B:N")
        a, b = _number(parts[1], text), _number(parts[2], text)
        try:
            n = int(parts[3])
        except ValueError:
            n = 0
        if not 2 <= n <= MAX_AXIS_VALUES:
            raise UsageError(f"--grid {text!r}: N = {parts[3]!r} must be a whole number from 2 "
                             f"to {MAX_AXIS_VALUES}")
        if a == b:
            raise UsageError(f"--grid {text!r}: A and B must differ")
        if kind == "log":
            if a <= 0 or b <= 0:
                raise UsageError(f"--grid {text!r}: log spacing needs A > 0 and B > 0")
            values = tuple(float(v) for v in np.geomspace(a, b, n))
        else:
            values = tuple(float(v) for v in np.linspace(a, b, n))
        return Axis(key, text, values, kind)
    items = [s for s in spec.split(",")]
    if any(not s.strip() for s in items):
        raise UsageError(f"--grid {text!r}: an empty value in the list; must be {form}")
    if len(items) > MAX_AXIS_VALUES:
        raise UsageError(f"--grid {text!r}: at most {MAX_AXIS_VALUES} values")
    values = tuple(_list_value(s) for s in items)
    if len(set(map(repr, values))) != len(values):
        raise UsageError(f"--grid {text!r}: a value is listed twice")
    return Axis(key, text, values, "list")


def check_axes(axes: Sequence[Axis]) -> None:
    """One or two axes on different keys (UsageError otherwise)."""
    if not 1 <= len(axes) <= 2:
        raise UsageError(f"--grid: give one or two axes (got {len(axes)}), e.g. "
                         "--grid k=log:1e2:1e7:50 dt=log:1e-6:1e-2:50")
    if len(axes) == 2 and axes[0].key == axes[1].key:
        raise UsageError(f"--grid: {axes[0].text!r} and {axes[1].text!r} sweep the same key "
                         f"{axes[0].key}")
    if math.prod(len(a.values) for a in axes) > MAX_POINTS:
        raise UsageError(f"--grid: {math.prod(len(a.values) for a in axes)} points; a sweep "
                         f"allows at most {MAX_POINTS}")


@dataclass(frozen=True)
class Point:
    """One grid point: its index in grid order and the dotted values it sets."""

    index: int
    values: dict[str, Any]


def plan(scene: Scene, axes: Sequence[Axis], solver: str, t_end: float | None = None
         ) -> list[Point]:
    """Every grid point, validated as a scene and as a bounded run before anything runs.

    ``t_end`` (s) overrides the scene's ``run.t_end``. Raises UsageError naming the axis."""
    from ..solvers import make_options, solver_class

    check_axes(axes)
    cls = solver_class(solver)
    fixed = {"run.t_end": t_end} if t_end is not None else {}
    points, total = [], 0
    for index, combo in enumerate(itertools.product(*(a.values for a in axes))):
        values = {**fixed, **{a.key: v for a, v in zip(axes, combo, strict=True)}}
        where = ", ".join(f"{a.key} = {v!r}" for a, v in zip(axes, combo, strict=True))
        try:
            point_scene = scene.with_values(values)
        except DumbbellError as exc:
            raise UsageError(f"--grid at {where}: {exc}") from None
        reason = cls.supports(point_scene)
        if reason is not None:
            raise UsageError(f"--grid at {where}: solver {solver!r} cannot run it: {reason}")
        try:
            options = make_options(point_scene)
        except DumbbellError as exc:
            raise UsageError(f"--grid at {where}: {exc}") from None
        if options.n_steps > MAX_STEPS_PER_POINT:
            raise UsageError(
                f"--grid at {where}: dt = {options.dt:g} s over t_end = {options.t_end:g} s is "
                f"{options.n_steps:.3g} steps; a sweep point may take at most "
                f"{MAX_STEPS_PER_POINT:.0e}: raise dt or lower --t-end")
        total += options.n_steps
        points.append(Point(index, values))
    if total > MAX_STEPS_TOTAL:
        raise UsageError(f"--grid: the sweep would take {total:.3g} steps in all; at most "
                         f"{MAX_STEPS_TOTAL:.0e}: use fewer points, a larger dt or a smaller "
                         "--t-end")
    return points


def evaluate(scene: Scene, values: dict[str, Any], solver: str) -> dict[str, Any]:
    """Run one grid point and summarise it: w_dt, verdict, t_fail (s or None),
    max_rel_energy_error and reason. A solver error becomes the verdict ``failed``."""
    from ..model.energy import relative_energy_error
    from ..solvers import make_options, simulate

    point = scene.with_values(values)
    options = make_options(point)
    every = max(1, math.ceil(options.n_steps / (MAX_SAMPLES - 1)))
    w_dt = point.omega * options.dt
    try:
        traj = simulate(point, solver, every=every, quiet=True)
        err = relative_energy_error(traj)
        finite = err[np.isfinite(err)]
        max_err = float(finite.max()) if finite.size else math.nan
        verdict = traj.verdict
        return {"w_dt": w_dt, "verdict": verdict.status, "t_fail": verdict.t,
                "max_rel_energy_error": max_err, "reason": verdict.reason}
    except Exception as exc:  # noqa: BLE001 - one bad point must not sink the sweep
        text = " ".join(f"{type(exc).__name__}: {exc}".split())
        return {"w_dt": w_dt, "verdict": "failed", "t_fail": None,
                "max_rel_energy_error": math.nan, "reason": f"solver error: {text}"}


def _evaluate_batch(scene: Scene, batch: list[Point], solver: str
                    ) -> list[tuple[int, dict[str, Any]]]:
    """Run a batch of points (the unit of work sent to a worker)."""
    return [(p.index, evaluate(scene, p.values, solver)) for p in batch]


def _warm_up(solver: str) -> None:
    """Load a solver's compiled code (if it has any) in a worker before the work arrives."""
    from ..solvers import solver_class

    solver_class(solver).warm_up()


def _batches(points: list[Point], workers: int) -> list[list[Point]]:
    # A few batches per worker balance the load without drowning small points in overhead.
    size = max(1, min(64, len(points) // (8 * max(1, workers))))
    # Interleave so that each batch mixes cheap and costly points (small dt is costly).
    count = math.ceil(len(points) / size)
    return [points[i::count] for i in range(count)]


#: Units of :data:`RESULT_COLUMNS` ("1": dimensionless).
RESULT_UNITS = {"w_dt": "1", "verdict": "", "t_fail": "s", "max_rel_energy_error": "1",
                "reason": ""}


@dataclass(frozen=True)
class SweepResult:
    """The rows of a sweep in grid order, with the axes, the scene and how long it took."""

    scene: Scene
    axes: list[Axis]
    solver: str
    t_end: float
    rows: list[dict[str, Any]]
    wall_time: float = 0.0
    backend: str = ""

    @property
    def columns(self) -> list[str]:
        return [a.key for a in self.axes] + list(RESULT_COLUMNS)

    def csv_text(self) -> str:
        """The CSV as text: same bytes whichever backend produced the rows."""
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(self.columns)
        for row in self.rows:
            writer.writerow([_cell(row[c]) for c in self.columns])
        return buf.getvalue()

    def write_csv(self, path: str | Path) -> Path:
        with atomic_output(path) as tmp:
            tmp.write_text(self.csv_text())
        return Path(path)

    def to_pandas(self) -> pandas.DataFrame:
        """One row per grid point in grid order, the CSV's columns, units in
        ``df.attrs["units"]`` (an axis's unit is left empty: any scene key can be swept).
        Needs pip install 'dumbbell[pandas]'."""
        from ..io.frames import data_frame

        units = {a.key: "" for a in self.axes} | RESULT_UNITS
        return data_frame({c: [row[c] for row in self.rows] for c in self.columns}, units=units)

    def counts(self) -> dict[str, int]:
        """How many points ended with each verdict."""
        out: dict[str, int] = {}
        for row in self.rows:
            out[row["verdict"]] = out.get(row["verdict"], 0) + 1
        return out

    def boundary(self) -> list[dict[str, float]]:
        """Where a (something, run.dt) sweep stops being ok: for each value of the other axis,
        the largest dt below which every point is ok, its w*dt and the theory's 2/w (s).
        Empty unless one of two axes is run.dt."""
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
                if line[j]["verdict"] != "ok":
                    break
                ok_dt, w_dt = dts[j], line[j]["w_dt"]
            first_bad = next((dts[j] for j in order if line[j]["verdict"] != "ok"), math.nan)
            w = line[order[0]]["w_dt"] / dts[order[0]]
            out.append({other.key: value, "largest_ok_dt": ok_dt, "w_dt": w_dt,
                        "first_failing_dt": first_bad,
                        "theory_dt": 2.0 / w if w > 0 else math.inf})
        return out

    def draw_map(self, path: str | Path) -> Path:
        """The map PNG: log10 of the largest relative energy error over the grid, failures
        painted by verdict, and the line w*dt = 2."""
        from ..plot.figures import _pyplot

        plt = _pyplot()
        fig, ax = plt.subplots(figsize=(8.2, 6.2) if len(self.axes) == 2 else (8.2, 4.6))
        title = (f"Sweep of {self.scene.name}: {self.solver}, t_end = {self.t_end:g} s, "
                 f"{len(self.rows)} runs")
        if len(self.axes) == 2:
            draw_map(fig, ax, self.axes[0], self.axes[1], self.rows, title)
        else:
            draw_line(ax, self.axes[0], self.rows, title)
        fig.tight_layout()
        with atomic_output(path) as tmp:
            fig.savefig(tmp, dpi=100)
        plt.close(fig)
        return Path(path)


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


# --- backends -------------------------------------------------------------------------------


def _collect(futures: Iterable[Any], as_completed: Callable[[Any], Iterable[Any]],
             n_points: int, quiet: bool, desc: str) -> list[tuple[int, dict[str, Any]]]:
    from ..progress import bar

    done: list[tuple[int, dict[str, Any]]] = []
    with bar(n_points, desc, "run", quiet=quiet) as pb:
        for fut in as_completed(futures):
            part = fut.result()
            done.extend(part)
            pb.update(len(part))
    return done


def run_serial(scene: Scene, points: list[Point], solver: str, quiet: bool = True
               ) -> list[tuple[int, dict[str, Any]]]:
    """All points in this process, in order."""
    from ..progress import bar

    out = []
    with bar(len(points), f"sweep {scene.name}", "run", quiet=quiet) as pb:
        for p in points:
            out.append((p.index, evaluate(scene, p.values, solver)))
            pb.update(1)
    return out


def run_pool(scene: Scene, points: list[Point], solver: str, workers: int, quiet: bool = True
             ) -> list[tuple[int, dict[str, Any]]]:
    """The points on a local process pool of ``workers`` processes."""
    from concurrent.futures import ProcessPoolExecutor, as_completed

    with ProcessPoolExecutor(max_workers=workers, initializer=_warm_up,
                             initargs=(solver,)) as pool:
        futures: list[Future] = [pool.submit(_evaluate_batch, scene, batch, solver)
                                 for batch in _batches(points, workers)]
        try:
            return _collect(futures, as_completed, len(points), quiet,
                            f"sweep {scene.name} ({workers} processes)")
        except BaseException:
            for fut in futures:
                fut.cancel()
            raise


def run_dask(scene: Scene, points: list[Point], solver: str, scheduler: str,
             workers: int | None = None, quiet: bool = True, processes: bool = True
             ) -> list[tuple[int, dict[str, Any]]]:
    """The points on a Dask cluster at ``scheduler`` (``tcp://host:8786``), or on a new
    LocalCluster of ``workers`` single-threaded workers when ``scheduler`` is 'local'."""
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise UsageError("--scheduler needs dask.distributed: pip install 'dumbbell[dask]'"
                         ) from None
    import contextlib

    with contextlib.ExitStack() as stack:
        if scheduler == "local":
            n = workers or os.cpu_count() or 1
            cluster = stack.enter_context(LocalCluster(
                n_workers=n, threads_per_worker=1, processes=processes,
                dashboard_address=None, silence_logs=50))
            client = stack.enter_context(Client(cluster))
        else:
            try:
                client = stack.enter_context(Client(scheduler, timeout="10s"))
            except (OSError, TimeoutError, ValueError) as exc:
                text = " ".join(str(exc).split())[:200]
                raise UsageError(f"--scheduler {scheduler}: cannot connect to a Dask "
                                 f"scheduler there ({text})") from None
        n_workers = max(1, len(client.scheduler_info().get("workers", {})))
        scattered = client.scatter(scene, broadcast=True)
        futures = [client.submit(_evaluate_batch, scattered, batch, solver, pure=False)
                   for batch in _batches(points, n_workers)]
        try:
            return _collect(futures, as_completed, len(points), quiet,
                            f"sweep {scene.name} (dask)")
        except BaseException:
            client.cancel(futures)
            raise
    raise AssertionError("unreachable")  # pragma: no cover


def run_sweep(
    scene: Scene, axes: Sequence[Axis], solver: str, t_end: float | None = None,
    workers: int | None = None, scheduler: str | None = None, quiet: bool = True,
    processes: bool = True, points: list[Point] | None = None,
) -> SweepResult:
    """Run ``scene`` over the grid ``axes`` with ``solver``; ``t_end`` (s) overrides the
    scene's. One worker runs in this process; more use a process pool; ``scheduler`` a Dask
    cluster ('local' for a new LocalCluster). Rows come back in grid order."""
    points = plan(scene, axes, solver, t_end) if points is None else points
    workers = workers or os.cpu_count() or 1
    t0 = time.perf_counter()
    if scheduler is not None:
        pairs = run_dask(scene, points, solver, scheduler, workers if scheduler == "local"
                         else None, quiet, processes)
        backend = f"dask {scheduler}"
    elif workers == 1 or len(points) == 1:
        pairs = run_serial(scene, points, solver, quiet)
        backend = "serial"
    else:
        pairs = run_pool(scene, points, solver, workers, quiet)
        backend = f"process pool of {workers}"
    wall = time.perf_counter() - t0
    by_index = dict(pairs)
    rows = [{**{a.key: v for a, v in zip(axes, combo, strict=True)}, **by_index[i]}
            for i, combo in enumerate(itertools.product(*(a.values for a in axes)))]
    return SweepResult(scene, list(axes), solver,
                       t_end if t_end is not None else scene.run.t_end, rows, wall, backend)


# --- drawing --------------------------------------------------------------------------------


def _edges(values: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around sorted centre values (midpoints, geometric on a log axis)."""
    v = np.log10(values) if log else values.astype(float)
    if len(v) == 1:
        mid = np.array([v[0] - 0.5, v[0] + 0.5])
    else:
        inner = 0.5 * (v[1:] + v[:-1])
        mid = np.concatenate([[2 * v[0] - inner[0]], inner, [2 * v[-1] - inner[-1]]])
    return 10**mid if log else mid


def _is_log(axis: Axis) -> bool:
    if axis.spacing == "log":
        return True
    vals = np.array(axis.values, dtype=float)
    return axis.spacing == "list" and bool(np.all(vals > 0)) and vals.max() / vals.min() > 100


AXIS_LABELS = {"spring.stiffness": "k, spring constant [N/m]", "run.dt": "dt, time step [s]",
               "bodies.A.mass": "m_A [kg]", "bodies.B.mass": "m_B [kg]",
               "spring.rest_length": "b, rest length [m]", "gravity.g": "g [m/s^2]",
               "floor.elasticity": "floor elasticity", "run.t_end": "t_end [s]"}


def axis_label(key: str) -> str:
    return AXIS_LABELS.get(key, key)


def draw_map(fig: Any, ax: Any, x_axis: Axis, y_axis: Axis, rows: list[dict[str, Any]],
             title: str, x_label: str | None = None, y_label: str | None = None,
             wdt: np.ndarray | None = None, limits: tuple[int, int] | None = None,
             colorbar: bool = True) -> Any:
    """Paint a 2D grid of sweep rows (x outer, y inner, as in grid order) on ``ax``:
    colour by log10 of the largest relative energy error (between ``limits``, else fitted),
    failures by verdict, and the contour w*dt = 2 (from the rows' w_dt, or ``wdt`` given on
    the same grid). Returns the colour mesh."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    if not (x_axis.numeric and y_axis.numeric):
        raise UsageError("--grid: a map needs numeric axes; use a list of numbers")
    nx, ny = len(x_axis.values), len(y_axis.values)
    xs, ys = np.array(x_axis.values, float), np.array(y_axis.values, float)
    grid = np.array(rows, dtype=object).reshape(nx, ny).T  # [iy, ix]
    xo, yo = np.argsort(xs), np.argsort(ys)
    grid = grid[np.ix_(yo, xo)]
    xs, ys = xs[xo], ys[yo]
    err = np.array([[r["max_rel_energy_error"] for r in line] for line in grid], float)
    verdict = np.array([[r["verdict"] for r in line] for line in grid])
    w_dt = (np.array([[r["w_dt"] for r in line] for line in grid], float) if wdt is None
            else wdt)
    xlog, ylog = _is_log(x_axis), _is_log(y_axis)
    xe, ye = _edges(xs, xlog), _edges(ys, ylog)
    with np.errstate(divide="ignore", invalid="ignore"):
        level = np.log10(np.maximum(err, 1e-17))
    level = np.ma.masked_where((verdict != "ok") | ~np.isfinite(level), level)
    if limits is None:
        lo = math.floor(float(level.min())) if level.count() else -16
        limits = (lo, max(lo + 1, math.ceil(float(level.max()))) if level.count() else 2)
    mesh = ax.pcolormesh(xe, ye, level, cmap="viridis", vmin=limits[0], vmax=limits[1],
                         shading="flat")
    if colorbar:
        cbar = fig.colorbar(mesh, ax=ax, pad=0.02)
        cbar.set_label("log10 of the largest relative energy error |E - E0| / |E0|")
    handles = []
    for code, (name, colour) in enumerate(FAIL_COLOURS.items()):
        mask = verdict == name
        if mask.any():
            ax.pcolormesh(xe, ye, np.ma.masked_where(~mask, np.full(mask.shape, code)),
                          cmap=ListedColormap([colour]), shading="flat")
            handles.append(Patch(facecolor=colour, edgecolor="0.3",
                                 label=f"{name} ({int(mask.sum())} runs)"))
    if x_axis.key == "w_dt":
        ax.axvline(2.0, color="red", lw=2.2, ls="--")
        handles.append(_legend_line("red", "--", "w*dt = 2: stability limit from theory"))
    elif np.nanmax(w_dt) > 2.0 > np.nanmin(w_dt):
        # log10(w*dt) is linear in log k and log dt, so its interpolated contour is straight.
        with np.errstate(divide="ignore"):
            ax.contour(xs, ys, np.log10(w_dt), levels=[math.log10(2.0)], colors="red",
                       linewidths=2.2, linestyles="--")
        handles.append(_legend_line("red", "--", "w*dt = 2: stability limit from theory"))
    else:
        handles.append(Patch(facecolor="none", edgecolor="none",
                             label=f"w*dt from {np.nanmin(w_dt):.2g} to {np.nanmax(w_dt):.2g}: "
                                   "the line w*dt = 2 is off the map"))
    ax.set_xscale("log" if xlog else "linear")
    ax.set_yscale("log" if ylog else "linear")
    ax.set_xlim(xe[0], xe[-1])
    ax.set_ylim(ye[0], ye[-1])
    ax.set_xlabel(x_label or axis_label(x_axis.key))
    ax.set_ylabel(y_label or axis_label(y_axis.key))
    ax.set_title(title, fontsize=10)
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2,
              fontsize=8, frameon=False)
    return mesh


def _legend_line(colour: str, style: str, label: str) -> Any:
    from matplotlib.lines import Line2D

    return Line2D([], [], color=colour, ls=style, lw=2.2, label=label)


def draw_line(ax: Any, axis: Axis, rows: list[dict[str, Any]], title: str) -> None:
    """A one-axis sweep: log10 of the largest relative energy error against the value, the
    failures marked by verdict and the value where w*dt = 2."""
    if not axis.numeric:
        raise UsageError("--grid: a plot needs a numeric axis; use a list of numbers")
    xs = np.array(axis.values, float)
    order = np.argsort(xs)
    xs = xs[order]
    rows = [rows[i] for i in order]
    err = np.array([r["max_rel_energy_error"] for r in rows], float)
    verdicts = [r["verdict"] for r in rows]
    ok = np.array([v == "ok" for v in verdicts])
    ax.plot(xs[ok], err[ok], "o-", color="#31688e", ms=4, lw=1.2, label="ok")
    top = np.nanmax(err[np.isfinite(err)]) if np.isfinite(err).any() else 1.0
    for name, colour in FAIL_COLOURS.items():
        mask = np.array([v == name for v in verdicts])
        if mask.any():
            # At the error reached before the run stopped; off the top if none was finite.
            ys = np.where(np.isfinite(err[mask]), err[mask], max(top, 1.0) * 3)
            ax.plot(xs[mask], ys, "X", color=colour, mec="0.2", ms=9, ls="none",
                    label=f"{name} ({int(mask.sum())} runs, error when it stopped)")
    w_dt = np.array([r["w_dt"] for r in rows], float)
    cross = np.flatnonzero(np.diff(np.sign(w_dt - 2.0)) != 0)
    if cross.size:
        j = int(cross[0])
        # Interpolate log(w*dt) between the two values around 2.
        f = (math.log(2.0) - math.log(w_dt[j])) / (math.log(w_dt[j + 1]) - math.log(w_dt[j]))
        x2 = (xs[j] * (xs[j + 1] / xs[j]) ** f if _is_log(axis)
              else xs[j] + f * (xs[j + 1] - xs[j]))
        ax.axvline(x2, color="red", ls="--", lw=2, label="w*dt = 2: stability limit")
    ax.set_yscale("log")
    if _is_log(axis):
        ax.set_xscale("log")
    ax.set_xlabel(axis_label(axis.key))
    ax.set_ylabel("largest relative energy error")
    ax.set_title(title, fontsize=10)
    ax.grid(True, color="0.9")
    ax.legend(fontsize=8)
