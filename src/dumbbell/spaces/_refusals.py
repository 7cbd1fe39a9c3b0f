"""What the accounting refuses to report as a number: a space whose bodies' state, masses or
moments, or whose settings (gravity, a spring's), are not finite, and an energy past the
floats; each refusal a :class:`~dumbbell.errors.DumbbellError` naming the body or setting."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._evaluation import State, read_state
from ._what_counts import Inventory


def check_finite(space: Any) -> None:
    """Refuse a space whose non-static bodies have a non-finite position, angle, velocity or
    spin, or a dynamic body pymunk cannot step (mass or moment not > 0): a
    :class:`~dumbbell.errors.DumbbellError` naming the body and what is wrong, so that a NaN
    energy is never reported as a number."""
    import pymunk

    bodies = [b for b in space.bodies if b.body_type != pymunk.Body.STATIC]
    if not bodies:
        return
    dyn = [b.body_type == pymunk.Body.DYNAMIC for b in bodies]
    inv = Inventory(bodies=tuple(bodies), labels=(), dynamic=len(bodies),
                    mass=np.zeros(0), moment=np.zeros(0), gravity=(0.0, 0.0), springs=(),
                    skipped=(), unknown=(), notes=())
    place = {id(b): i for i, b in enumerate(space.bodies)}
    refuse_bad_state([f"body {place[id(b)]}" for b in bodies], read_state(inv),
                     [b.mass if d else 1.0 for b, d in zip(bodies, dyn, strict=True)],
                     [b.moment if d else 1.0 for b, d in zip(bodies, dyn, strict=True)])


def settings_problem(space: Any, inv: Inventory | None = None
                     ) -> tuple[str, str, float] | None:
    """The first setting of ``space`` that enters its energy and is not a finite number:
    (subject, what is wrong, the value), or None. ``space.gravity``, and each spring's
    stiffness, damping, rest length (rest angle) and anchors: with one of them NaN or
    infinite every energy would be NaN, and the guard's frequencies and steps too. Springs
    are named as everywhere else, by their place in ``space.constraints``. Given ``inv``, the
    inventory just taken of ``space``, the settings it read are looked at first: the space
    is read again only when one of them is not finite (or a spring it left out has a force
    function of its own), to name the setting as the user set it."""
    import pymunk

    if inv is not None and _settings_finite(inv):
        return None

    def bad(values: Any) -> float | None:
        return next((float(v) for v in values if not math.isfinite(v)), None)

    g = tuple(space.gravity)
    if (value := bad(g)) is not None:
        return "space.gravity", f"gravity = {_shown(g)}{_NO_STEP}", value
    kinds = (pymunk.DampedSpring, pymunk.DampedRotarySpring)
    for i, c in enumerate(space.constraints):
        if not isinstance(c, kinds):
            continue
        rotary = isinstance(c, pymunk.DampedRotarySpring)
        fields = (("rest_angle",) if rotary else ("rest_length", "anchor_a", "anchor_b")) + \
            ("stiffness", "damping")
        for name in fields:
            v = getattr(c, name)
            values = tuple(v) if name.startswith("anchor") else (v,)
            if (value := bad(values)) is not None:
                return f"{type(c).__name__} {i}", f"{name} = {_shown(values)}{_NO_STEP}", value
    return None


def _settings_finite(inv: Inventory) -> bool:
    """Whether every setting ``inv`` read (gravity, each counted spring's) is finite and it
    left out no spring (one with a force function of its own, whose settings it did not
    read)."""
    numbers = [*inv.gravity, *(v for sp in inv.springs for v in (
        sp.stiffness, sp.rest, sp.damping, *sp.anchor_a, *sp.anchor_b))]
    return (all(math.isfinite(v) for v in numbers)
            and not any(u.subject.startswith("Damped") for u in inv.unknown))


#: What a setting that is not finite means, after its name and value.
_NO_STEP = (" is not a finite number: every energy would be NaN and no step fixes it; set it to "
            "a finite number")


def _shown(values: tuple[float, ...]) -> str:
    return f"({values[0]:g}, {values[1]:g})" if len(values) == 2 else f"{values[0]:g}"


def refuse_settings(space: Any, inv: Inventory | None = None) -> None:
    """Raise a :class:`~dumbbell.errors.DumbbellError` naming the first setting of ``space``
    that is not finite (:func:`settings_problem`; from the settings ``inv`` holds, when given)."""
    from ..errors import DumbbellError

    problem = settings_problem(space, inv)
    if problem is not None:
        raise DumbbellError(f"space: {problem[0]}: {problem[1]}")


def refuse_overflow(labels: list[str], terms: dict[str, np.ndarray], st: State) -> None:
    """Raise a :class:`~dumbbell.errors.DumbbellError` naming the first body whose kinetic
    or gravitational energy is past the floats (a body at 1e300 m/s: 1/2 m v^2 = inf), when
    the total ``E`` of ``terms`` is not finite."""
    from ..errors import DumbbellError
    from ..model import args

    if np.isfinite(terms["E"]).all():
        return
    for name, values in (("velocity", ("body_K_trans", st.vx, st.vy)),
                         ("angular_velocity", ("body_K_rot", st.omega)),
                         ("position", ("body_U_g", st.x, st.y))):
        column = terms[values[0]][0]
        for i in np.flatnonzero(~np.isfinite(column[:len(labels)])):
            i = int(i)
            shown = tuple(float(a[0, i]) for a in values[1:])
            raise DumbbellError(f"{labels[i]}: {name} = "
                                f"{args.show(shown[0] if len(shown) == 1 else shown)}: its "
                                "energy overflows a float (is past 1.8e308 J); no number can "
                                "report it")
    raise DumbbellError("space: its energy overflows a float (is past 1.8e308 J): its springs "
                        "or bodies are too far apart or too fast")


def refuse_bad_state(labels: list[str], st: State, mass: Any, moment: Any) -> None:
    """Raise a :class:`~dumbbell.errors.DumbbellError` naming the first body (``labels``, in
    the order of the state's columns) whose state is not finite, or whose mass or moment
    (given for the dynamic ones, 1 for others) is not > 0."""
    from ..errors import DumbbellError
    from ..model import args

    n = len(labels)
    cols = (("position", (st.x, st.y)), ("velocity", (st.vx, st.vy)), ("angle", (st.angle,)),
            ("angular_velocity", (st.omega,)))
    mass = np.asarray(mass, dtype=float)[:n]
    moment = np.asarray(moment, dtype=float)[:n]
    bad = ~(np.isfinite(mass) & (mass > 0) & (moment > 0))
    for _, parts in cols:
        for part in parts:
            bad |= ~np.isfinite(part[0, :n])
    if not bad.any():
        return
    i = int(np.argmax(bad))
    for name, parts in cols:
        values = tuple(float(part[0, i]) for part in parts)
        if not all(math.isfinite(v) for v in values):
            shown = values[0] if len(values) == 1 else values
            raise DumbbellError(f"{labels[i]}: {name} = {args.show(shown)}: must be finite")
    raise DumbbellError(f"{labels[i]} is dynamic with mass {mass[i]:g} and moment "
                        f"{moment[i]:g}: pymunk cannot step it (give it a mass > 0, or shapes "
                        "with a density)")
