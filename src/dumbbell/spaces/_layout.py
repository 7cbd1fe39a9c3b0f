"""Whether pymunk's structs are laid out as :mod:`._memory` declares them, checked before
anything is read through the declarations: each read against pymunk's getters and
Chipmunk's public C getters, floats with a tolerance (:data:`TOLERANCE`), and the space's
fields past ``dt`` by value before any of them is followed (:func:`check_space`); once per
process on a small space of every constraint kind (:func:`problem`). A failed check raises
:class:`._memory.LayoutError`; the ledger then counts with pymunk's public API only."""

from __future__ import annotations

import math
from functools import cache
from typing import Any

from ._memory import (
    STRUCT,
    LayoutError,
    _lib,
    _plausible,
    _pymunk_ffi,
    address,
    array_items,
    hooks,
    platform_problem,
    struct_of,
    view,
)

#: Relative tolerance of a float read against pymunk's getter (both read the same double;
#: a getter may compute, e.g. a pivot's impulse is the length of its accumulated vector).
TOLERANCE = 1e-12


def near(got: float, want: float, rel: float = TOLERANCE) -> bool:
    """Two floats equal but for a few roundings (both NaN, or both the same infinity)."""
    if got == want or (math.isnan(got) and math.isnan(want)):
        return True
    return abs(got - want) <= rel * max(abs(got), abs(want)) + 1e-300


def _compare(what: str, pairs: list[tuple[str, Any, Any]]) -> None:
    for name, got, want in pairs:
        same = (got == want) if isinstance(want, int) and not isinstance(want, bool) else (
            near(float(got), float(want)))
        if not same:
            raise LayoutError(f"{what}.{name}: read {got!r}, pymunk says {want!r}")


def check_space(space: Any) -> int:
    """Check the declared space struct against ``space``, in order, and return its address:
    the fields up to ``dt`` against pymunk's getters; the fields past it that Chipmunk's C
    getters give (nothing past ``dt`` is followed before these agree); then the headers and
    contents of the arrays the ledger reads. Raises :class:`LayoutError`."""
    lib = _lib()
    at = address(space._space)
    r = view("space", at)
    _compare("space", [
        ("iterations", r.iterations, space.iterations),
        ("gravity.x", r.gravity.x, space.gravity[0]),
        ("gravity.y", r.gravity.y, space.gravity[1]),
        ("damping", r.damping, space.damping),
        ("idle_speed", r.idle_speed, space.idle_speed_threshold),
        ("sleep_time", r.sleep_time, space.sleep_time_threshold),
        ("slop", r.slop, space.collision_slop), ("bias", r.bias, space.collision_bias),
        ("persistence", int(r.persistence), int(space.collision_persistence)),
        ("user_data", address(r.user_data), address(lib.cpSpaceGetUserData(space._space))),
        ("stamp", int(r.stamp), int(lib.cpSpaceGetTimestamp(space._space))),
        ("dt", r.dt, space.current_time_step)])
    # Past dt: pointer values compared, none followed yet.
    _compare("space", [
        ("shape_ids", int(r.shape_ids), int(lib.cpSpaceGetShapeIDCounter(space._space))),
        ("static_body", address(r.static_body),
         address(lib.cpSpaceGetStaticBody(space._space))),
        ("locked", int(r.locked > 0), int(bool(lib.cpSpaceIsLocked(space._space))))])
    for name in ("dynamic_bodies", "static_bodies", "sleeping_components", "constraints",
                 "arbiters"):
        if not _plausible(address(getattr(r, name))):
            raise LayoutError(f"space.{name}: not a valid address")
    # Now the arrays: their headers, then what they hold.
    constraints = set(array_items(address(r.constraints)).tolist())
    known = {address(c._constraint) for c in space.constraints}
    if not known <= constraints or not constraints <= known | hooks(space):
        raise LayoutError("space.constraints: does not hold the space's constraints")
    mine = {address(b._body) for b in space.bodies}
    # Static: the space's static bodies, and those its shapes and constraints use that are
    # not among them (pymunk's own, made lazily, Chipmunk's own).
    used = [s.body for s in space.shapes] + [e for c in space.constraints for e in (c.a, c.b)]
    own = getattr(space, "_static_body", None)  # read only to widen this check
    static = mine | {address(b._body) for b in [*used, *([own] if own else [])]}
    static.add(address(lib.cpSpaceGetStaticBody(space._space)))
    for name, allowed in (("dynamic_bodies", mine), ("sleeping_components", mine),
                          ("static_bodies", static)):
        if not set(array_items(address(getattr(r, name))).tolist()) <= allowed:
            raise LayoutError(f"space.{name}: holds bodies the space does not")
    if not {address(b._body) for b in space.bodies if b.body_type == b.STATIC} <= set(
            array_items(address(r.static_bodies)).tolist()):
        raise LayoutError("space.static_bodies: lacks static bodies of the space")
    array_items(address(r.arbiters))
    return at


