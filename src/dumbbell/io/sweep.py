"""The sweep's CSV (:class:`dumbbell.analysis.sweep.SweepResult` in): the axes' values, then
:data:`~dumbbell.analysis.sweep.RESULT_COLUMNS`, one line per grid point in grid order. The
map is :mod:`dumbbell.plot`'s."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..analysis.sweep import SweepResult
from .tables import csv_text as _csv_text
from .tables import write_text

__all__ = ["write_csv"]


def _checked(result: Any) -> SweepResult:
    from ..model import args

    return args.instance(result, "result", SweepResult, "a SweepResult (from dumbbell.sweep)")


def _value(value: Any) -> Any:
    # A swept switch is written as TOML spells it, so the cell reads back as a scene value.
    if isinstance(value, bool):
        return "true" if value else "false"
    return value


def csv_text(result: SweepResult) -> str:
    """The CSV as text: the same bytes whichever backend produced the rows."""
    result = _checked(result)
    return _csv_text(result.columns, ([_value(v) for v in row.cells]
                                      for row in result.rows))


def write_csv(result: SweepResult, path: str | Path) -> Path:
    """Write the sweep as CSV (:func:`csv_text`), whole or not at all: one row per grid
    point, the axes' values then w*dt, the verdict, the time of failure (s), the largest
    relative energy error and the reason.

    Parameters
    ----------
    result : SweepResult
        What :func:`dumbbell.sweep` ran.
    path : str or pathlib.Path
        Where the sweep's CSV goes.

    Returns
    -------
    pathlib.Path
        The file written, whole.

    Raises
    ------
    UsageError
        A ``result`` that is not a SweepResult, or a ``path`` where no file can be written.

    Examples
    --------
    Two stiffnesses by two steps; the stiff spring at the long step is unstable:

    >>> import dumbbell
    >>> from dumbbell.io.sweep import write_csv
    >>> from dumbbell.model.scene import scenes_dir
    >>> result = dumbbell.sweep(scenes_dir() / "textbook-1d.toml",
    ...                         {"k": [200.0, 2e6], "dt": [1e-5, 1e-3]}, t_end=0.5, workers=1)
    >>> print(write_csv(result, "sweep.csv").read_text())
    spring.stiffness,run.dt,w_dt,verdict,t_fail,max_rel_energy_error,reason
    200.0,1e-05,0.0006324555320336759,ok,,0.00030916674793161035,
    200.0,0.001,0.06324555320336758,ok,,0.030021882013879935,
    2000000.0,1e-05,0.06324555320336758,ok,,0.029257371854075474,
    2000000.0,0.001,6.324555320336758,unstable,0.009000000000000001,41.59376249599365,"w*dt = 6.32 > 2 ..."
    <BLANKLINE>
    """
    result = _checked(result)
    return write_text(path, csv_text(result))
