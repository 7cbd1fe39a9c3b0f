"""The analyses as Python functions, for scripts and notebooks: each returns a typed, frozen
result with ``to_pandas()``, and writes nothing (the CLI writes the files).

>>> result = dumbbell.compare("scenes/textbook-1d.toml")               # doctest: +SKIP
>>> result.to_pandas()[["dt", "window_error", "energy_error"]]           # doctest: +SKIP

A scene may be given as a loaded :class:`Scene` or as the path of its file. The analysis
modules are imported only when their function is called.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import UsageError
from ..model.scene import Scene

__all__ = ["bench", "compare", "stability", "sweep"]

if TYPE_CHECKING:
    from .bench import BenchResult
    from .compare import Comparison
    from .stability import StabilityResult
    from .sweep import SweepResult


def _scene(scene: Scene | str | Path) -> Scene:
    from ..model import args

    return args.scene(scene)


def _floats(values: float | Sequence[float] | None, name: str = "dts") -> list[float] | None:
    """None, one number or a list of numbers (numpy scalars too) as a list of floats > 0."""
    import numbers

    from ..model import args

    if values is None:
        return None
    if isinstance(values, numbers.Real) and not isinstance(values, bool):
        values = [values]
    return args.positives(list(values) if isinstance(values, tuple) else values, name, "s")


def _names(values: Sequence[str] | None, name: str = "solvers") -> list[str] | None:
    """None, one solver name or a list of them, as a list of known names."""
    from ..model import args
    from ..solvers import available

    if values is None or (isinstance(values, list | tuple) and not values):
        return None  # the default set, as before
    return args.names([values] if isinstance(values, str) else values, name, available())


def compare(scene: Scene | str | Path, solvers: Sequence[str] | None = None,
            dts: float | Sequence[float] | None = None, window: float = 2.0,
            t_end: float | None = None, quiet: bool = True) -> Comparison:
    """Run ``solvers`` (default: pymunk and the hand-written method) at the steps ``dts``
    (s; default the scene's) and the truth (exact in 1D and rigid 2D, the reference for 2D
    springs) over ``t_end`` (s); measure position errors over [0, ``window``] s, energy errors, impact times and run
    times. ``.to_pandas()`` is the summary table, ``.impacts_to_pandas()`` the impacts."""
    from .compare import compare as run

    return run(_scene(scene), _names(solvers), _floats(dts), window, t_end, quiet)


def bench(scene: Scene | str | Path, solvers: Sequence[str] | None = None,
          dts: Sequence[float] | None = None, window: float = 2.0, repeat: int = 5,
          t_end: float | None = None, budget: float = 120.0, spacing: float | None = None,
          quiet: bool = True) -> BenchResult:
    """Error against run time for every solver at every step ``dts`` (s): the data of
    ``dumbbell bench``'s work-precision diagram. ``repeat`` timed runs follow a warm-up; a
    step whose runs would take more than ``budget`` s is skipped. ``.to_pandas()`` has one row
    per (solver, dt)."""
    from .bench import run_bench

    return run_bench(_scene(scene), _names(solvers), _floats(dts), window, repeat, t_end,
                     budget, spacing, quiet)


def sweep(scene: Scene | str | Path,
          grid: Mapping[str, str | Sequence[Any]] | Sequence[str],
          solver: str | None = None, t_end: float | None = None, workers: int | None = 1,
          scheduler: str | None = None, quiet: bool = True) -> SweepResult:
    """Run the scene at every point of a grid of one or two scene keys. ``grid`` maps a
    dotted key (``k`` and ``dt`` are short names) to a spec ``"log:A:B:N"``/``"lin:A:B:N"``
    or a list of values, or is a list of ``"NAME=SPEC"`` as on the command line. ``workers``
    local processes (None: one per CPU), or a Dask ``scheduler``. ``.to_pandas()`` has one
    row per point: the values, w*dt, the verdict, the time of failure (s) and the largest
    relative energy error."""
    from ..solvers import solver_class
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
    the_scene = _scene(scene)
    solver = solver or the_scene.run.solver
    solver_class(solver)                      # an unknown name fails before anything runs
    return run_sweep(the_scene, axes, solver, t_end, workers, scheduler, quiet)


def stability(cases: str | Path | None = None, solvers: Sequence[str] | None = None,
              workers: int | None = None, quiet: bool = True) -> StabilityResult:
    """Run the extreme-case catalogue (or the scenes in the folder ``cases``) with every
    solver that can run each case, each verdict beside the theory's. ``.to_pandas()`` has
    one row per run; :func:`dumbbell.io.stability.markdown` is the report ``dumbbell stability``
    writes."""
    from ..model import args
    from .stability import run_stability

    cases = None if cases is None else args.path(cases, "cases")
    return run_stability(cases, _names(solvers), workers, quiet)
