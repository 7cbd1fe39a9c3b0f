"""Energy and momentum of any pymunk space, from the per-body formulas of :mod:`dumbbell.model.energy`.

What counts: the space's DYNAMIC bodies. Each has a translational kinetic energy 1/2 m |v|^2
(v the velocity of its centre of gravity), a rotational one 1/2 I omega^2, a gravity potential
-m g.r (r its centre of gravity, zero at y = 0 along ``space.gravity``), a momentum m v and an
angular momentum. Springs add 1/2 k (d - rest)^2 (``DampedSpring``, d between the anchors in
world coordinates) and 1/2 k (a_a - a_b - rest)^2 (``DampedRotarySpring``, angles in rad).

What is reported instead of guessed:

- static and kinematic bodies (the user moves them; their energy is not the system's) are
  listed in ``skipped``; springs fixed to them still count, with the anchor where it is now;
- a body of infinite moment cannot turn (its spin is the user's to set), so its rotational
  energy is left out and the body listed in ``skipped`` if it spins;
- a spring with a custom force (or torque) function, a ``SimpleMotor`` and any constraint class
  not known here go to ``unknown``: their energy is not in ``E``. Joints that do no work
  (pivots, pins, slides, grooves, gears, limits, ratchets) hold no energy and are not listed;
- what takes energy out without a contact (``space.damping`` < 1, spring damping) is named in
  ``notes``.

The vectorized core (:func:`inventory`, :func:`evaluate`) also serves the dumbbell's ``pymunk``
solver, which evaluates it over all its samples at once.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._pymunk import spring_function
from ..model.energy import (
    angular_momentum,
    gravity_potential,
    rotational_ke,
    spring_potential,
    translational_ke,
)
from .units import UNNAMED, shown

__all__ = ["BodyEnergy", "Skipped", "SpaceEnergy", "SpringEnergy", "energy"]

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
    """Take stock of a checked ``space`` (see the module docstring for what is counted and
    reported)."""
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
        if b._velocity_func is not None:
            unknown.append(Skipped(label, "custom velocity_func: the energy of the field it "
                                          "applies is not in E (declare its potential to a "
                                          "spaces.Ledger)"))
        if b._position_func is not None:
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


@dataclass(frozen=True)
class State:
    """States of the tracked bodies, each array (samples, bodies): centre of gravity x, y (m),
    its velocity vx, vy (m/s), angle (rad) and angular velocity omega (rad/s)."""

    x: np.ndarray
    y: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    angle: np.ndarray
    omega: np.ndarray


def read_state(inv: Inventory) -> State:
    """The present state of the tracked bodies, as one sample: read from pymunk's body
    structs in one pass (the centre of gravity as pymunk holds it), or through pymunk's
    getters on a pymunk build whose structs :mod:`._memory` cannot read."""
    from . import _layout as layout
    from . import _memory as mem

    if inv.bodies and layout.readable():
        at = mem.addresses(inv.bodies, "_body")
        a = mem.Span.over(at, mem.size("body")).f(
            at, np.array([mem.offset("body", *f.split(".")) for f in
                          ("p.x", "p.y", "v.x", "v.y", "a", "w")], dtype=np.uint64)[:, None])
        return State(*a[:, None, :])
    rows = []
    for b in inv.bodies:
        cg = b.local_to_world(b.center_of_gravity)
        v = b.velocity
        rows.append((cg[0], cg[1], v[0], v[1], b.angle, b.angular_velocity))
    a = np.array(rows, dtype=float).reshape(len(inv.bodies), 6).T[:, None, :]
    return State(*a)


def _ordered(values: np.ndarray) -> np.ndarray:
    """Sum over the last axis in order, left to right: ((v0 + v1) + v2) + ..."""
    return np.cumsum(values, axis=-1)[..., -1]


def _rotate(angle: np.ndarray, p: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    if p == (0.0, 0.0):
        return 0.0 * angle, 0.0 * angle
    c, s = np.cos(angle), np.sin(angle)
    return c * p[0] - s * p[1], s * p[0] + c * p[1]


def evaluate(inv: Inventory, st: State, about: tuple[float, float] = (0.0, 0.0)
             ) -> dict[str, np.ndarray]:
    """All terms over all samples: the system's K_trans, K_rot, K_cm, K_int, U_g, U_spring,
    E (J), px, py (kg m/s), L_cm, L_about (kg m^2/s), X, Y (centre of mass, m), and per body
    (arrays (samples, dynamic bodies)) body_K_trans, body_K_rot, body_U_g, body_L_about;
    per spring (samples, springs) spring_U.

    K_int is summed as each body's motion relative to the centre of mass plus its spin
    (Koenig's theorem), which equals K_trans + K_rot - K_cm without the cancellation."""
    n = inv.dynamic
    m, moment = inv.mass, inv.moment
    gx, gy = inv.gravity
    ox, oy = about
    samples = st.x.shape[0]
    zero = np.zeros(samples)
    if n == 0:
        empty = np.zeros((samples, 0))
        out = {k: zero.copy() for k in ("K_trans", "K_rot", "K_cm", "K_int", "U_g", "E", "px",
                                         "py", "L_cm", "L_about", "X", "Y")}
        out.update(body_K_trans=empty, body_K_rot=empty, body_U_g=empty, body_L_about=empty)
    else:
        # Sums over bodies in their order, left to right (cumsum: no pairwise regrouping),
        # so that two bodies add as they always have.
        M = _ordered(m[:n])
        px, py = _ordered(m[:n] * st.vx[:, :n]), _ordered(m[:n] * st.vy[:, :n])
        mx, my = _ordered(m[:n] * st.x[:, :n]), _ordered(m[:n] * st.y[:, :n])
        X, Y, Vx, Vy = mx / M, my / M, px / M, py / M
        spin = np.isfinite(moment[:n])
        kt = translational_ke(m[:n], st.vx[:, :n], st.vy[:, :n])
        kr = np.where(spin, rotational_ke(np.where(spin, moment[:n], 0.0), st.omega[:, :n]), 0.0)
        own = np.where(spin, np.where(spin, moment[:n], 0.0) * st.omega[:, :n], 0.0)
        lo = angular_momentum(m[:n], st.x[:, :n], st.y[:, :n], st.vx[:, :n], st.vy[:, :n],
                              ox, oy) + own
        rel = translational_ke(m[:n], st.vx[:, :n] - Vx[:, None], st.vy[:, :n] - Vy[:, None])
        K_int = _ordered(np.concatenate([rel, kr[:, spin]], axis=1))
        arm = angular_momentum(m[:n], st.x[:, :n], st.y[:, :n], st.vx[:, :n], st.vy[:, :n],
                               X[:, None], Y[:, None])
        L_cm = _ordered(np.concatenate([arm, own[:, spin]], axis=1))
        K_cm = translational_ke(M, Vx, Vy)
        out = {
            "K_trans": kt.sum(axis=1), "K_rot": kr.sum(axis=1), "K_cm": K_cm, "K_int": K_int,
            "U_g": gravity_potential(M, gx, gy, X, Y), "px": px, "py": py, "L_cm": L_cm,
            "L_about": lo.sum(axis=1), "X": X, "Y": Y, "body_K_trans": kt, "body_K_rot": kr,
            "body_U_g": gravity_potential(m[:n], gx, gy, st.x[:, :n], st.y[:, :n]),
            "body_L_about": lo,
        }
    spring_u = np.zeros((samples, len(inv.springs)))
    U_spring = zero.copy()
    for j, s in enumerate(inv.springs):
        if s.kind == "DampedRotarySpring":
            extent = st.angle[:, s.a] - st.angle[:, s.b]
        else:
            ax, ay = _rotate(st.angle[:, s.a], s.anchor_a)
            bx, by = _rotate(st.angle[:, s.b], s.anchor_b)
            extent = np.hypot((st.x[:, s.b] + bx) - (st.x[:, s.a] + ax),
                              (st.y[:, s.b] + by) - (st.y[:, s.a] + ay))
        spring_u[:, j] = spring_potential(s.stiffness, extent, s.rest)
        U_spring = spring_u[:, j] if j == 0 else U_spring + spring_u[:, j]
    out["U_spring"] = U_spring
    out["spring_U"] = spring_u
    out["E"] = out["K_cm"] + out["K_int"] + out["U_g"] + U_spring
    return out


class _Sampler:
    """The energy terms of one space, sampled many times cheaply (the recorder's energy
    panel, one sample per frame). :meth:`sample` reads every tracked body's state at once and
    keeps it; the :func:`inventory` is taken again only when something it holds changes:
    the space's bodies or constraints, a body's type, mass, moment or centre of gravity,
    gravity, a spring's anchors, rest length or angle, stiffness or force function (read in
    bulk from pymunk's structs; on a pymunk build whose structs cannot be read, every sample
    takes the inventory again). :meth:`terms` evaluates all samples at once with
    :func:`evaluate`: at each sample the numbers :func:`energy` gives. A sample whose state
    is not finite is refused as :func:`energy` refuses it."""

    #: Body fields read per sample: the fingerprint (type, mass, moment, centre of gravity),
    #: then the state (as :func:`read_state`).
    _PRINT = ("m", "i", "idle_time", "cog.x", "cog.y")
    _STATE = ("p.x", "p.y", "v.x", "v.y", "a", "w")
    _SPRING = (("spring", ("anchor_a.x", "anchor_a.y", "anchor_b.x", "anchor_b.y", "rest",
                           "stiffness")),
               ("rotary_spring", ("rest", "stiffness")))

    def __init__(self, space: Any) -> None:
        from . import _layout as layout

        self.space = space
        self.fast = layout.readable()
        self.inventories: list[Inventory] = []
        self.samples: list[tuple[int, np.ndarray]] = []
        self._bodies: list[Any] | None = None
        self._constraints: list[Any] = []
        self._print: np.ndarray | None = None

    def _same_objects(self) -> bool:
        import operator

        bodies, constraints = self.space.bodies, self.space.constraints
        return (self._bodies is not None and len(bodies) == len(self._bodies)
                and len(constraints) == len(self._constraints)
                and all(map(operator.is_, bodies, self._bodies))
                and all(map(operator.is_, constraints, self._constraints))
                and tuple(self.space.gravity) == self._gravity)

    def _take_stock(self) -> None:
        """The inventory now, and where to read what it rests on."""
        import pymunk

        from . import _memory as mem

        space = self.space
        inv = inventory(space)
        self.inventories.append(inv)
        self._bodies, self._constraints = list(space.bodies), list(space.constraints)
        self._gravity = tuple(space.gravity)
        if not self.fast:
            return
        place = {id(b): i for i, b in enumerate(self._bodies)}
        extra = [b for b in inv.bodies if id(b) not in place]
        self._at = mem.addresses([*self._bodies, *extra], "_body")
        self._span = mem.Span.over(self._at, mem.size("body"))
        self._fields = np.array([mem.offset("body", *f.split("."))
                                 for f in (*self._PRINT, *self._STATE)], dtype=np.uint64)[:, None]
        rows = {id(b): i for i, b in enumerate([*self._bodies, *extra])}
        self._rows = np.array([rows[id(b)] for b in inv.bodies], dtype=np.intp)
        springs = [c for c in self._constraints
                   if isinstance(c, pymunk.DampedSpring | pymunk.DampedRotarySpring)]
        self._funcs = [spring_function(c) for c in springs]
        self._springs = []
        for kind, fields in self._SPRING:
            objs = [c for c in springs if mem.struct_of(c) == kind]
            if objs:
                at = mem.addresses(objs, "_constraint")
                self._springs.append((mem.Span.over(at, mem.size(kind)), at, np.array(
                    [mem.offset(kind, *f.split(".")) for f in fields],
                    dtype=np.uint64)[:, None]))
        self._print = None
        self._print = self._fingerprint(self._read())

    def _read(self) -> np.ndarray:
        if self._span is None:  # no bodies
            return np.zeros((len(self._fields), 0))
        return self._span.f(self._at, self._fields)

    def _fingerprint(self, values: np.ndarray) -> np.ndarray:
        import pymunk

        n = len(self._PRINT)
        parts = [values[:n].ravel(), np.isinf(values[2])]
        parts += [span.f(at, fields).ravel() for span, at, fields in self._springs]
        funcs = [spring_function(c) for c in self._constraints
                 if isinstance(c, pymunk.DampedSpring | pymunk.DampedRotarySpring)]
        same = len(funcs) == len(self._funcs) and all(
            f is g for f, g in zip(funcs, self._funcs, strict=True))
        values = np.concatenate(parts)
        values[2 * len(self._at):3 * len(self._at)] = 0.0  # idle time: only whether inf
        return values if same else np.full(len(values), math.nan)

    def sample(self) -> None:
        """Keep the state of the space now."""
        if not self.fast:
            self._take_stock()
            inv = self.inventories[-1]
            st = read_state(inv)
            state = np.stack([st.x[0], st.y[0], st.vx[0], st.vy[0], st.angle[0], st.omega[0]])
        else:
            if not self._same_objects():
                self._take_stock()
            values = self._read()
            if not np.array_equal(self._fingerprint(values), self._print):
                self._take_stock()
                values = self._read()
            state = values[len(self._PRINT):, self._rows]
        inv = self.inventories[-1]
        n = inv.dynamic
        if not (np.isfinite(state[:, :n]).all() and np.isfinite(inv.mass[:n]).all()
                and (inv.mass[:n] > 0).all() and (inv.moment[:n] > 0).all()):
            refuse_bad_state(list(inv.labels[:n]), State(*state[:, None, :]), inv.mass,
                             inv.moment)
        self.samples.append((len(self.inventories) - 1, state))

    def drop(self) -> None:
        """Forget the last sample."""
        self.samples.pop()

    def terms(self, about: tuple[float, float] = (0.0, 0.0)) -> dict[str, np.ndarray]:
        """K_trans, K_rot, U_g, U_spring and E (and the other sums :func:`evaluate` gives)
        at every sample, in order (arrays of one value per sample)."""
        names = ("K_trans", "K_rot", "K_cm", "K_int", "U_g", "U_spring", "E")
        out = {k: np.zeros(len(self.samples)) for k in names}
        which = np.array([i for i, _ in self.samples], dtype=int)
        for i in sorted({i for i, _ in self.samples}):  # (np.unique would import numpy.ma)
            rows = np.flatnonzero(which == i)
            stacked = np.stack([self.samples[r][1] for r in rows.tolist()])
            st = State(*(np.ascontiguousarray(stacked[:, j]) for j in range(6)))
            terms = evaluate(self.inventories[i], st, about)
            for k in names:
                out[k][rows] = terms[k]
        return out


@dataclass(frozen=True, repr=False)
class BodyEnergy:
    """One dynamic body: its label, mass (kg), moment (kg m^2), K_trans, K_rot, U_g (J),
    momentum (kg m/s) and angular momentum about the point asked for (kg m^2/s); in the
    space's ``units`` (length, mass, time), as :func:`energy` was told (not named when not).

    Parameters
    ----------
    subject : str
        Its label ('body 0').
    mass, moment : float
        kg and kg m².
    K_trans, K_rot, U_g : float
        Its energies (J).
    momentum : tuple of float
        (px, py) (kg m/s).
    L_about : float
        Angular momentum about the point asked for (kg m²/s).
    units : tuple of str, default ('units', 'mass units', 's')
        (length, mass, time), as :func:`energy` was told.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                    # a wheel moving at 3 m/s, spinning at 4 rad/s
    >>> wheel = pymunk.Body(2.0, 0.5)             # kg, kg m^2
    >>> wheel.velocity, wheel.angular_velocity = (3.0, 0.0), 4.0
    >>> space.add(wheel)
    >>> b = spaces.energy(space, units="m").bodies[0]
    >>> b.K_trans, b.K_rot, b.momentum           # 1/2 m v^2, 1/2 I w^2 (J), m v (kg m/s)
    (9.0, 4.0, (6.0, 0.0))
    """

    subject: str
    mass: float
    moment: float
    K_trans: float
    K_rot: float
    U_g: float
    momentum: tuple[float, float]
    L_about: float
    units: tuple[str, str, str] = UNNAMED

    __repr__ = shown


@dataclass(frozen=True, repr=False)
class SpringEnergy:
    """One spring: its label, kind and potential energy U (J; in the space's ``units``).

    Parameters
    ----------
    subject : str
        Its label ('DampedSpring 0').
    kind : str
        Its pymunk class.
    U : float
        Its potential energy (J).
    units : tuple of str, default ('units', 'mass units', 's')
        (length, mass, time), as for :class:`BodyEnergy`.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a rod twisted half a radian on a rotary spring
    >>> rod = pymunk.Body(1.0, pymunk.moment_for_segment(1.0, (-0.5, 0), (0.5, 0), 0.01))
    >>> rod.angle = 0.5                           # rad, twisted from its rest angle 0
    >>> space.add(rod, pymunk.DampedRotarySpring(space.static_body, rod, 0.0, 8.0, 0.0))
    >>> spaces.energy(space, units="m").springs[0]   # 1/2 k theta^2 = 1/2 8 0.5^2
    SpringEnergy('DampedRotarySpring 0', DampedRotarySpring: U = 1 J)
    """

    subject: str
    kind: str
    U: float
    units: tuple[str, str, str] = UNNAMED

    __repr__ = shown


@dataclass(frozen=True, repr=False)
class SpaceEnergy:
    """Energy and momentum of a space's dynamic bodies (in the ``units``
    :func:`energy` was given: (length, mass, time)).

    K_trans, K_rot, K_cm, K_int (= K_trans + K_rot - K_cm), U_g, U_spring and E = K_trans +
    K_rot + U_g + U_spring in J; ``momentum`` (px, py) in kg m/s; ``L_cm`` and ``L_about`` in
    kg m^2/s about the centre of mass ``cm`` (m) and about ``about`` (m). ``bodies`` and
    ``springs`` hold the parts; ``skipped``, ``unknown`` and ``notes`` what was left out.

    Parameters
    ----------
    K_trans, K_rot, K_cm, K_int, U_g, U_spring, E : float
        The energies (J).
    momentum : tuple of float
        (px, py) (kg m/s).
    L_cm, L_about : float
        Angular momentum (kg m²/s) about the centre of mass and about ``about``.
    about, cm : tuple of float
        The point asked for and the centre of mass (m).
    bodies : tuple of BodyEnergy
        One per dynamic body.
    springs : tuple of SpringEnergy
        One per spring.
    skipped, unknown : tuple of Skipped
        What was left out: bodies or constraints not counted, and constraints of a kind the
        accounting does not know.
    notes : tuple of str
        What else to know.
    units : tuple of str, default ('units', 'mass units', 's')
        As :func:`energy` was told (see :class:`BodyEnergy`).

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                  # a dumbbell: two 1 kg balls on a 1 m rod
    >>> a, b = pymunk.Body(1.0, 1e-3), pymunk.Body(1.0, 1e-3)
    >>> b.position = (1.0, 0.0)
    >>> a.velocity, b.velocity = (2.0, 1.0), (2.0, -1.0)     # m/s: flying and spinning
    >>> space.add(a, b, pymunk.PinJoint(a, b))
    >>> e = spaces.energy(space, units="m")
    >>> e.K_trans, e.K_cm, e.K_int              # J: the centre of mass's share, the rest
    (5.0, 4.0, 1.0)
    >>> e.momentum, e.L_cm, e.cm                # kg m/s, kg m^2/s about cm (m)
    ((4.0, 0.0), -1.0, (0.5, 0.0))
    """

    K_trans: float
    K_rot: float
    K_cm: float
    K_int: float
    U_g: float
    U_spring: float
    E: float
    momentum: tuple[float, float]
    L_cm: float
    L_about: float
    about: tuple[float, float]
    cm: tuple[float, float]
    bodies: tuple[BodyEnergy, ...]
    springs: tuple[SpringEnergy, ...]
    skipped: tuple[Skipped, ...]
    unknown: tuple[Skipped, ...]
    notes: tuple[str, ...]
    units: tuple[str, str, str] = UNNAMED

    @property
    def complete(self) -> bool:
        """True when nothing holding energy was left out (no unknown constraints)."""
        return not self.unknown

    __repr__ = shown

def energy(space: Any, about: tuple[float, float] = (0.0, 0.0),
           units: Any = None) -> SpaceEnergy:
    """Energy and momentum of ``space`` now; angular momentum also about ``about``.
    ``units`` names the space's units as the recorder takes them (the length unit alone,
    'px' or 'm', or (length, mass, time); None: not named, and the reprs say "energy units",
    never J for what may be pixels): the values are the same, their reprs carry them. See
    the module docstring for what is counted.

    Parameters
    ----------
    space : pymunk.Space
        Any space.
    about : tuple of float, default (0.0, 0.0)
        The point (length units) the angular momentum ``L_about`` is taken about.
    units : str or tuple of str or None, default None
        The space's units as the recorder takes them: the length unit alone ('px' or 'm'),
        or (length, mass, time); None: not named (reprs say "energy units", never J).

    Returns
    -------
    SpaceEnergy
        The energies, momenta and parts, frozen.

    Raises
    ------
    UsageError
        A ``space`` that is not a pymunk Space, or ``about`` or ``units`` not allowed.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a ball on a spring, SI units
    >>> space.gravity = (0.0, -9.8)
    >>> ball = pymunk.Body(0.1, pymunk.moment_for_circle(0.1, 0, 0.02))
    >>> ball.position = (0.3, 1.0)
    >>> spring = pymunk.DampedSpring(space.static_body, ball, (0.0, 1.5), (0.0, 0.0), 0.4,
    ...                              200.0, 0.0)
    >>> space.add(ball, pymunk.Circle(ball, 0.02), spring)
    >>> e = spaces.energy(space, units="m")
    >>> e
    SpaceEnergy(E = 4.33238484 J: K_trans = 0, K_rot = 0, U_g = 0.98, U_spring = 3.35238484 J; momentum = (0, 0) kg m/s, L_cm = 0 kg m²/s; 1 body, 1 spring, complete = True)
    >>> spaces.energy(space).E          # units not named: the same number, no J in its repr
    4.33238484...
    """
    from ..model import args
    from .units import check_units

    args.space(space)
    units = check_units(units)
    ox, oy = args.pair(about, "about", units[0])
    inv = inventory(space)
    st = read_state(inv)
    n = inv.dynamic
    refuse_bad_state(list(inv.labels[:n]), st, inv.mass, inv.moment)
    refuse_settings(space, inv)
    with np.errstate(over="ignore", invalid="ignore"):
        terms = evaluate(inv, st, (ox, oy))
    refuse_overflow(list(inv.labels[:n]), terms, st)

    def f(name: str) -> float:
        return float(terms[name][0])

    columns = (inv.labels[:n], inv.mass[:n].tolist(), inv.moment[:n].tolist(),
               terms["body_K_trans"][0].tolist(), terms["body_K_rot"][0].tolist(),
               terms["body_U_g"][0].tolist(), (inv.mass[:n] * st.vx[0, :n]).tolist(),
               (inv.mass[:n] * st.vy[0, :n]).tolist(), terms["body_L_about"][0].tolist())
    bodies = tuple(BodyEnergy(label, m, i, kt, kr, ug, (px, py), lo, units)
                   for label, m, i, kt, kr, ug, px, py, lo in zip(*columns, strict=True))
    springs = tuple(SpringEnergy(s.subject, s.kind, float(terms["spring_U"][0, j]), units)
                    for j, s in enumerate(inv.springs))
    return SpaceEnergy(
        K_trans=f("K_trans"), K_rot=f("K_rot"), K_cm=f("K_cm"), K_int=f("K_int"), U_g=f("U_g"),
        U_spring=f("U_spring"), E=f("E"), momentum=(f("px"), f("py")), L_cm=f("L_cm"),
        L_about=f("L_about"), about=(ox, oy), cm=(f("X"), f("Y")), bodies=bodies,
        springs=springs, skipped=inv.skipped, unknown=inv.unknown, notes=inv.notes,
        units=units,
    )