@cache
def callbacks_known() -> bool:
    """pymunk keeps a space's collision handlers in ``Space._handlers``, the post-step
    callbacks a step will run in ``Space._post_step_callbacks`` and the adds and removes
    asked for inside a step (done at its end) in ``Space._add_later`` and
    ``Space._remove_later`` (empty on a new space; pymunk 7 has no public getter for any),
    checked once per process on a scratch space: a handler set with ``on_collision``, a
    callback added with ``add_post_step_callback``, and a body added and another removed
    from a constraint's ``pre_solve`` while the space steps must show there. Read, never
    written, and only to know that nothing can change a body between the solver and the
    end of a step (the ledger's ``_quiet_end``); False (the ledger then checks every body
    at every step's end) if anything differs."""
    import pymunk

    def nothing(*args: Any) -> None:
        return None

    try:
        space = pymunk.Space()
        held = (space._handlers, space._post_step_callbacks, space._add_later,
                space._remove_later)
        # (the removes are a dict from pymunk 7.0.1 on, a set in 7.0.0)
        if not all(isinstance(x, kinds) for x, kinds in zip(
                held, (dict, dict, (set, dict), (set, dict)), strict=True)) or any(held):
            return False
        a, b, c, d = (pymunk.Body(1, 1) for _ in range(4))
        joint = pymunk.PinJoint(a, b)
        space.add(a, b, c, joint)
        seen = []

        def defer(constraint: Any, space_: Any) -> None:
            space_.add(d)
            space_.remove(c)
            seen.append(d in space_._add_later and c in space_._remove_later)

        joint.pre_solve = defer
        space.step(0.01)
        if seen != [True] or space._add_later or space._remove_later:
            return False
        space.on_collision(1, 2, post_solve=nothing)
        space.add_post_step_callback(nothing, "key")
        return bool(space._handlers) and "key" in space._post_step_callbacks
    except Exception:  # noqa: BLE001 - any other pymunk: not known
        return False


def check_body(body: Any) -> None:
    """Raise :class:`LayoutError` unless the declared body struct reads what pymunk reads."""
    lib = _lib()
    r = view("body", address(body._body))
    cog = body.local_to_world(body.center_of_gravity)
    # The centre of gravity in world coordinates goes through pymunk's transform. Chipmunk
    # keeps p (the centre of gravity's world position) when a program sets
    # center_of_gravity: until the body next moves, p is where its centre of gravity was,
    # the body's origin for one given a centre of gravity after its position.
    if not all(near(g, w) for g, w in zip((r.p.x, r.p.y), cog, strict=True)):
        cog = body.position
    for name, got, want in [
            ("m", r.m, body.mass), ("i", r.i, body.moment),
            ("cog.x", r.cog.x, body.center_of_gravity[0]),
            ("cog.y", r.cog.y, body.center_of_gravity[1]), ("p.x", r.p.x, cog[0]),
            ("p.y", r.p.y, cog[1]), ("v.x", r.v.x, body.velocity[0]),
            ("v.y", r.v.y, body.velocity[1]), ("a", r.a, body.angle),
            ("w", r.w, body.angular_velocity), ("f.x", r.f.x, body.force[0]),
            ("f.y", r.f.y, body.force[1]), ("t", r.t, body.torque)]:
        if not (near(got, want) or abs(got - want) <= 1e-9 * (1.0 + abs(want))):
            raise LayoutError(f"body.{name}: read {got!r}, pymunk says {want!r}")
    _compare("body", [
        ("user_data", address(r.user_data), address(lib.cpBodyGetUserData(body._body))),
        ("space", address(r.space), address(lib.cpBodyGetSpace(body._body))),
        ("root", int(address(r.root) != 0), int(bool(lib.cpBodyIsSleeping(body._body))))])


