"""Read pymunk's C structs in bulk: what the energy ledger needs and pymunk's Python API does
not give (signed constraint impulses, contact impulses, the solver's bias velocities, the
list of contacts the solver used in a step), for many bodies at once with numpy.

pymunk 7 runs on Munk2D (a Chipmunk2D fork). Its struct layouts are declared here in cffi's
ABI mode (no compiler): cffi lays them out by the platform's C rules. Nothing is trusted
blindly: :func:`check` compares what the declarations read against pymunk's own getters
(masses, positions, velocities, every constraint setting, the space's settings and time
stamp) on live objects, and the ledger refuses to attach when they differ (another pymunk
build), rather than read the wrong bytes. Reads happen only at addresses of live objects of
the space and at the solver's own arrays.

:func:`gather` reads fields of many structs of one type at once: it views the memory from the
lowest to the highest address as one numpy array (creating the view reads nothing) and picks
the fields by index, so only the structs' own bytes are read.
"""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np

#: The structs, in Munk2D's field order (cpFloat = double, cpBool = unsigned char,
#: cpTimestamp = unsigned int, pointers and cpHashValue 8 bytes on 64-bit platforms).
_DECLARATIONS = """
typedef struct { double x, y; } vec;
typedef struct { int num, max; void **arr; } array;
typedef struct {
    void *velocity_func, *position_func;
    double m, m_inv, i, i_inv;
    vec cog, p, v, f;
    double a, w, t;
    double transform[6];
    void *user_data;
    vec v_bias;
    double w_bias;
    void *space, *shapes, *arbiters, *constraints;
    void *root, *next;
    double idle_time;
} body;
typedef struct {
    void *klass, *space, *a, *b, *next_a, *next_b;
    double max_force, error_bias, max_bias;
    unsigned char collide_bodies;
    void *pre_solve, *post_solve, *user_data;
} constraint;
typedef struct { constraint c; vec anchor_a, anchor_b; double dist; vec r1, r2, n;
                 double n_mass, j, bias; } pin;
typedef struct { constraint c; vec anchor_a, anchor_b; double min, max; vec r1, r2, n;
                 double n_mass, j, bias; } slide;
typedef struct { constraint c; vec anchor_a, anchor_b; vec r1, r2; double k[4];
                 vec j, bias; } pivot;
typedef struct { constraint c; vec groove_n, groove_a, groove_b, anchor_b, groove_tn;
                 double clamp; vec r1, r2; double k[4]; vec j, bias; } groove;
typedef struct { constraint c; vec anchor_a, anchor_b; double rest, stiffness, damping;
                 void *force_func; double target_vrn, v_coef; vec r1, r2; double n_mass;
                 vec n; double j; } spring;
typedef struct { constraint c; double rest, stiffness, damping; void *torque_func;
                 double target_wrn, w_coef, i_sum, j; } rotary_spring;
typedef struct { constraint c; double min, max, i_sum, bias, j; } rotary_limit;
typedef struct { constraint c; double angle, phase, ratchet, i_sum, bias, j; } ratchet;
typedef struct { constraint c; double phase, ratio, ratio_inv, i_sum, bias, j; } gear;
typedef struct { constraint c; double rate, i_sum, j; } motor;
typedef struct {
    int iterations;
    vec gravity;
    double damping, idle_speed, sleep_time, slop, bias;
    unsigned int persistence;
    void *user_data;
    unsigned int stamp;
    double dt;
    array *dynamic_bodies, *static_bodies, *roused_bodies, *sleeping_components;
    uintptr_t shape_ids;
    void *static_shapes, *dynamic_shapes;
    array *constraints;
    array *arbiters;
} space;
"""

#: pymunk constraint class -> struct declared above.
STRUCT = {"PinJoint": "pin", "SlideJoint": "slide", "PivotJoint": "pivot",
          "GrooveJoint": "groove", "DampedSpring": "spring",
          "DampedRotarySpring": "rotary_spring", "RotaryLimitJoint": "rotary_limit",
          "RatchetJoint": "ratchet", "GearJoint": "gear", "SimpleMotor": "motor"}


class LayoutError(Exception):
    """pymunk's structs are not laid out as declared here (another pymunk build)."""


@cache
def ffi() -> Any:
    """The cffi declarations (ABI mode: no compiler)."""
    import cffi

    f = cffi.FFI()
    f.cdef(_DECLARATIONS)
    return f


def address(cdata: Any) -> int:
    """The address a pymunk cffi pointer points to."""
    return int(_cast()("uintptr_t", cdata))


def addresses(objects: Any, attr: str) -> np.ndarray:
    """Addresses (uint64) of the structs of many pymunk objects (``attr``: '_body',
    '_constraint', ...)."""
    cast = _cast()
    return np.array([int(cast("uintptr_t", getattr(o, attr))) for o in objects],
                    dtype=np.uint64)


