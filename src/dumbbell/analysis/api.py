"""The analyses as Python functions, for scripts and notebooks: each returns a typed, frozen
result with ``to_pandas()``, and writes nothing (the CLI writes the files).

>>> result = dumbbell.compare("scenes/textbook-1d.toml")               # doctest: +SKIP
>>> result.to_pandas()[["dt", "window_error", "energy_error"]]           # doctest: +SKIP

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
    """Run solvers at their steps and the truth (exact in 1D and rigid 2D, the reference for
    2D springs); measure position errors over a window, energy errors, impact times and run
    times. ``options`` are the fields of :class:`~dumbbell.analysis.compare.CompareOptions`:
    ``solvers`` (names or Solver classes; default: pymunk and the hand-written method),
    ``dts`` (s; default the scene's), ``window`` (s), ``t_end`` (s) and ``quiet``.
    ``.to_pandas()`` is the summary table, ``.impacts_to_pandas()`` the impacts."""
    from .compare import compare as run

    return run(scene, _record(CompareOptions, options))


def bench(scene: Scene | str | Path, **options: Any) -> BenchResult:
    """Error against run time for every solver at every step: the data of ``dumbbell
    bench``'s work-precision diagram. ``options`` are the fields of
    :class:`~dumbbell.analysis.bench.BenchOptions`: ``solvers`` (names or Solver classes),
    ``dts`` (s), ``window`` (s), ``repeat`` timed runs after a warm-up, ``t_end`` (s),
    ``budget`` (s: a step whose runs would take longer is skipped), ``spacing`` (s) and
    ``quiet``. ``.to_pandas()`` has one row per (solver, dt)."""
    from .bench import run_bench

    return run_bench(scene, _record(BenchOptions, options))


def sweep(scene: Scene | str | Path,
          grid: Mapping[str, str | Sequence[Any]] | Sequence[str], **options: Any) -> SweepResult:
    """Run the scene at every point of a grid of one or two scene keys. ``grid`` maps a
    dotted key (``k`` and ``dt`` are short names) to a spec ``"log:A:B:N"``/``"lin:A:B:N"``
    or a list of values, or is a list of ``"NAME=SPEC"`` as on the command line. ``options``
    are the fields of :class:`~dumbbell.analysis.sweep.SweepOptions`: ``solver`` (a name or
    a Solver class; default the scene's), ``t_end`` (s), ``workers`` local processes (None:
    one per CPU) or a Dask ``scheduler``, and ``quiet``. ``.to_pandas()`` has one row per
    point: the values, w*dt, the verdict, the time of failure (s) and the largest relative
    energy error."""
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
    """Run the extreme-case catalogue (or the scenes in the folder ``cases``) with every
    solver that can run each case, each verdict beside the theory's. ``options`` are the
    other fields of :class:`~dumbbell.analysis.stability.StabilityOptions`: ``solvers`` (names
    or Solver classes), ``workers`` and ``quiet``. ``.to_pandas()`` has one row per run;
    :func:`dumbbell.io.stability.markdown` is the report ``dumbbell stability`` writes."""
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