def _constraint_fields(c: Any) -> list[tuple[str, float]]:
    name = next(kls.__name__ for kls in type(c).__mro__ if kls.__name__ in STRUCT)
    fields: list[tuple[str, float]] = [("c.max_force", c.max_force),
                                        ("c.error_bias", c.error_bias),
                                        ("c.max_bias", c.max_bias)]
    if hasattr(c, "anchor_a"):
        fields += [("anchor_a.x", c.anchor_a[0]), ("anchor_a.y", c.anchor_a[1])]
    if hasattr(c, "anchor_b"):
        fields += [("anchor_b.x", c.anchor_b[0]), ("anchor_b.y", c.anchor_b[1])]
    extra = {"PinJoint": ("distance:dist",), "SlideJoint": ("min", "max"),
             "GrooveJoint": ("groove_a", "groove_b"),
             "DampedSpring": ("rest_length:rest", "stiffness", "damping"),
             "DampedRotarySpring": ("rest_angle:rest", "stiffness", "damping"),
             "RotaryLimitJoint": ("min", "max"),
             "RatchetJoint": ("angle", "phase", "ratchet"), "GearJoint": ("phase", "ratio"),
             "SimpleMotor": ("rate",)}.get(name, ())
    for spec in extra:
        attr, _, field = spec.partition(":")
        value = getattr(c, attr)
        if isinstance(value, tuple):
            fields += [(f"{field or attr}.x", value[0]), (f"{field or attr}.y", value[1])]
        else:
            fields.append((field or attr, value))
    return fields


def check_constraint(c: Any) -> None:
    """Raise :class:`LayoutError` unless the declared struct of ``c`` reads its settings,
    its bodies, its space and (up to sign, with a tolerance) the impulse pymunk reports."""
    lib = _lib()
    kind = struct_of(c)
    if kind is None:
        raise LayoutError(f"{type(c).__name__}: not a constraint class the ledger reads")
    r = view(kind, address(c._constraint))
    _compare(kind, [
        ("c.a", address(r.c.a), address(lib.cpConstraintGetBodyA(c._constraint))),
        ("c.b", address(r.c.b), address(lib.cpConstraintGetBodyB(c._constraint))),
        ("c.space", address(r.c.space), address(lib.cpConstraintGetSpace(c._constraint))),
        ("c.user_data", address(r.c.user_data),
         address(lib.cpConstraintGetUserData(c._constraint)))])
    if address(r.c.a) != address(c.a._body) or address(r.c.b) != address(c.b._body):
        raise LayoutError(f"{kind}: bodies do not match")
    for path, want in _constraint_fields(c):
        got = r
        for part in path.split("."):
            got = getattr(got, part)
        if not near(got, want):
            raise LayoutError(f"{kind}.{path}: read {got!r}, pymunk says {want!r}")
    j = r.j
    got = math.hypot(j.x, j.y) if kind in ("pivot", "groove") else (
        j if kind in ("spring", "rotary_spring") else abs(j))
    if not near(got, c.impulse):
        raise LayoutError(f"{kind}: impulse {got!r}, pymunk says {c.impulse!r}")


@cache
def default_funcs() -> tuple[frozenset[int], frozenset[int]]:
    """Addresses of pymunk's default velocity and position functions (as a new body holds
    them, and as pymunk sets them back)."""
    import pymunk

    pffi, lib = _pymunk_ffi(), _lib()
    r = view("body", address(pymunk.Body(1.0, 1.0)._body))
    vel = {address(r.velocity_func), address(pffi.addressof(lib, "cpBodyUpdateVelocity"))}
    pos = {address(r.position_func), address(pffi.addressof(lib, "cpBodyUpdatePosition"))}
    return frozenset(vel), frozenset(pos)


@cache
def default_spring_funcs() -> tuple[frozenset[int], frozenset[int]]:
    """Addresses of Munk2D's default spring force and rotary spring torque functions (as a
    new spring holds them), read through the checked declarations."""
    import pymunk

    a, b = pymunk.Body(1.0, 1.0), pymunk.Body(1.0, 1.0)
    spring = pymunk.DampedSpring(a, b, (0, 0), (0, 0), 1.0, 1.0, 0.0)
    rotary = pymunk.DampedRotarySpring(a, b, 0.0, 1.0, 0.0)
    return (frozenset({address(view("spring", address(spring._constraint)).force_func)}),
            frozenset({address(view("rotary_spring",
                                    address(rotary._constraint)).torque_func)}))