@cache
def _cast() -> Any:
    from pymunk._chipmunk_cffi import ffi as pffi

    return pffi.cast


def view(kind: str, at: int) -> Any:
    """A cffi pointer of struct type ``kind`` at address ``at`` (attribute access by name)."""
    return ffi().cast(f"{kind} *", at)


def offset(kind: str, *path: str) -> int:
    """Byte offset of a (nested) field, e.g. ``offset('spring', 'r1')``."""
    return ffi().offsetof(kind, *path)


def size(kind: str) -> int:
    return ffi().sizeof(kind)


def pointers(arr_at: int) -> np.ndarray:
    """The pointers held in a Chipmunk ``cpArray`` at ``arr_at`` (uint64 addresses)."""
    f = ffi()
    arr = f.cast("array *", arr_at)
    n = int(arr.num)
    if n == 0:
        return np.zeros(0, dtype=np.uint64)
    return np.frombuffer(f.buffer(arr.arr, 8 * n), dtype=np.uint64).copy()


class Span:
    """A numpy view over the memory from ``lo`` to ``hi`` (bytes), typed three ways."""

    __slots__ = ("f64", "i64", "lo", "u8", "u32", "u64")

    def __init__(self, lo: int, hi: int) -> None:
        f = ffi()
        self.lo = lo & ~7
        n = (hi - self.lo + 7) & ~7
        raw = np.frombuffer(f.buffer(f.cast("char *", self.lo), n), dtype=np.uint8)
        self.u8 = raw
        self.u32 = raw.view(np.uint32)
        self.u64 = raw.view(np.uint64)
        self.i64 = raw.view(np.int64)
        self.f64 = raw.view(np.float64)

    @classmethod
    def over(cls, at: np.ndarray, nbytes: int) -> Span | None:
        """The span covering structs of ``nbytes`` at the addresses ``at``."""
        if len(at) == 0:
            return None
        return cls(int(at.min()), int(at.max()) + nbytes)

    def _index(self, at: np.ndarray, off: int) -> np.ndarray:
        return (at - np.uint64(self.lo)) + np.uint64(off)

    def f(self, at: np.ndarray, off: int) -> np.ndarray:
        """float64 fields at ``at + off`` (a copy)."""
        return self.f64[self._index(at, off) >> np.uint64(3)]

    def p(self, at: np.ndarray, off: int) -> np.ndarray:
        """Pointer (uint64) fields at ``at + off``."""
        return self.u64[self._index(at, off) >> np.uint64(3)]

    def i(self, at: np.ndarray, off: int) -> np.ndarray:
        """32-bit unsigned fields at ``at + off``."""
        return self.u32[self._index(at, off) >> np.uint64(2)]

    def b(self, at: np.ndarray, off: int) -> np.ndarray:
        """Byte fields at ``at + off``."""
        return self.u8[self._index(at, off)]


def _close(a: float, b: float) -> bool:
    import math

    return a == b or (math.isnan(a) and math.isnan(b))


def check_body(body: Any) -> None:
    """Raise :class:`LayoutError` unless the declared body struct reads what pymunk reads."""
    r = view("body", address(body._body))
    cog = body.local_to_world(body.center_of_gravity)
    pairs = [(r.m, body.mass), (r.i, body.moment), (r.cog.x, body.center_of_gravity[0]),
             (r.cog.y, body.center_of_gravity[1]), (r.p.x, cog[0]), (r.p.y, cog[1]),
             (r.v.x, body.velocity[0]), (r.v.y, body.velocity[1]), (r.a, body.angle),
             (r.w, body.angular_velocity), (r.f.x, body.force[0]), (r.t, body.torque)]
    for got, want in pairs:
        # The centre of gravity in world coordinates goes through pymunk's transform.
        if not (_close(got, want) or abs(got - want) <= 1e-9 * (1.0 + abs(want))):
            raise LayoutError(f"body: read {got!r}, pymunk says {want!r}")


def check_space(space: Any) -> None:
    """Raise :class:`LayoutError` unless the declared space struct reads pymunk's settings."""
    from pymunk._chipmunk_cffi import lib

    r = view("space", address(space._space))
    pairs = [(r.iterations, space.iterations), (r.gravity.x, space.gravity[0]),
             (r.gravity.y, space.gravity[1]), (r.damping, space.damping),
             (r.idle_speed, space.idle_speed_threshold),
             (r.sleep_time, space.sleep_time_threshold), (r.slop, space.collision_slop),
             (r.bias, space.collision_bias), (r.persistence, space.collision_persistence),
             (r.stamp, lib.cpSpaceGetTimestamp(space._space)),
             (r.dt, space.current_time_step)]
    for got, want in pairs:
        if not _close(got, want):
            raise LayoutError(f"space: read {got!r}, pymunk says {want!r}")
    n = int(view("array", address(r.constraints)).num)
    if n > len(space.constraints) + 1 or int(view("array", address(r.dynamic_bodies)).num) > \
            len(space.bodies):
        raise LayoutError("space: its arrays hold more than the space has")


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


