"""The restitution study's outputs (:class:`dumbbell.analysis.restitution.RestitutionResult`
in): one line per tilt, the columns of
:meth:`~dumbbell.analysis.restitution.RestitutionResult.columns` (tilt in degrees, the rest
dimensionless), as a CSV file and as the Markdown table ``dumbbell restitution`` prints. The
figure is :mod:`dumbbell.plot`'s."""

from __future__ import annotations

from pathlib import Path

from ..analysis.restitution import RestitutionResult
from .tables import csv_text, write_text

__all__ = ["markdown", "write_csv"]


def _checked(result: object) -> RestitutionResult:
    from ..model import args

    return args.instance(result, "result", RestitutionResult,
                         "a RestitutionResult (from dumbbell.analysis.restitution.restitution)")


def write_csv(result: RestitutionResult, path: str | Path) -> Path:
    """Write the columns as CSV, whole or not at all.

    Parameters
    ----------
    result : RestitutionResult
        What :func:`~dumbbell.analysis.restitution.restitution` measured.
    path : str or pathlib.Path
        The CSV file, one row per tilt.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    UsageError
        A ``result`` not from :func:`~dumbbell.analysis.restitution.restitution`, or a
        ``path`` that cannot be written.

    Examples
    --------
    The header row:

    >>> import dumbbell
    >>> from dumbbell.io.restitution import write_csv
    >>> from dumbbell.analysis.restitution import restitution
    >>> from dumbbell.model.scene import scenes_dir
    >>> result = restitution(dumbbell.load_scene(scenes_dir() / "rigid-2d.toml"), [0.0, 30.0],
    ...                      stiffnesses=(), dt=1e-4)
    >>> write_csv(result, "restitution.csv").read_text().splitlines()[0]
    'theta,formula,truth,pymunk,rigid_impacts,rigid_K_rot_share'
    """
    from ..model import args

    result = _checked(result)
    path = args.path(path, "path")
    cols = result.columns()
    rows = ([float(cols[c][i]) for c in cols] for i in range(len(result.theta)))
    return write_text(path, csv_text(list(cols), rows))


def markdown(result: RestitutionResult) -> str:
    """The columns as a Markdown table, one row per tilt, 6 significant digits.

    Parameters
    ----------
    result : RestitutionResult
        What :func:`~dumbbell.analysis.restitution.restitution` measured.

    Returns
    -------
    str
        The Markdown table: a header, a rule, a row per tilt.

    Raises
    ------
    UsageError
        A ``result`` that :func:`write_csv` would refuse too.

    Examples
    --------
    >>> from dumbbell.io.restitution import markdown
    >>> import dumbbell
    >>> from dumbbell.analysis.restitution import restitution
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "rigid-2d.toml")
    >>> result = restitution(scene, [0.0, 30.0], stiffnesses=(), dt=1e-4)
    >>> print(markdown(result))
    | theta | formula | truth | pymunk | rigid_impacts | rigid_K_rot_share |
    |---|---|---|---|---|---|
    | 0 | 1 | 1 | 0.999779 | 1 | 0 |
    | 30 | 0.6 | 0.6 | 0.599823 | 1 | 0.639858 |
    """
    cols = _checked(result).columns()
    head = "| " + " | ".join(cols) + " |"
    rule = "|" + "---|" * len(cols)
    rows = ["| " + " | ".join(f"{cols[c][i]:.6g}" for c in cols) + " |"
            for i in range(len(result.theta))]
    return "\n".join([head, rule, *rows])
