"""The analyses as Python functions, for scripts and notebooks: each returns a typed, frozen
result with ``to_pandas()``, and writes nothing (the CLI writes the files).

A scene may be given as a loaded :class:`Scene` or as the path of its file. Each function's
options are the fields of one frozen record (:class:`~.compare.CompareOptions`,
:class:`~.bench.BenchOptions`, :class:`~.sweep.SweepOptions`,
:class:`~.stability.StabilityOptions`), checked once when it is built; the functions' keyword
arguments are those fields (their signatures are the records', see :func:`_signature`).
"""

from __future__ import annotations

import dataclasses
import inspect
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import UsageError
from ..model.scene import Scene
from .bench import BenchOptions
from .compare import CompareOptions
from .stability import StabilityOptions
from .sweep import SweepOptions

__all__ = ["bench", "compare", "stability", "sweep"]

if TYPE_CHECKING:
    from .bench import BenchResult
    from .compare import Comparison
    from .stability import StabilityResult
    from .sweep import SweepResult


def compare(scene: Scene | str | Path, **options: Any) -> Comparison:
    """Run solvers at their steps and the truth (exact in 1D and rigid 2D, the reference for 2D
    springs); measure position errors over a window, energy errors, impact times and run
    times: ``dumbbell compare`` without the files. The keywords are the fields of
    :class:`~dumbbell.analysis.compare.CompareOptions`, each checked when it is built.

    Parameters
    ----------
    scene : Scene or str or pathlib.Path
        The scene, or its file.
    solvers : list of str or Solver classes, optional
        Default: pymunk and the hand-written method.
    dts : list of float, optional
        Steps (s); default the scene's.
    window : float, default 2.0
        The span [0, window] (s) the position error is measured over.
    t_end : float, optional
        The runs' end (s); default the scene's.
    quiet : bool, default True
        No progress bar.

    Returns
    -------
    Comparison
        ``.to_pandas()`` is the summary table (one row per run), ``.impacts_to_pandas()``
        the impacts.

    Raises
    ------
    SceneError
        A scene file that is missing or not valid.
    UsageError
        An option that does not exist or a value it does not allow, or runs beyond the
        budget (one line naming it and what would do).

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> result = dumbbell.compare(scene, solvers=["euler-cromer"], dts=[1e-4], t_end=1.0,
    ...                           window=1.0)
    >>> table = result.to_pandas()
    >>> table.loc["euler-cromer", ["dt", "window_error"]].to_dict()   # m, over [0, 1] s
    {'dt': 0.0001, 'window_error': 0.00151...}
    >>> dumbbell.compare(scene, step=1e-4)
    Traceback (most recent call last):
    ...
    dumbbell.errors.UsageError: step: not an option; the options are solvers, dts, window, t_end, quiet
    """
    from .compare import compare as run

    return run(scene, _record(CompareOptions, options))


def bench(scene: Scene | str | Path, **options: Any) -> BenchResult:
    """Error against run time for every solver at every step: the data of ``dumbbell bench``'s
    work-precision diagram. The keywords are the fields of
    :class:`~dumbbell.analysis.bench.BenchOptions`, each checked when it is built.

    Parameters
    ----------
    scene
        As for :func:`dumbbell.compare`: a Scene, or its file.
    solvers : list of str or Solver classes, optional
        Default: every one that runs the scene.
    dts : sequence of float, default 1e-3 down to 1e-6
        Steps (s).
    window : float, default 2.0
        The span [0, window] (s) the position error is measured over.
    repeat : int, default 5
        Timed runs after a warm-up; the fastest counts.
    t_end : float, optional
        The runs' end (s); default the scene's.
    budget : float, default 120.0
        Seconds; a step whose runs would take longer is skipped (and says so).
    spacing : float, optional
        The sample spacing (s) errors are measured at.
    quiet : bool, default True
        No progress bar.

    Returns
    -------
    BenchResult
        ``.to_pandas()`` has one row per (solver, dt); ``.fits`` the measured orders.

    Raises
    ------
    SceneError
        A scene file that is missing or not valid.
    UsageError
        An option that does not exist or a value it does not allow.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> result = dumbbell.bench(scene, solvers=["euler-cromer"], dts=[1e-3, 1e-4, 1e-5],
    ...                         window=1.0, t_end=1.0, repeat=1)
    >>> table = result.to_pandas()                  # the truth's row too, without a step
    >>> table[["solver", "dt", "verdict"]].values.tolist()
    [['euler-cromer', 0.001, 'ok'], ['euler-cromer', 0.0001, 'ok'], ['euler-cromer', 1e-05, 'ok'], ['exact', nan, 'ok']]
    >>> errors = table["error"][:3].tolist()        # m: smaller with every smaller step
    >>> errors[0] > errors[1] > errors[2]
    True
    """
    from .bench import run_bench

    return run_bench(scene, _record(BenchOptions, options))


