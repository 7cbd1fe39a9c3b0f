"""The checks of the analyses' options records (:class:`~.compare.CompareOptions`,
:class:`~.bench.BenchOptions`, :class:`~.sweep.SweepOptions`,
:class:`~.stability.StabilityOptions`): each field by its kind, once, when the record is built.
A value already of its final type (a float > 0, an int, a bool, a tuple of solver classes)
passes without a call into :mod:`dumbbell.model.args`."""

from __future__ import annotations

import math
import numbers
from typing import Any

from ..model import args
from ..solvers import solver_class, solver_classes

#: A field's kind: how it is checked, and whether None is allowed (a trailing "?").
KINDS = ("solver?", "solvers", "steps", "steps?", "seconds", "seconds?", "flag", "workers?",
         "path?", "text?")


def _positive(value: Any) -> bool:
    return type(value) is float and 0 < value < math.inf


def _steps(value: Any, name: str) -> tuple[float, ...]:
    """One step or a list of them (s, each > 0) as a tuple."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        value = [value]
    if isinstance(value, tuple) and value and all(_positive(v) for v in value):
        return value
    return tuple(args.positives(list(value) if isinstance(value, tuple) else value, name, "s"))


def _one(kind: str, value: Any, name: str) -> Any:
    """``value`` of the field ``name`` checked as ``kind`` (without its "?")."""
    if kind == "solver":
        return solver_class(value)
    if kind == "solvers":
        classes = solver_classes(value, name)
        return None if classes is None else tuple(classes)
    if kind == "steps":
        return _steps(value, name)
    if kind == "seconds":
        return value if _positive(value) else args.real(value, name, "s")
    if kind == "flag":
        return value if type(value) is bool else args.flag(value, name)
    if kind == "workers":
        return value if type(value) is int and value >= 1 else args.whole(value, name,
                                                                            "processes")
    if kind == "path":
        return args.path(value, name)
    return args.text(value, name, "a str or None")


def check(record: Any, kinds: dict[str, str]) -> None:
    """Check the fields of the frozen ``record`` named in ``kinds`` (field -> kind, one of
    :data:`KINDS`), each set to its checked value; UsageError naming the field."""
    for name, kind in kinds.items():
        value = getattr(record, name)
        if value is None and kind.endswith("?"):
            continue
        object.__setattr__(record, name, _one(kind.rstrip("?"), value, name))
