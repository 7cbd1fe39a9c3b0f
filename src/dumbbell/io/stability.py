"""The stability report's files (:class:`dumbbell.analysis.stability.StabilityResult` in):
stability.md, a table beside the theory with notes, and stability.csv, one line per run. The
map is :mod:`dumbbell.plot`'s."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from ..analysis.stability import AGREES, COLUMNS, StabilityResult
from .tables import csv_text as _csv_text
from .tables import write_text

__all__ = ["markdown", "write"]


def _checked(result: Any) -> StabilityResult:
    from ..model import args

    return args.instance(result, "result", StabilityResult,
                         "a StabilityResult (from dumbbell.stability)")


def _fmt(value: Any, kind: str = "") -> str:
    """A table cell: "-" when missing, 2 significant digits for an error (kind "err"), 4 for
    a time ("t"), 3 for any other float."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if kind == "err":
        return f"{value:.2g}"
    if kind == "t":
        return f"{value:.4g}"
    if isinstance(value, float):
        return f"{value:.3g}"
    return str(value)


def markdown(result: StabilityResult) -> str:
    """The report as a markdown table, then the verdict lines of the runs that did not end ok
    or disagree with the theory, the step-size guard on the pymunk runs and the runs not
    made: the ``stability.md`` that ``dumbbell stability`` writes.

    Parameters
    ----------
    result : StabilityResult
        What :func:`dumbbell.stability` ran.

    Returns
    -------
    str
        The report, in Markdown.

    Raises
    ------
    UsageError
        A ``result`` that :func:`dumbbell.stability` did not return.

    Examples
    --------
    The report of one shipped case, just past the limit w·dt = 2:

    >>> import shutil
    >>> from pathlib import Path
    >>> import dumbbell
    >>> from dumbbell.analysis.stability import default_cases
    >>> from dumbbell.io.stability import markdown
    >>> Path("cases").mkdir()
    >>> _ = shutil.copy(default_cases() / "stiff-wdt-2.1.toml", "cases")
    >>> print(markdown(dumbbell.stability("cases", solvers=["verlet"], workers=1)))
    | case | what it tests (the scene's title) | solver | dt [s] | w*dt | verdict | ...
    |---|...
    | stiff-wdt-2.1 | Stiff spring just outside the limit, w*dt = 2.1 | verlet | 0.0021 | 2.1 | unstable | 0.0105 | ...
    ...
    """
    result = _checked(result)
    rows, skipped, guard = result.rows, result.skipped, result.guard
    out = [("| case | what it tests (the scene's title) | solver | dt [s] | w*dt | verdict | "
            "t_fail [s] | largest rel. energy error | theory expects | agreement |"),
           "|---|---|---|---|---|---|---|---|---|---|"]
    previous = None
    for r in rows:
        agree = AGREES if r.agrees else "**DISAGREES**"
        case, title = (r.case, r.title) if r.case != previous else ("", "")
        previous = r.case
        out.append(f"| {case} | {title} | {r.solver} | {_fmt(r.dt)} | "
                   f"{_fmt(r.w_dt)} | {r.verdict} | {_fmt(r.t_fail, 't')} | "
                   f"{_fmt(r.max_rel_energy_error, 'err')}{' (a)' if r.dissipative else ''}"
                   f" | {r.predicted} "
                   f"({r.theory}) | {agree} |")
    if any(r.dissipative for r in rows):
        out += ["", ("(a) The floor takes energy on purpose in this scene (elasticity below 1 "
                     "or friction), so this is the energy lost, not an error.")]
    thresholds = sorted({r.inaccurate_energy for r in rows})
    if thresholds:
        out += ["", ("`ok`: stable to the end, and the relative energy error (on a dissipative "
                     "scene, what the heat counted leaves unexplained) within the case's "
                     "`run.inaccurate_energy` "
                     f"({' or '.join(f'{v:g}' for v in thresholds)}); `inaccurate`: stable "
                     "to the end, but past it, dated where it first passed it.")]
    notes = [_note(r) for r in rows if r.verdict != "ok" or not r.agrees]
    if notes:
        out += ["", "Runs that did not end ok, or disagree with the theory:", "", *notes]
    if guard:
        out += ["", ("Step-size guard (`dumbbell.spaces.check` on the space the pymunk solver "
                     "builds, at the case's dt):"), ""]
        out += guard
    if skipped:
        out += ["", "Not run (the solver cannot run the scene):", ""]
        out += [f"- {s}" for s in skipped]
    return "\n".join(out) + "\n"


def _note(r: Any) -> str:
    """The line of a run that did not end ok or disagrees with the theory."""
    line = f"- {r.case}, {r.solver}: {r.verdict}"
    if r.t_fail is not None:
        line += f" at t = {r.t_fail:.4g} s"
    if r.reason:
        line += f": {r.reason}"
    if not r.agrees:
        line += f". {r.agreement} ({r.theory})"
    return line


def csv_text(result: StabilityResult) -> str:
    """The report as CSV with :data:`~dumbbell.analysis.stability.COLUMNS`."""
    result = _checked(result)
    return _csv_text(COLUMNS, ([getattr(r, c) for c in COLUMNS] for r in result.rows))


def write(result: StabilityResult, out: Path) -> list[Path]:
    """OUT/stability.md and OUT/stability.csv: what ``dumbbell stability`` writes.

    Parameters
    ----------
    result : StabilityResult
        What :func:`dumbbell.stability` ran.
    out : pathlib.Path
        The folder for both files (made if missing).

    Returns
    -------
    list of pathlib.Path
        stability.md then stability.csv, each written whole or not at all.

    Raises
    ------
    UsageError
        A ``result`` not from :func:`dumbbell.stability`, or a folder that cannot be written.

    Examples
    --------
    A folder of one case of the user's own, the report written beside it:

    >>> from pathlib import Path
    >>> import dumbbell
    >>> from dumbbell.io.stability import write
    >>> Path("mine").mkdir()
    >>> _ = Path("mine/stiff.toml").write_text('''
    ... dimensions = 1
    ... bodies = { A = { mass = 0.1, height = 1.2 }, B = { mass = 0.1, height = 1.0 } }
    ... spring = { stiffness = 1e8, rest_length = 0.2 }
    ... run = { t_end = 0.5, dt = 1e-4 }
    ... ''')
    >>> result = dumbbell.stability("mine", solvers=["verlet"], workers=1)
    >>> [path.name for path in write(result, Path("stability"))]
    ['stability.md', 'stability.csv']
    """
    from ..model import args

    result = _checked(result)
    out = args.path(out, "out")
    return [write_text(out / "stability.md", markdown(result)),
            write_text(out / "stability.csv", csv_text(result))]
