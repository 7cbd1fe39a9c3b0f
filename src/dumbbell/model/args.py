"""Checks of arguments at the border of every public function.

Each returns the value in the form the code below expects (a float, an int, a Scene, a Path)
or raises :class:`~dumbbell.errors.UsageError` naming the argument and what is allowed. Numbers
are anything :mod:`numbers` calls real or integral, so numpy scalars (``np.float32(1e-4)``,
``np.int64(100)``) are numbers; ``bool`` is not a number here.
"""

from __future__ import annotations

import math
import numbers
import os
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from .._display import counted
from .._pymunk import require as require_pymunk
from ..errors import UsageError

#: None: these are the checks the public functions call, not functions a user calls.
__all__: list[str] = []


def show(value: Any) -> str:
    """``value`` for an error message: one line, at most 60 characters."""
    try:
        text = repr(value) if isinstance(value, str) else str(value)
    except ValueError:  # an integer with more digits than Python will print
        text = "a whole number too large to print"
    text = " ".join(text.split())
    return text if len(text) <= 60 else text[:57] + "..."


def show_path(value: Any, limit: int = 120) -> str:
    """A path for an error message: one line, at most ``limit`` characters, its start and
    its end kept (the end names the file)."""
    text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in os.fsdecode(value)) \
        if isinstance(value, str | bytes | os.PathLike) else show(value)
    return text if len(text) <= limit else f"{text[:limit - 43]}...{text[-40:]}"


def _range(unit: str, positive: bool, lo: float | None, hi: float | None) -> str:
    """What a number must be, in words: 'a finite number > 0 (s)', '... from 0 to 1 (-)'."""
    if lo is not None and hi is not None:
        bounds = f" from {lo:g} to {hi:g}"
    elif lo is not None:
        bounds = f" >= {lo:g}"
    elif hi is not None:
        bounds = f" <= {hi:g}"
    else:
        bounds = " > 0" if positive else ""
    return f"a finite number{bounds} ({unit})"


def _is_real(value: Any) -> bool:
    """A real number: ``numbers.Real`` (numpy scalars, Fraction), or another number that is
    not complex (``decimal.Decimal``, which converts to the nearest float); not a bool."""
    return not isinstance(value, bool) and (
        isinstance(value, numbers.Real)
        or (isinstance(value, numbers.Number) and not isinstance(value, numbers.Complex)))


def real(value: Any, name: str, unit: str, positive: bool = True, *, lo: float | None = None,
         hi: float | None = None) -> float:
    """``value`` as a finite float, in ``unit``: > 0 if ``positive``, or between the
    inclusive bounds ``lo`` and ``hi`` when either is given (``positive`` is then unused).
    A Decimal is taken as the float nearest to it."""
    allowed = f"must be {_range(unit, positive, lo, hi)}"
    if not _is_real(value):
        raise UsageError(f"{name} = {show(value)}: {allowed}", param=name)
    try:
        number = float(value)
    except (OverflowError, ValueError, TypeError):
        number = math.nan
    if number == 0 and value != 0:
        allowed += " (it rounds to 0 as a float)"
    if lo is not None or hi is not None:
        bad = (lo is not None and number < lo) or (hi is not None and number > hi)
    else:
        bad = positive and number <= 0
    if not math.isfinite(number) or bad:
        raise UsageError(f"{name} = {show(value)}: {allowed}", param=name)
    return number


def reals(values: Any, name: str, unit: str, positive: bool = True, *, lo: float | None = None,
          hi: float | None = None, empty: bool = False) -> list[float]:
    """``values`` (a list, tuple or 1-d numpy array; one number is a list of one) as a list
    of floats that :func:`real` accepts; an empty list only if ``empty``."""
    if _is_real(values):
        values = [values]
    elif type(values).__name__ == "ndarray" and getattr(values, "ndim", 0) == 1:
        values = values.tolist()
    if isinstance(values, str) or not isinstance(values, list | tuple) or (
            not values and not empty):
        raise UsageError(f"{name} = {show(values)}: must be a list of "
                         f"{_range(unit, positive, lo, hi).replace('a finite number', 'finite numbers')}",
                         param=name)
    return [real(v, name, unit, positive, lo=lo, hi=hi) for v in values]


def positives(values: Any, name: str, unit: str) -> list[float]:
    """``values`` as a non-empty list of finite numbers > 0, in ``unit``."""
    if isinstance(values, str) or not isinstance(values, list | tuple) or not values:
        raise UsageError(f"{name} = {show(values)}: must be a list of numbers > 0 ({unit})",
                         param=name)
    return [real(v, name, unit) for v in values]


