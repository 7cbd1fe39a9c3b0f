"""The units of a space: pymunk has none, so a program names them (``units``), and every
value of the space the toolkit prints carries them. One rule, shared by the recorder's
labels, the ledger's reprs and tables, the heat counter's, the guard's messages and
:func:`dumbbell.spaces.energy`'s repr. A program that names none gets no unit claimed for it:
lengths print in "units" and energies in "energy units" (time in seconds, as pymunk's step
takes it), never "J" for what may be pixels."""

from __future__ import annotations

from typing import Any

__all__: list[str] = []  # the toolkit's own; users pass ``units`` to its tools

#: Units of a space (length, mass, time) in SI, whose energy is the joule.
SI = ("m", "kg", "s")
#: Longest unit name.
UNIT_CHARS = 12
#: The units of a space whose program named none: what messages say for a length and a time.
UNNAMED = ("units", "mass units", "s")


def check_units(units: Any) -> tuple[str, str, str]:
    """``units`` as (length, mass, time): None (not named: :data:`UNNAMED`), the length unit
    alone ('px'; mass in kg, time in s) or three names, each 1 to :data:`UNIT_CHARS`
    printable characters."""
    from ..errors import UsageError
    from ..model import args

    if units is None:
        return UNNAMED
    allowed = (f"must be None (not named), the length unit ('px', as the guard takes it; mass in kg, time in s) "
               f"or three names (length, mass, time), each 1 to {UNIT_CHARS} characters, e.g. "
               "('m', 'kg', 's')")
    names = (units, SI[1], SI[2]) if isinstance(units, str) else units
    if not isinstance(names, tuple | list) or len(names) != 3 or not all(
            isinstance(u, str) and 0 < len(u) <= UNIT_CHARS and u.isprintable() for u in names):
        raise UsageError(f"units = {args.show(units)}: {allowed}", param="units")
    return tuple(names)  # type: ignore[return-value]


def energy_unit(units: tuple[str, str, str]) -> str:
    """The energy unit of a space in ``units`` (length, mass, time): J in SI, 'energy units'
    when the program named none."""
    if tuple(units) == UNNAMED:
        return "energy units"
    length, mass, t = units
    return "J" if tuple(units) == SI else f"{mass} {length}²/{t}²"


def power_unit(units: tuple[str, str, str]) -> str:
    """The unit of power (energy per time): W in SI, 'energy units/s' when not named."""
    if tuple(units) == UNNAMED:
        return "energy units/s"
    length, mass, t = units
    return "W" if tuple(units) == SI else f"{mass} {length}²/{t}³"


def momentum_unit(units: tuple[str, str, str]) -> str:
    """The unit of momentum (mass length / time)."""
    if tuple(units) == UNNAMED:
        return "momentum units"
    length, mass, t = units
    return f"{mass} {length}/{t}"


def angular_unit(units: tuple[str, str, str]) -> str:
    """The unit of angular momentum (mass length² / time)."""
    if tuple(units) == UNNAMED:
        return "angular momentum units"
    length, mass, t = units
    return f"{mass} {length}²/{t}"


def _g(value: float) -> str:
    # + 0.0 turns a -0.0 (U_g = -m g y at y = 0, or with no gravity) into 0.
    return f"{value + 0.0:.9g}"


def shown(record: Any) -> str:
    """The one-line repr of a record of :func:`dumbbell.spaces.energy` (``SpaceEnergy``,
    ``BodyEnergy``, ``SpringEnergy``), every value with its unit."""
    from .._display import counted, one_line

    u = record.units
    e = energy_unit(u)
    kind = type(record).__name__
    if kind == "SpringEnergy":
        return f"SpringEnergy({record.subject!r}, {record.kind}: U = {_g(record.U)} {e})"
    p = f"({_g(record.momentum[0])}, {_g(record.momentum[1])}) {momentum_unit(u)}"
    if kind == "BodyEnergy":
        return (f"BodyEnergy({record.subject!r}: K_trans = {_g(record.K_trans)} {e}, K_rot = "
                f"{_g(record.K_rot)} {e}, U_g = {_g(record.U_g)} {e}, momentum = {p})")
    return one_line(
        f"SpaceEnergy(E = {_g(record.E)} {e}: K_trans = {_g(record.K_trans)}, K_rot = "
        f"{_g(record.K_rot)}, U_g = {_g(record.U_g)}, U_spring = {_g(record.U_spring)} {e}; "
        f"momentum = {p}, L_cm = {_g(record.L_cm)} {angular_unit(u)}; "
        f"{counted(len(record.bodies), 'body', 'bodies')}, "
        f"{counted(len(record.springs), 'spring')}, complete = "
        f"{record.complete})")
