"""What the accounting counts in a space: its bodies, springs and gravity as one
:class:`Inventory`, and what it leaves out (:class:`Skipped`), each with the reason in words.

What counts, and what is reported instead of guessed: :mod:`dumbbell.spaces.accounting`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._pymunk import spring_function
from ._layout import body_function

#: Joints that hold no energy and, ideally, do no work.
_WORKLESS = ("PinJoint", "SlideJoint", "PivotJoint", "GrooveJoint", "GearJoint",
             "RotaryLimitJoint", "RatchetJoint")


@dataclass(frozen=True)
class Skipped:
    """Something the accounting left out, and why in words.

    Parameters
    ----------
    subject : str
        What (a body or a constraint, as the accounting labels it).
    reason : str
        Why it was left out.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> wheel = pymunk.Body(1.0, 0.1)
    >>> space = pymunk.Space()                     # a wheel driven by a motor
    >>> space.add(wheel, pymunk.SimpleMotor(space.static_body, wheel, 2.0))
    >>> e = spaces.energy(space)
    >>> e.unknown                      # a motor's work is not counted, so E is not complete
    (Skipped(subject='SimpleMotor 0', reason='motor: puts energy in (its work is not counted)'),)
    >>> e.complete
    False
    """

    subject: str
    reason: str


@dataclass(frozen=True)
class Spring:
    """A spring the accounting knows: ``kind`` 'DampedSpring' or 'DampedRotarySpring', the
    indices of its two bodies in :attr:`Inventory.bodies`, anchors in body coordinates relative
    to each body's centre of gravity (m; unused for rotary springs), stiffness (N/m or N m/rad),
    rest length (m) or rest angle (rad), and damping (N s/m or N m s/rad)."""

    subject: str
    kind: str
    a: int
    b: int
    anchor_a: tuple[float, float]
    anchor_b: tuple[float, float]
    stiffness: float
    rest: float
    damping: float


@dataclass(frozen=True)
class Inventory:
    """What the accounting sees in a space: the bodies it tracks (the dynamic ones first, then
    static or kinematic ones that springs hang from), their masses (kg) and moments (kg m^2,
    inf when they cannot turn), the springs, gravity (m/s^2) and what it left out."""

    bodies: tuple[Any, ...]
    labels: tuple[str, ...]
    dynamic: int
    mass: np.ndarray
    moment: np.ndarray
    gravity: tuple[float, float]
    springs: tuple[Spring, ...]
    skipped: tuple[Skipped, ...]
    unknown: tuple[Skipped, ...]
    notes: tuple[str, ...]


def inventory(space: Any) -> Inventory:
    """Take stock of a checked ``space`` (see :mod:`dumbbell.spaces.accounting` for what is
    counted and reported)."""
    import pymunk

    bodies = space.bodies
    place = {id(b): i for i, b in enumerate(bodies)}
    types, masses, moments_all = _kinds(bodies)
    dyn = [b for b, kind in zip(bodies, types, strict=True) if kind == pymunk.Body.DYNAMIC]
    tracked = list(dyn)
    where = {id(b): i for i, b in enumerate(tracked)}

    def name(body: Any) -> str:
        i = place.get(id(body))
        return f"body {i}" if i is not None else _outside(space, body)

    labels = [name(b) for b in dyn]
    moments = [i for i, kind in zip(moments_all, types, strict=True)
               if kind == pymunk.Body.DYNAMIC]
    dyn_mass = [m for m, kind in zip(masses, types, strict=True) if kind == pymunk.Body.DYNAMIC]
    skipped = _skipped_bodies(bodies, types, name) + _skipped_spins(dyn, moments, labels)

    def index(body: Any) -> int:
        i = where.get(id(body))
        if i is None:
            i = where[id(body)] = len(tracked)
            tracked.append(body)
            labels.append(name(body))
        return i

    springs, unknown, notes = _constraints(space, index)
    for b, label in zip(dyn, labels[: len(dyn)], strict=True):
        # pymunk up to 7.3.0 keeps a replaced function: body_function says whether it is
        # called.
        if b._velocity_func is not None and body_function(b, "velocity_func") is not None:
            unknown.append(Skipped(label, "custom velocity_func: the energy of the field it "
                                          "applies is not in E (declare its potential to a "
                                          "spaces.Ledger)"))
        if b._position_func is not None and body_function(b, "position_func") is not None:
            notes.append(f"{label} has a custom position_func: it moves the body its own way")
    if any(kind == pymunk.Body.KINEMATIC for kind in types):
        notes.append("kinematic bodies do work on what they push or pull (spaces.Ledger "
                     "counts it)")
    if space.damping != 1.0:
        notes.append(f"space.damping = {space.damping:g}: bodies lose energy every step that "
                     "no term here counts")
    return Inventory(
        bodies=tuple(tracked), labels=tuple(labels), dynamic=len(dyn),
        mass=np.array(dyn_mass + [b.mass for b in tracked[len(dyn):]], dtype=float),
        moment=np.array(moments + [b.moment for b in tracked[len(dyn):]], dtype=float),
        gravity=(float(space.gravity[0]), float(space.gravity[1])),
        springs=tuple(springs), skipped=tuple(skipped), unknown=tuple(unknown),
        notes=tuple(notes),
    )


def _outside(space: Any, body: Any) -> str:
    """The label of a body not among the space's bodies: the space's own static body
    (found without making it: pymunk makes it on first use), or one not in the space."""
    import pymunk

    if body.body_type == pymunk.Body.STATIC and body.space is space:
        return "static body"
    return "body (not in the space)"


def _constraints(space: Any, index: Callable[[Any], int]
                 ) -> tuple[list[Spring], list[Skipped], list[str]]:
    """The springs of ``space`` between the tracked bodies ``index(body)``, the constraints
    whose energy is unknown, and notes on energy that nothing counts (spring damping)."""
    import pymunk

    unknown: list[Skipped] = []
    notes: list[str] = []
    springs: list[Spring] = []
    for i, c in enumerate(space.constraints):
        name = type(c).__name__
        label = f"{name} {i}"
        if any(b.space is not space and b.body_type != pymunk.Body.STATIC for b in (c.a, c.b)):
            notes.append(f"{label} joins a body that is not in the space: its impulses change "
                         "that body's velocity, whose energy is not in E (what leaves with it: "
                         "spaces.Ledger counts it)")
        if isinstance(c, pymunk.DampedSpring | pymunk.DampedRotarySpring):
            spring = _spring(c, label, index)
            if isinstance(spring, Skipped):
                unknown.append(spring)
                continue
            if c.damping != 0.0:
                notes.append(f"{label} has damping {c.damping:g}: it turns energy into heat "
                             "that the heat counter does not see (spaces.Ledger counts it)")
            springs.append(spring)
        elif name in _WORKLESS and type(c).__module__.startswith("pymunk"):
            moves = []
            if name in ("SlideJoint", "RotaryLimitJoint", "RatchetJoint"):
                moves.append("a stop: reached, it takes energy out")
            if math.isfinite(c.max_force):
                moves.append(f"max_force {c.max_force:g}: slipping, it takes energy out")
            if moves:
                notes.append(f"{label}: {'; '.join(moves)} (spaces.Ledger counts it)")
        elif isinstance(c, pymunk.SimpleMotor):
            unknown.append(Skipped(label, "motor: puts energy in (its work is not counted)"))
        else:
            unknown.append(Skipped(label, f"{name}: constraint not known to the accounting"))
    return springs, unknown, notes


def _kinds(bodies: list[Any]) -> tuple[list[int], list[float], list[float]]:
    """Each body's type, mass and moment: read from pymunk's structs in one pass (the type as
    Chipmunk's cpBodyGetType decides it: static when its idle time is infinite, kinematic
    when its mass is), or through pymunk's getters when the structs cannot be read."""
    import pymunk

    from . import _layout as layout
    from . import _memory as mem

    if not bodies or not layout.readable():
        return ([b.body_type for b in bodies], [b.mass for b in bodies],
                [b.moment for b in bodies])
    at = mem.addresses(bodies, "_body")
    m, i, idle = mem.Span.over(at, mem.size("body")).f(at, np.array(
        [mem.offset("body", f) for f in ("m", "i", "idle_time")], dtype=np.uint64)[:, None])
    kind = np.where(idle == np.inf, pymunk.Body.STATIC,
                    np.where(m == np.inf, pymunk.Body.KINEMATIC, pymunk.Body.DYNAMIC))
    return kind.tolist(), m.tolist(), i.tolist()