def whole(value: Any, name: str, unit: str, lo: int = 1, hi: int | None = None) -> int:
    """``value`` as an int from ``lo`` to ``hi`` (no upper bound if None)."""
    allowed = (f"must be a whole number from {lo:,} to {hi:,} ({unit})" if hi is not None
               else f"must be a whole number >= {lo:,} ({unit})")
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise UsageError(f"{name} = {show(value)}: {allowed}", param=name)
    number = int(value)
    if number < lo or (hi is not None and number > hi):
        raise UsageError(f"{name} = {show(value)}: {allowed}", param=name)
    return number


def flag(value: Any, name: str) -> bool:
    """``value`` as a bool (True/False or a numpy bool)."""
    if not isinstance(value, bool) and type(value).__name__ != "bool_":
        raise UsageError(f"{name} = {show(value)}: must be True or False", param=name)
    return bool(value)


def choice(value: Any, name: str, choices: list[str] | tuple[str, ...]) -> str:
    """``value`` as one of the names ``choices``."""
    if not isinstance(value, str) or value not in choices:
        raise UsageError(f"{name} = {show(value)}: must be one of {', '.join(choices)}",
                         param=name)
    return value


def names(value: Any, name: str, choices: list[str] | tuple[str, ...]) -> list[str]:
    """``value`` as a non-empty list of names among ``choices`` (a single str is refused:
    ``"exact"`` would otherwise read as five one-letter names)."""
    if isinstance(value, str) or not isinstance(value, list | tuple) or not value:
        raise UsageError(f"{name} = {show(value)}: must be a list of names among "
                         f"{', '.join(choices)}", param=name)
    return [choice(v, name, choices) for v in value]


def path(value: Any, name: str) -> Path:
    """``value`` (a str or os.PathLike, not empty) as a Path."""
    if not isinstance(value, str | os.PathLike) or str(value) == "":
        raise UsageError(f"{name} = {show(value)}: must be a path (str or pathlib.Path)",
                         param=name)
    return Path(value)


def scene(value: Any, name: str = "scene") -> Any:
    """``value`` as a Scene: a Scene, or the path of a scene file, which is loaded (a file
    that cannot be read or is not a valid scene is a SceneError that names the argument, then
    the file: ``scene: x.toml: no such scene file``)."""
    from ..errors import SceneError
    from .scene import Scene, load_scene

    if isinstance(value, Scene):
        return value
    if isinstance(value, str | os.PathLike):
        try:
            return load_scene(value)
        except SceneError as exc:
            raise SceneError(f"{name}: {exc}") from None
    raise UsageError(f"{name} = {show(value)}: must be a Scene or the path of a scene file",
                     param=name)


def array(value: Any, name: str, unit: str) -> Any:
    """``value`` (a number, or a list, tuple or numpy array of numbers) as a float numpy
    array (0-d for a number) of finite values, in ``unit``."""
    import numpy as np

    allowed = f"must be a finite number or an array of finite numbers ({unit})"
    if isinstance(value, bool | str) or not isinstance(
            value, numbers.Real | list | tuple | np.ndarray):
        raise UsageError(f"{name} = {show(value)}: {allowed}", param=name)
    try:
        out = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise UsageError(f"{name} = {show(value)}: {allowed}", param=name) from None
    if out.ndim > 1 or not np.all(np.isfinite(out)):
        raise UsageError(f"{name} = {show(value)}: {allowed}", param=name)
    return out


def text(value: Any, name: str, what: str = "a str") -> str:
    """``value`` as a str (``what`` says what it is for in the message)."""
    if not isinstance(value, str):
        raise UsageError(f"{name} = {show(value)}: must be {what}", param=name)
    return value


def instance(value: Any, name: str, kind: type | tuple[type, ...], what: str) -> Any:
    """``value`` if it is a ``kind``, else a UsageError saying it must be ``what`` (e.g. 'a
    Trajectory (from dumbbell.simulate)')."""
    if not isinstance(value, kind):
        raise UsageError(f"{name} = {show(value)}: must be {what}", param=name)
    return value


def _model(module: str, name: str) -> Any:
    """The class ``name`` of ``dumbbell.model.<module>`` if that module is loaded, else an
    empty tuple (no object of it can exist yet): the checks here import no model module but
    the scene's, so that the model's files import each other in one direction only."""
    loaded = sys.modules.get(f"dumbbell.model.{module}")
    return getattr(loaded, name) if loaded is not None else ()


def trajectory(value: Any, name: str = "traj") -> Any:
    """``value`` as a Trajectory."""
    return instance(value, name, _model("trajectory", "Trajectory"),
                    "a Trajectory (from dumbbell.simulate)")