def struct_of(c: Any) -> str | None:
    """The declared struct of a pymunk constraint (of a subclass too), or None."""
    for kls in type(c).__mro__:
        if kls.__name__ in STRUCT and kls.__module__.startswith("pymunk"):
            return STRUCT[kls.__name__]
    return None


def check_constraint(c: Any) -> None:
    """Raise :class:`LayoutError` unless the declared struct of ``c`` reads its settings,
    its bodies and (up to sign) the impulse pymunk reports."""
    import math

    kind = struct_of(c)
    if kind is None:
        raise LayoutError(f"{type(c).__name__}: not a constraint class the ledger reads")
    at = address(c._constraint)
    r = view(kind, at)
    if address(r.c.a) != address(c.a._body) or address(r.c.b) != address(c.b._body):
        raise LayoutError(f"{kind}: bodies do not match")
    for path, want in _constraint_fields(c):
        got = r
        for part in path.split("."):
            got = getattr(got, part)
        if not _close(got, want):
            raise LayoutError(f"{kind}.{path}: read {got!r}, pymunk says {want!r}")
    j = r.j
    got = math.hypot(j.x, j.y) if kind in ("pivot", "groove") else (
        j if kind in ("spring", "rotary_spring") else abs(j))
    if not _close(got, c.impulse):
        raise LayoutError(f"{kind}: impulse {got!r}, pymunk says {c.impulse!r}")


@cache
def default_funcs() -> tuple[frozenset[int], frozenset[int]]:
    """Addresses of pymunk's default velocity and position functions (as a new body holds
    them, and as pymunk sets them back)."""
    import pymunk
    from pymunk._chipmunk_cffi import ffi as pffi
    from pymunk._chipmunk_cffi import lib

    r = view("body", address(pymunk.Body(1.0, 1.0)._body))
    vel = {address(r.velocity_func), address(pffi.addressof(lib, "cpBodyUpdateVelocity"))}
    pos = {address(r.position_func), address(pffi.addressof(lib, "cpBodyUpdatePosition"))}
    return frozenset(vel), frozenset(pos)


@cache
def readable() -> bool:
    """True when the declarations read this pymunk build's structs right: checked once per
    process on a small space of every constraint kind, stepped with contacts."""
    import pymunk

    try:
        space = pymunk.Space()
        space.gravity = (0.3, -9.8)
        floor = pymunk.Segment(space.static_body, (-5, -1), (5, -1), 0.1)
        a, b = pymunk.Body(1.0, 0.5), pymunk.Body(2.0, 0.7)
        a.position, b.position = (0.0, -0.85), (0.5, 0.3)
        a.velocity, b.angular_velocity = (0.3, -1.0), 1.5
        space.add(floor, a, pymunk.Circle(a, 0.1), b, pymunk.Circle(b, 0.1))
        kinds = [pymunk.PinJoint(a, b), pymunk.SlideJoint(a, b, (0, 0), (0, 0), 0.1, 0.5),
                 pymunk.PivotJoint(a, b, (0.2, 0.0)), pymunk.GrooveJoint(a, b, (0, 0), (1, 1),
                                                                       (0, 0)),
                 pymunk.DampedSpring(a, b, (0, 0), (0, 0), 1.0, 10.0, 0.1),
                 pymunk.DampedRotarySpring(a, b, 0.1, 2.0, 0.1),
                 pymunk.RotaryLimitJoint(a, b, -0.1, 0.1), pymunk.RatchetJoint(a, b, 0.0, 0.5),
                 pymunk.GearJoint(a, b, 0.0, 2.0), pymunk.SimpleMotor(a, b, 1.0)]
        for c in kinds:
            c.max_force = 50.0
        space.add(*kinds)
        for _ in range(3):
            space.step(0.01)
        check_space(space)
        for body in (a, b):
            check_body(body)
        kinematic = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        for body, kind in ((a, pymunk.Body.DYNAMIC), (kinematic, pymunk.Body.KINEMATIC),
                           (space.static_body, pymunk.Body.STATIC)):
            r = view("body", address(body._body))
            seen = (pymunk.Body.STATIC if r.idle_time == float("inf") else
                    pymunk.Body.KINEMATIC if r.m == float("inf") else pymunk.Body.DYNAMIC)
            if seen != kind or body.body_type != kind:
                raise LayoutError("body: type")
        for c in kinds:
            check_constraint(c)
    except LayoutError:
        return False
    return True