def sweep(scene: Scene | str | Path,
          grid: Mapping[str, str | Sequence[Any]] | Sequence[str], **options: Any) -> SweepResult:
    """Run the scene at every point of a grid of one or two scene keys. The keywords are the fields
    of :class:`~dumbbell.analysis.sweep.SweepOptions`, each checked when it is built.

    Parameters
    ----------
    scene : Scene or str or pathlib.Path
        The scene, or its file.
    grid : mapping or list of str
        A dotted key (``k`` and ``dt`` are short names) -> a spec ``"log:A:B:N"`` or
        ``"lin:A:B:N"`` or a list of values; or a list of ``"NAME=SPEC"`` as on the command
        line.
    solver : str or Solver class, optional
        Default the scene's.
    t_end : float, optional
        Each run's end (s); default the scene's.
    workers : int or None, default 1
        Local processes (None: one per CPU).
    scheduler : str or None, default None
        A Dask scheduler's address, to run on its cluster instead (the ``dask`` extra).
    quiet : bool, default True
        No progress bar.
    processes : bool, default True
        With Dask: worker processes rather than threads.
    connect_timeout : float, default 10.0
        With Dask: seconds to wait for the scheduler.

    Returns
    -------
    SweepResult
        ``.to_pandas()`` has one row per point: the values, w*dt, the verdict, the time of
        failure (s) and the largest relative energy error.

    Raises
    ------
    SceneError
        A scene file that is missing or not valid.
    UsageError
        A grid or an option that is not allowed (one line naming it).

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> result = dumbbell.sweep(scene, {"k": [200.0, 2e6], "dt": [1e-5, 1e-3]}, t_end=0.5,
    ...                         workers=1)
    >>> result.to_pandas()[["spring.stiffness", "run.dt", "verdict"]].values.tolist()
    [[200.0, 1e-05, 'ok'], [200.0, 0.001, 'ok'], [2000000.0, 1e-05, 'ok'], [2000000.0, 0.001, 'unstable']]
    >>> dumbbell.sweep(scene, {"k": "log:1:2"})
    Traceback (most recent call last):
    ...
    dumbbell.errors.UsageError: ...
    """
    from .sweep import check_axes, parse_axis, run_sweep

    if isinstance(grid, Mapping):
        items = [f"{key}={spec}" if isinstance(spec, str)
                 else f"{key}={','.join(repr(v) if isinstance(v, float) else str(v) for v in spec)}"
                 for key, spec in grid.items()]
    elif isinstance(grid, list | tuple) and all(isinstance(g, str) for g in grid):
        items = list(grid)
    else:
        from ..model.args import show

        raise UsageError(f"grid = {show(grid)}: must be a mapping of key to spec, or a list "
                         "of 'NAME=SPEC' items", param="grid")
    axes = [parse_axis(item) for item in items]
    check_axes(axes)
    return run_sweep(scene, axes, _record(SweepOptions, options))


def stability(cases: str | Path | None = None, **options: Any) -> StabilityResult:
    """Run the extreme-case catalogue (or the scenes in a folder) with every solver that can run
    each case, each verdict beside the theory's. The keywords are the other fields of
    :class:`~dumbbell.analysis.stability.StabilityOptions`, each checked when it is built.

    Parameters
    ----------
    cases : str or pathlib.Path or None, default None
        A folder of scene files; None: the shipped catalogue (minutes on 2 cores).
    solvers : list of str or Solver classes, optional
        Default: every one that runs each case.
    workers : int or None, default None
        Processes (None: one per CPU).
    quiet : bool, default True
        No progress bar.

    Returns
    -------
    StabilityResult
        ``.to_pandas()`` has one row per run; :func:`dumbbell.io.stability.markdown` is the
        report ``dumbbell stability`` writes.

    Raises
    ------
    UsageError
        A folder that is missing or holds no scene file, or an option that is not allowed.
    SceneError
        A scene file in the folder that is not valid.

    Examples
    --------
    A folder with one case: a spring so stiff that w·dt = 4.5, past the limit of 2 of both
    explicit methods.

    >>> from pathlib import Path
    >>> import dumbbell
    >>> Path("cases").mkdir()
    >>> _ = Path("cases/stiff.toml").write_text('''
    ... dimensions = 1
    ... bodies.A = { mass = 0.1, height = 1.2 }
    ... bodies.B = { mass = 0.1, height = 1.0 }
    ... spring = { stiffness = 1e8, rest_length = 0.2 }
    ... floor = { elasticity = 1.0 }
    ... gravity = { g = 9.8 }
    ... run = { t_end = 0.5, dt = 1e-4 }
    ... ''')
    >>> result = dumbbell.stability("cases", solvers=["euler-cromer", "verlet"], workers=1)
    >>> result.to_pandas()[["case", "solver", "verdict"]].values.tolist()
    [['stiff', 'euler-cromer', 'unstable'], ['stiff', 'verlet', 'unstable']]
    """
    from .stability import run_stability

    return run_stability(_record(StabilityOptions, {"cases": cases, **options}))


def _record(kind: type, options: Mapping[str, Any]) -> Any:
    """The options record ``kind`` of the keyword arguments ``options``; UsageError naming a
    keyword it does not have."""
    names = [f.name for f in dataclasses.fields(kind)]
    unknown = [key for key in options if key not in names]
    if unknown:
        raise UsageError(f"{unknown[0]}: not an option; the options are {', '.join(names)}",
                         param=unknown[0])
    return kind(**options)


def _signature(fn: Any, kind: type) -> None:
    """Give ``fn`` (its own parameters, then ``**options``) the signature of its options record
    ``kind``: its own parameters, then the record's other fields as keywords with their
    defaults, so that help() and notebooks list the real keywords."""
    params = list(inspect.signature(fn).parameters.values())[:-1]
    keyword = inspect.Parameter.KEYWORD_ONLY
    own = {p.name for p in params}
    params += [inspect.Parameter(f.name, keyword, default=f.default)
               for f in dataclasses.fields(kind) if f.name not in own]
    fn.__signature__ = inspect.signature(fn).replace(parameters=params)


# Kept on purpose (issue 32): each function takes its record's fields as ``**options`` (one
# list of options, checked once, the record's), so without this help() and a notebook's
# completion would show ``**options`` in place of the 23 keywords of the four functions
# (`python -c "import inspect, dumbbell; print(inspect.signature(dumbbell.bench))"` lists
# bench's 8); writing them out again in each signature would be a second list to keep in step.
for _fn, _kind in ((compare, CompareOptions), (bench, BenchOptions), (sweep, SweepOptions),
                   (stability, StabilityOptions)):
    _signature(_fn, _kind)