def impacts(value: Any, name: str = "events") -> list[Any]:
    """``value`` (a list or tuple of Impact) as a list."""
    kind = _model("trajectory", "Impact")
    if not isinstance(value, list | tuple) or not all(isinstance(e, kind) for e in value):
        raise UsageError(f"{name} = {show(value)}: must be a list of Impact", param=name)
    return list(value)


def samples(value: Any, name: str) -> Any:
    """``value`` (a 1-d array, list or tuple of numbers) as a numpy array."""
    import numpy as np

    array = np.asarray(value) if isinstance(value, np.ndarray | list | tuple) else None
    if array is None or array.ndim != 1 or array.dtype.kind not in "fiu":
        raise UsageError(f"{name} = {show(value)}: must be a 1-d array of numbers",
                         param=name)
    return array


def columns(value: Any, n: int, name: str) -> dict[str, Any]:
    """``value`` (a dict of columns by name) with each column as a numpy array of ``n``
    samples (as many as the times ``t``)."""
    out = {key: samples(col, f"{name}[{key!r}]")
           for key, col in mapping(value, name, "a dict of columns by name").items()}
    for key, col in out.items():
        if len(col) != n:
            raise UsageError(f"{name}[{key!r}] has {counted(len(col), 'sample')}: must have as many as "
                             f"t ({n})", param=name)
    return out


def pair(value: Any, name: str, unit: str) -> tuple[float, float]:
    """``value`` (two finite numbers: a tuple, list, 1-d array or pymunk Vec2d) as a tuple
    of two floats, in ``unit``."""
    if type(value).__name__ == "ndarray":
        value = value.tolist() if getattr(value, "ndim", 0) == 1 else None
    if not isinstance(value, tuple | list) or len(value) != 2:
        raise UsageError(f"{name} = {show(value)}: must be two finite numbers (x, y) ({unit})",
                         param=name)
    return (real(value[0], name, unit, positive=False), real(value[1], name, unit,
                                                            positive=False))


def function(value: Any, name: str, what: str = "a function") -> Callable[..., Any]:
    """``value`` if it can be called."""
    if not callable(value):
        raise UsageError(f"{name} = {show(value)}: must be {what}", param=name)
    return value


def mapping(value: Any, name: str, what: str) -> Mapping[Any, Any]:
    """``value`` if it is a mapping (a dict)."""
    if not isinstance(value, Mapping):
        raise UsageError(f"{name} = {show(value)}: must be {what}", param=name)
    return value


def axes(value: Any, name: str = "ax", count: int = 1) -> Any:
    """``value`` as matplotlib axes to draw on: None (the function makes its figure), one
    ``matplotlib.axes.Axes`` (``count`` 1) or a sequence of ``count`` of them. Never imports
    matplotlib: an Axes can exist only once ``matplotlib.axes`` has been imported."""
    if value is None:
        return None
    module = sys.modules.get("matplotlib.axes")
    kind = module.Axes if module is not None else ()
    if count == 1:
        if not isinstance(value, kind):
            raise UsageError(f"{name} = {show(value)}: must be a matplotlib Axes or None",
                             param=name)
        return value
    if type(value).__name__ == "ndarray":
        value = list(value.ravel())
    if (not isinstance(value, list | tuple) or len(value) != count
            or not all(isinstance(a, kind) for a in value)):
        raise UsageError(f"{name} = {show(value)}: must be {count} matplotlib Axes (a list "
                         "or tuple) or None", param=name)
    return value


def figure(value: Any, name: str = "fig") -> Any:
    """``value`` as a matplotlib Figure (matplotlib is not imported here)."""
    module = sys.modules.get("matplotlib.figure")
    return instance(value, name, module.Figure if module is not None else (),
                    "a matplotlib Figure (ax.figure)")


def _pymunk(name: str) -> Any:
    """The pymunk class ``name`` if pymunk is loaded, else an empty tuple: without pymunk
    loaded no pymunk object can exist, so nothing passes an isinstance check against it."""
    module = sys.modules.get("pymunk")
    return getattr(module, name) if module is not None else ()


def space(value: Any, name: str = "space") -> Any:
    """``value`` as a ``pymunk.Space`` (pymunk is not imported here), on a pymunk release
    dumbbell runs on (else a PymunkVersionError: this is the spaces API's first use of it)."""
    instance(value, name, _pymunk("Space"), "a pymunk.Space")
    require_pymunk()
    return value


def pymunk_object(value: Any, name: str, kinds: tuple[str, ...]) -> Any:
    """``value`` if it is one of the pymunk classes ``kinds`` (by name, e.g. 'Circle'), on a
    pymunk release dumbbell runs on."""
    classes = tuple(c for c in (_pymunk(k) for k in kinds) if c != ())
    instance(value, name, classes, " or ".join(f"a pymunk.{k}" for k in kinds))
    require_pymunk()
    return value

