"""The scene reader's checker: one table of a parsed scene document, every key read through
it, each bad value named by its dotted key with what is allowed (one :class:`SceneError`)."""

from __future__ import annotations

import math
import numbers
from typing import Any, Self

from ..errors import SceneError

#: No public names: the checker behind :func:`dumbbell.model.scene.load_scene`.
__all__: list[str] = []

#: Largest magnitude of any number in a scene (m, kg, m/s, N/m, ...), and the smallest mass
#: (kg): the energy formulas multiply up to four of them (1/2 I w^2 = 1/4 m r^2 w^2), which then
#: stay below 1e300, and positions stay far below the solvers' blow-up threshold (1e150).
MAX_MAGNITUDE = 1e75
MIN_MASS = 1e-75


#: The least integer of more digits than Python converts to or from text by default.
_UNREADABLE = 10**4300


class _LongInteger(int):
    """A TOML integer of more digits than Python reads (its value stands in: 10**4300 with
    its sign, beyond every bound a scene has), shown in messages by its number of digits."""

    digits: int | None

    def __new__(cls, sign: str, digits: int | None) -> Self:
        value = super().__new__(cls, -_UNREADABLE if sign == "-" else _UNREADABLE)
        value.digits = digits
        return value

    def __str__(self) -> str:
        size = "more than 4,300" if self.digits is None else f"{self.digits:,}"
        return f"a {'negative ' if self < 0 else ''}whole number of {size} digits"

    __repr__ = __str__


class _Checker:
    """Reads one TOML table, remembering which keys were used, and raises SceneError."""

    def __init__(self, source: str, table: Any, path: str):
        self.source = source
        self.path = path
        if not isinstance(table, dict):
            self.fail(path, table, "must be a table")
        self.table = table
        self.used: set[str] = set()

    def key(self, name: str) -> str:
        return f"{self.path}.{name}" if self.path else name

    def fail(self, dotted: str, value: Any, allowed: str) -> None:
        raise SceneError(f"{_printable(self.source)}: {dotted} = {_show(value)}: {allowed}")

    def _missing(self, name: str, default: Any, allowed: str) -> Any:
        """A key the table lacks: ``default``, or (None) a SceneError saying it is missing and
        what is ``allowed``."""
        if default is None:
            raise SceneError(f"{_printable(self.source)}: "
                             f"{self.key(name)} is missing: {allowed}")
        return default

    def has(self, name: str) -> bool:
        return name in self.table

    def number(
        self,
        name: str,
        default: float | None = None,
        *,
        lo: float | None = None,
        hi: float | None = None,
        lo_open: bool = False,
        unit: str = "",
    ) -> float:
        self.used.add(name)
        allowed = _range_text(lo, hi, lo_open, unit)
        if name not in self.table:
            return self._missing(name, default, allowed)
        raw = self.table[name]
        value = _finite(raw)
        if value is None:
            self.fail(self.key(name), raw, allowed)
        if lo is not None and (value < lo or (lo_open and value == lo)):
            self.fail(self.key(name), value, allowed)
        if hi is not None and value > hi:
            self.fail(self.key(name), value, allowed)
        _check_magnitude(self, self.key(name), value, unit)
        return value

    def integer(self, name: str, default: int, *, lo: int, hi: int | None = None) -> int:
        self.used.add(name)
        if name not in self.table:
            return default
        value = self.table[name]
        allowed = f"must be a whole number >= {lo}" + (f" and <= {hi}" if hi is not None else "")
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            self.fail(self.key(name), value, allowed)
        if isinstance(value, _LongInteger) or abs(value) >= _UNREADABLE:
            # Past what Python converts to and from text: no message could print it.
            shown = value if isinstance(value, _LongInteger) else \
                _LongInteger("-" if value < 0 else "", None)
            self.fail(self.key(name), shown,
                      allowed if hi is not None else f"{allowed}, of at most 4,300 digits")
        if value < lo or (hi is not None and value > hi):
            self.fail(self.key(name), value, allowed)
        return int(value)

    def boolean(self, name: str, default: bool | None) -> bool | None:
        self.used.add(name)
        if name not in self.table:
            return default
        value = self.table[name]
        if not isinstance(value, bool):
            self.fail(self.key(name), value, "must be true or false")
        return value

    def string(self, name: str, default: str | None, choices: tuple[str, ...] | None = None) -> str:
        self.used.add(name)
        if name not in self.table:
            return self._missing(name, default, "must be a string")
        value = self.table[name]
        if choices is not None:
            if value not in choices:
                self.fail(self.key(name), value, "must be one of " + ", ".join(choices))
        elif not isinstance(value, str):
            self.fail(self.key(name), value, "must be a string")
        return value

    def sub(self, name: str) -> _Checker | None:
        self.used.add(name)
        if name not in self.table:
            return None
        return _Checker(self.source, self.table[name], self.key(name))

    def done(self) -> None:
        unknown = sorted(set(self.table) - self.used, key=str)
        if unknown:
            allowed = ", ".join(sorted(self.used)) or "nothing"
            where = f"in [{_printable(self.path)}]" if self.path else "at the top level"
            raise SceneError(
                f"{_printable(self.source)}: "
                f"unknown key '{_printable(self.key(str(unknown[0])))}' {where}; "
                f"allowed: {allowed}"
            )


#: Most characters of a key, a table's name or a file's name an error message echoes.
MAX_ECHO = 120


def _printable(text: str) -> str:
    """``text`` (a key, a table's name, the scene's source) for an error message: control
    characters escaped, so that it stays on one line, and at most :data:`MAX_ECHO`
    characters, its start and end kept (a key of 80,000 characters, spaces or not, is a
    short line)."""
    text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))
    return text if len(text) <= MAX_ECHO else f"{text[:MAX_ECHO - 43]}...{text[-40:]}"


def _finite(value: Any) -> float | None:
    """``value`` as a finite float, or None if it is not a finite number (a bool, a string, an
    integer too large for a float, nan or inf)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return None
    try:
        number = float(value)
    except (OverflowError, ValueError, TypeError):
        return None
    return number if math.isfinite(number) else None


def _check_magnitude(c: _Checker, dotted: str, value: float, unit: str) -> None:
    if abs(value) > MAX_MAGNITUDE:
        c.fail(dotted, value, f"must be at most {MAX_MAGNITUDE:g} in magnitude"
                              + (f" ({unit})" if unit else "")
                              + ": larger values overflow the energies")


def _show(value: Any) -> str:
    try:
        text = repr(value) if isinstance(value, str) else str(value)
    except ValueError:  # an integer with more digits than Python will print
        text = "a whole number too large to read"
    if isinstance(value, bool):
        text = "true" if value else "false"
    return text if len(text) <= 60 else text[:57] + "..."


def _range_text(lo: float | None, hi: float | None, lo_open: bool, unit: str) -> str:
    parts = []
    if lo is not None:
        parts.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        parts.append(f"<= {hi:g}")
    text = "must be a finite number" + (" " + " and ".join(parts) if parts else "")
    return text + (f" ({unit})" if unit else "")