def _skipped_bodies(bodies: list[Any], types: list[int], name: Callable[[Any], str]
                    ) -> list[Skipped]:
    """The bodies whose energy is not counted: static and kinematic bodies."""
    import pymunk

    skipped: list[Skipped] = []
    for b, kind in zip(bodies, types, strict=True):
        if kind == pymunk.Body.STATIC:
            skipped.append(Skipped(name(b), "static: holds no energy"))
        elif kind == pymunk.Body.KINEMATIC:
            skipped.append(Skipped(name(b),
                                   "kinematic: moved by the user, its energy is not counted"))
    return skipped


def _skipped_spins(dyn: list[Any], moments: list[float], labels: list[str]) -> list[Skipped]:
    """The spins not counted: of the dynamic bodies of infinite moment that spin."""
    return [Skipped(label, f"infinite moment spinning at {b.angular_velocity:g} rad/s: "
                           "rotational energy left out")
            for b, moment, label in zip(dyn, moments, labels, strict=True)
            if math.isinf(moment) and b.angular_velocity != 0.0]


def _spring(c: Any, label: str, index: Callable[[Any], int]) -> Spring | Skipped:
    """The linear or rotary spring ``c`` as a :class:`Spring` between the tracked bodies
    ``index(body)``, or Skipped when a custom force function makes its energy unknown."""
    import pymunk

    rotary = isinstance(c, pymunk.DampedRotarySpring)
    if spring_function(c) is not None:
        return Skipped(label, "custom force function: its energy is unknown")
    a, b = c.a, c.b
    ia, ib = index(a), index(b)
    if rotary:
        anchors = ((0.0, 0.0), (0.0, 0.0))
        rest = c.rest_angle
    else:
        anchors = tuple((float(p[0] - cg[0]), float(p[1] - cg[1])) for p, cg in
                        ((c.anchor_a, a.center_of_gravity),
                         (c.anchor_b, b.center_of_gravity)))
        rest = c.rest_length
    return Spring(label, "DampedRotarySpring" if rotary else "DampedSpring",
                  ia, ib, anchors[0], anchors[1], float(c.stiffness),
                  float(rest), float(c.damping))