def _probe_space() -> tuple[Any, list[Any], list[Any]]:
    """A small space of every constraint kind, stepped with contacts, and a sleeping body."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.3, -9.8)
    space.sleep_time_threshold = 0.05
    floor = pymunk.Segment(space.static_body, (-5, -1), (5, -1), 0.1)
    a, b = pymunk.Body(1.0, 0.5), pymunk.Body(2.0, 0.7)
    a.position, b.position = (0.0, -0.85), (0.5, 0.3)
    a.velocity, b.angular_velocity = (0.3, -1.0), 1.5
    rest = pymunk.Body(1.0, 0.5)
    rest.position = (3.0, -0.8)
    space.add(floor, a, pymunk.Circle(a, 0.1), b, pymunk.Circle(b, 0.1), rest,
              pymunk.Circle(rest, 0.1))
    kinds = [pymunk.PinJoint(a, b), pymunk.SlideJoint(a, b, (0, 0), (0, 0), 0.1, 0.5),
             pymunk.PivotJoint(a, b, (0.2, 0.0)),
             pymunk.GrooveJoint(a, b, (0, 0), (1, 1), (0, 0)),
             pymunk.DampedSpring(a, b, (0, 0), (0, 0), 1.0, 10.0, 0.1),
             pymunk.DampedRotarySpring(a, b, 0.1, 2.0, 0.1),
             pymunk.RotaryLimitJoint(a, b, -0.1, 0.1), pymunk.RatchetJoint(a, b, 0.0, 0.5),
             pymunk.GearJoint(a, b, 0.0, 2.0), pymunk.SimpleMotor(a, b, 1.0)]
    for c in kinds:
        c.max_force = 50.0
    space.add(*kinds)
    for _ in range(3):
        space.step(0.01)
    rest.sleep()
    return space, [a, b, rest], kinds


def problem() -> str | None:
    """Why this pymunk build's structs cannot be read as declared (None when they can):
    checked once per process (:func:`platform_problem`, then every check on
    :func:`_probe_space`). While the check runs (a program that attaches a ledger to every
    space it makes attaches one to the probe too), it answers None: each space's own checks
    still come first, and nothing read from the probe's ledger is used."""
    if _PROBLEM:
        return _PROBLEM[0]
    if _PROBING:
        return None
    _PROBING.append(True)
    try:
        found = _problem()
    finally:
        _PROBING.clear()
    _PROBLEM.append(found)
    return found


_PROBLEM: list[str | None] = []
_PROBING: list[bool] = []


def _problem() -> str | None:
    import pymunk

    try:
        why = platform_problem()
        if why is not None:
            return why
        space, bodies, kinds = _probe_space()
        check_space(space)
        for body in bodies:
            check_body(body)
        arbiters = set(array_items(address(view("space", address(space._space)).arbiters))
                       .tolist())
        if not arbiters:
            return "space.arbiters: empty on a space with contacts"
        seen: set[int] = set()
        for body in bodies[:2]:
            body.each_arbiter(lambda arb: seen.add(address(arb._arbiter)))
        if not arbiters <= seen:
            return "space.arbiters: holds arbiters its bodies do not have"
        kinematic = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        for body, kind in ((bodies[0], pymunk.Body.DYNAMIC),
                           (kinematic, pymunk.Body.KINEMATIC),
                           (space.static_body, pymunk.Body.STATIC)):
            r = view("body", address(body._body))
            seen_kind = (pymunk.Body.STATIC if r.idle_time == float("inf") else
                         pymunk.Body.KINEMATIC if r.m == float("inf") else pymunk.Body.DYNAMIC)
            if seen_kind != kind or body.body_type != kind:
                return "body: type"
        for c in kinds:
            check_constraint(c)
    except LayoutError as e:
        return str(e)
    return None


def body_function(body: Any, name: str) -> Any:
    """The ``velocity_func`` or ``position_func`` (``name``) that pymunk calls for ``body``
    instead of Chipmunk's own; None when the body uses the default.

    pymunk 7.1 and later read it back through the property. pymunk 7.0.x's property has only
    a setter, which keeps a custom function as ``_velocity_func`` / ``_position_func``. Up to
    7.3.0 the setter does not forget that function when pymunk's own is set again: the getter
    (or the kept attribute) then names a function pymunk no longer calls. So a custom
    function is confirmed by the body's own function pointer, read through the checked
    declarations when they read this build right."""
    import pymunk

    velocity = name == "velocity_func"
    default = pymunk.Body.update_velocity if velocity else pymunk.Body.update_position
    try:
        func = getattr(body, name)
    except AttributeError:  # pymunk 7.0.x: a setter only
        func = getattr(body, f"_{name}", None)
    if func is None or func is default:
        return None
    if readable():
        at = address(getattr(view("body", address(body._body)), name))
        if at in default_funcs()[0 if velocity else 1]:
            return None
    return func


def readable() -> bool:
    """True when the declarations read this pymunk build's structs right (see
    :func:`problem`)."""
    return problem() is None
