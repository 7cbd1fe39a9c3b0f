"""Read pymunk's C structs in bulk: what the energy ledger needs and pymunk's Python API does
not give (signed constraint impulses, the solver's bias velocities, the list of contacts the
solver used in a step), for many bodies at once with numpy.

pymunk 7 runs on Munk2D (a Chipmunk2D fork). pymunk's compiled module declares the arbiters,
contacts and ``cpArray`` in full (their layout is checked by the C compiler when pymunk is
built: read through it, they are right by construction), but keeps ``cpSpace``, ``cpBody``
and the constraints opaque. Those are declared here in cffi's ABI mode (no compiler), with
pymunk's own sizes of ``cpFloat``, ``cpBool``, ``cpTimestamp``, ``cpHashValue`` and pointers,
and cffi lays them out by the platform's C rules. Nothing is trusted blindly:

- :func:`platform_problem`: the gathers index memory in 8-byte words, so every float field
  must sit at a multiple of 8 and every pointer at a multiple of the pointer width;
- :func:`check_space`: the settings up to ``dt`` against pymunk's getters (with a
  tolerance), then, before any pointer past ``dt`` is followed, the fields past it that
  Chipmunk's public C getters return (the shape id counter, the static body); then each
  array's header, and its contents against the objects the space is known to hold;
- :func:`check_body` and :func:`check_constraint`: every field read against pymunk's getters
  and Chipmunk's C getters (bodies, space, user data), floats with a tolerance;
- :func:`readable`: all of it once per process on a small space of every constraint kind,
  stepped with contacts and a sleeping body.

When any check fails, the ledger says so once and counts with pymunk's public API only
(:mod:`._public`). Reads happen only at addresses of live objects of the space and at the
solver's own arrays.

:class:`Reader` reads fields of many structs of one type at once: it views the memory from
the lowest to the highest address as one numpy array (creating the view reads nothing) and
picks the fields by index, so only the structs' own bytes are read.
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any

import numpy as np

#: The structs, in Munk2D's field order (its include/chipmunk/chipmunk_structs.h, the same in
#: every pymunk 7.x). The typedefs come from pymunk's compiled module (:func:`_typedefs`);
#: ``handler`` stands for the space's global collision handler, ``handler_words`` pointer-
#: sized words long.
_DECLARATIONS = """
typedef struct { cpFloat x, y; } vec;
typedef struct { int num, max; void **arr; } array;
typedef struct {
    void *velocity_func, *position_func;
    cpFloat m, m_inv, i, i_inv;
    vec cog, p, v, f;
    cpFloat a, w, t;
    cpFloat transform[6];
    void *user_data;
    vec v_bias;
    cpFloat w_bias;
    void *space, *shapes, *arbiters, *constraints;
    void *root, *next;
    cpFloat idle_time;
} body;
typedef struct {
    void *klass, *space, *a, *b, *next_a, *next_b;
    cpFloat max_force, error_bias, max_bias;
    cpBool collide_bodies;
    void *pre_solve, *post_solve, *user_data;
} constraint;
typedef struct { constraint c; vec anchor_a, anchor_b; cpFloat dist; vec r1, r2, n;
                 cpFloat n_mass, j, bias; } pin;
typedef struct { constraint c; vec anchor_a, anchor_b; cpFloat min, max; vec r1, r2, n;
                 cpFloat n_mass, j, bias; } slide;
typedef struct { constraint c; vec anchor_a, anchor_b; vec r1, r2; cpFloat k[4];
                 vec j, bias; } pivot;
typedef struct { constraint c; vec groove_n, groove_a, groove_b, anchor_b, groove_tn;
                 cpFloat clamp; vec r1, r2; cpFloat k[4]; vec j, bias; } groove;
typedef struct { constraint c; vec anchor_a, anchor_b; cpFloat rest, stiffness, damping;
                 void *force_func; cpFloat target_vrn, v_coef; vec r1, r2; cpFloat n_mass;
                 vec n; cpFloat j; } spring;
typedef struct { constraint c; cpFloat rest, stiffness, damping; void *torque_func;
                 cpFloat target_wrn, w_coef, i_sum, j; } rotary_spring;
typedef struct { constraint c; cpFloat min, max, i_sum, bias, j; } rotary_limit;
typedef struct { constraint c; cpFloat angle, phase, ratchet, i_sum, bias, j; } ratchet;
typedef struct { constraint c; cpFloat phase, ratio, ratio_inv, i_sum, bias, j; } gear;
typedef struct { constraint c; cpFloat rate, i_sum, j; } motor;
typedef struct {
    int iterations;
    vec gravity;
    cpFloat damping, idle_speed, sleep_time, slop, bias;
    cpTimestamp persistence;
    void *user_data;
    cpTimestamp stamp;
    cpFloat dt;
    array *dynamic_bodies, *static_bodies, *roused_bodies, *sleeping_components;
    cpHashValue shape_ids;
    void *static_shapes, *dynamic_shapes;
    array *constraints;
    array *arbiters;
    void *contact_buffers, *cached_arbiters;
    array *pooled_arbiters, *allocated_buffers;
    int locked;
    void *collision_handlers;
    uintptr_t handler[HANDLER_WORDS];
    cpBool skip_post_step;
    array *post_step_callbacks;
    void *static_body;
    body own_static_body;
} space;
"""

#: pymunk constraint class -> struct declared above.
STRUCT = {"PinJoint": "pin", "SlideJoint": "slide", "PivotJoint": "pivot",
          "GrooveJoint": "groove", "DampedSpring": "spring",
          "DampedRotarySpring": "rotary_spring", "RotaryLimitJoint": "rotary_limit",
          "RatchetJoint": "ratchet", "GearJoint": "gear", "SimpleMotor": "motor"}

#: Relative tolerance of a float read against pymunk's getter (both read the same double;
#: a getter may compute, e.g. a pivot's impulse is the length of its accumulated vector).
TOLERANCE = 1e-12
#: Most elements a solver array is believed to hold (a header past it is a misread).
_ARRAY_MAX = 1 << 28
#: Lowest address a live object can have (the first page is never mapped).
_LOWEST = 4096


class LayoutError(Exception):
    """pymunk's structs are not laid out as declared here (another pymunk build)."""


@cache
def _pymunk_ffi() -> Any:
    from pymunk._chipmunk_cffi import ffi as pffi

    return pffi


@cache
def _lib() -> Any:
    from pymunk._chipmunk_cffi import lib

    return lib


def _unsigned(size: int) -> str:
    return {1: "unsigned char", 2: "unsigned short", 4: "unsigned int",
            8: "unsigned long long"}[size]


@cache
def _typedefs() -> str:
    """pymunk's own sizes of Chipmunk's scalar types, as C typedefs."""
    p = _pymunk_ffi()
    return "\n".join([
        "typedef double cpFloat;",
        f"typedef {_unsigned(p.sizeof('cpBool'))} cpBool;",
        f"typedef {_unsigned(p.sizeof('cpTimestamp'))} cpTimestamp;",
        f"typedef {_unsigned(p.sizeof('cpHashValue'))} cpHashValue;"])


@cache
def ffi() -> Any:
    """The cffi declarations (ABI mode: no compiler)."""
    import cffi

    p = _pymunk_ffi()
    words = p.sizeof("cpCollisionHandler") // p.sizeof("uintptr_t")
    f = cffi.FFI()
    f.cdef(_typedefs() + _DECLARATIONS.replace("HANDLER_WORDS", str(max(words, 1))))
    return f


#: Size of a pointer in bytes (4 or 8), and the numpy type of one.
def pointer_size() -> int:
    return int(ffi().sizeof("void *"))


def pointer_dtype() -> Any:
    return np.uint64 if pointer_size() == 8 else np.uint32


#: Float and pointer fields each struct's readers gather (checked for alignment).
_FLOAT_FIELDS = {
    "body": ("p.x", "p.y", "a", "v.x", "v.y", "w", "f.x", "f.y", "t", "m", "i", "cog.x",
             "cog.y", "v_bias.x", "v_bias.y", "w_bias", "idle_time"),
    "spring": ("rest", "stiffness", "damping", "c.max_force", "j", "n.x", "n.y", "r1.x",
               "r1.y", "r2.x", "r2.y", "anchor_a.x", "anchor_a.y", "anchor_b.x",
               "anchor_b.y"),
    "rotary_spring": ("rest", "stiffness", "damping", "c.max_force", "j"),
    "pin": ("j", "n.x", "n.y", "r1.x", "r1.y", "r2.x", "r2.y"),
    "slide": ("j", "n.x", "n.y", "r1.x", "r1.y", "r2.x", "r2.y"),
    "pivot": ("j.x", "j.y", "r1.x", "r1.y", "r2.x", "r2.y"),
    "groove": ("j.x", "j.y", "r1.x", "r1.y", "r2.x", "r2.y"),
    "rotary_limit": ("j", "bias"), "ratchet": ("j", "bias"), "gear": ("j", "ratio_inv"),
    "motor": ("j",),
}
_POINTER_FIELDS = {"body": ("velocity_func", "position_func", "root"),
                   "spring": ("force_func",), "rotary_spring": ("torque_func",)}


@cache
def platform_problem() -> str | None:
    """Why the declared structs cannot be read on this platform, or None: pymunk's scalar
    types, the pointer width, and the alignment the 8-byte gathers need."""
    p = _pymunk_ffi()
    ptr = p.sizeof("void *")
    if ptr not in (4, 8):
        return f"pointers are {ptr} bytes"
    for name, want in (("cpFloat", 8), ("cpVect", 16), ("uintptr_t", ptr),
                       ("cpHashValue", ptr)):
        if p.sizeof(name) != want:
            return f"{name} is {p.sizeof(name)} bytes, not {want}"
    if p.sizeof("cpBool") not in (1, 2, 4, 8) or p.sizeof("cpTimestamp") not in (1, 2, 4, 8):
        return "cpBool or cpTimestamp has an unusual size"
    f = ffi()
    if f.sizeof("void *") != ptr:
        return "cffi and pymunk disagree on the pointer width"
    if p.sizeof("cpCollisionHandler") % ptr:
        return "cpCollisionHandler is not a whole number of pointers"
    # pymunk's own declarations of the arbiters and contacts the gathers read.
    for struct, fields, step in (("cpArbiter", ("n",), 8), ("cpArbiter", ("count", "state"), 4),
                                 ("cpArbiter", ("body_a", "body_b", "contacts"), ptr),
                                 ("cpContact", ("r1", "r2", "jnAcc", "jtAcc", "jBias"), 8)):
        for name in fields:
            if p.offsetof(struct, name) % step:
                return f"{struct}.{name} is not aligned for the gathers on this platform"
    if p.sizeof("cpArbiter") % 8 or p.sizeof("cpContact") % 8:
        return "cpArbiter or cpContact is not a whole number of 8-byte words"
    for kind, fields in _FLOAT_FIELDS.items():
        for path in fields:
            if offset(kind, *path.split(".")) % 8:
                return f"{kind}.{path} is not 8-byte aligned on this platform"
    for kind, fields in _POINTER_FIELDS.items():
        for path in fields:
            if offset(kind, path) % ptr:
                return f"{kind}.{path} is not pointer-aligned on this platform"
    return None


def address(cdata: Any) -> int:
    """The address a pymunk cffi pointer points to."""
    return int(_pymunk_ffi().cast("uintptr_t", cdata))


def addresses(objects: Any, attr: str) -> np.ndarray:
    """Addresses (uint64) of the structs of many pymunk objects (``attr``: '_body',
    '_constraint', ...)."""
    cast = _pymunk_ffi().cast
    return np.array([int(cast("uintptr_t", getattr(o, attr))) for o in objects],
                    dtype=np.uint64)


def view(kind: str, at: int) -> Any:
    """A cffi pointer of struct type ``kind`` at address ``at`` (attribute access by name)."""
    return ffi().cast(f"{kind} *", at)


def offset(kind: str, *path: str) -> int:
    """Byte offset of a (nested) field, e.g. ``offset('spring', 'r1')``."""
    return int(ffi().offsetof(kind, *path))


def size(kind: str) -> int:
    return int(ffi().sizeof(kind))


def _plausible(at: int) -> bool:
    """An address a live, pointer-aligned object can have."""
    top = 1 << (8 * pointer_size())
    return _LOWEST <= at < top and at % pointer_size() == 0


def array_items(arr_at: int) -> np.ndarray:
    """The pointers held in a Chipmunk ``cpArray`` at ``arr_at`` (uint64 addresses), read
    through pymunk's compiled declaration of ``cpArray``; a header that cannot be a live
    array's raises :class:`LayoutError` before its items are read."""
    p = _pymunk_ffi()
    arr = p.cast("cpArray *", arr_at)
    num, cap = int(arr.num), int(arr.max)
    if not 0 <= num <= cap <= _ARRAY_MAX:
        raise LayoutError(f"array: {num} of {cap} items")
    if num == 0:
        return np.zeros(0, dtype=np.uint64)
    items = address(arr.arr)
    if not _plausible(items):
        raise LayoutError("array: its items are not at a valid address")
    out = np.frombuffer(p.buffer(arr.arr, pointer_size() * num), dtype=pointer_dtype())
    return out.astype(np.uint64)


def pointers(arr_at: int) -> np.ndarray:
    """Alias of :func:`array_items` (the pointers held in a ``cpArray``)."""
    return array_items(arr_at)


class Span:
    """A numpy view over the memory from ``lo`` to ``hi`` (bytes), typed several ways;
    ``ptr`` is the view of pointer-sized words and ``pshift`` the shift from a byte offset
    to its index."""

    __slots__ = ("f64", "i64", "lo", "pshift", "ptr", "u8", "u32", "u64")

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
        wide = pointer_size() == 8
        self.ptr = self.u64 if wide else self.u32
        self.pshift = 3 if wide else 2

    @classmethod
    def over(cls, at: np.ndarray, nbytes: int) -> Span | None:
        """The span covering structs of ``nbytes`` at the addresses ``at``."""
        if len(at) == 0:
            return None
        return cls(int(at.min()), int(at.max()) + nbytes)

    def _index(self, at: np.ndarray, off: Any) -> np.ndarray:
        return (at - np.uint64(self.lo)) + np.asarray(off, dtype=np.uint64)

    def f(self, at: np.ndarray, off: Any) -> np.ndarray:
        """float64 fields at ``at + off`` (a copy)."""
        return self.f64[self._index(at, off) >> np.uint64(3)]

    def p(self, at: np.ndarray, off: Any) -> np.ndarray:
        """Pointer fields at ``at + off`` (uint64)."""
        return self.ptr[self._index(at, off) >> np.uint64(self.pshift)].astype(np.uint64)

    def i(self, at: np.ndarray, off: Any) -> np.ndarray:
        """32-bit unsigned fields at ``at + off``."""
        return self.u32[self._index(at, off) >> np.uint64(2)]


class Reader:
    """Fields of structs of one kind at fixed addresses, read in one numpy gather each:
    ``floats()`` (fields, structs) float64, ``pointers()`` (fields, structs) uint64."""

    def __init__(self, kind: str, at: np.ndarray, floats: tuple[str, ...],
                 ptrs: tuple[str, ...] = ()) -> None:
        self.span = Span.over(at, size(kind))
        self.fi = self.pi = None
        self.shape = (len(floats), len(ptrs))
        if self.span is None:
            return
        if np.any(at % np.uint64(8)):
            raise LayoutError(f"{kind}: a struct not 8-byte aligned")
        rel = at - np.uint64(self.span.lo)
        if floats:
            self.fi = np.stack([(rel + np.uint64(offset(kind, *f.split(".")))) >> np.uint64(3)
                                for f in floats])
        if ptrs:
            shift = np.uint64(self.span.pshift)
            self.pi = np.stack([(rel + np.uint64(offset(kind, *f.split(".")))) >> shift
                                for f in ptrs])

    def floats(self) -> np.ndarray:
        if self.span is None:
            return np.zeros((self.shape[0], 0))
        return self.span.f64[self.fi]

    def pointers(self) -> np.ndarray:
        if self.span is None:
            return np.zeros((self.shape[1], 0), dtype=np.uint64)
        out = self.span.ptr[self.pi]
        return out if out.dtype == np.uint64 else out.astype(np.uint64)


# --------------------------------------------------------------------------------------
# Checks: what the declarations read against what pymunk and Chipmunk's C API say.


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
    for name in ("dynamic_bodies", "constraints", "arbiters"):
        if not _plausible(address(getattr(r, name))):
            raise LayoutError(f"space.{name}: not a valid address")
    # Now the arrays: their headers, then what they hold.
    constraints = set(array_items(address(r.constraints)).tolist())
    known = {address(c._constraint) for c in space.constraints}
    from . import _hook

    hooks = _hook.addresses(space)
    if not known <= constraints or not constraints <= known | hooks:
        raise LayoutError("space.constraints: does not hold the space's constraints")
    bodies = set(array_items(address(r.dynamic_bodies)).tolist())
    if not bodies <= {address(b._body) for b in space.bodies}:
        raise LayoutError("space.dynamic_bodies: holds bodies the space does not")
    array_items(address(r.arbiters))
    return at


def check_body(body: Any) -> None:
    """Raise :class:`LayoutError` unless the declared body struct reads what pymunk reads."""
    lib = _lib()
    r = view("body", address(body._body))
    cog = body.local_to_world(body.center_of_gravity)
    # The centre of gravity in world coordinates goes through pymunk's transform.
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


def struct_of(c: Any) -> str | None:
    """The declared struct of a pymunk constraint (of a subclass too), or None."""
    for kls in type(c).__mro__:
        if kls.__name__ in STRUCT and kls.__module__.startswith("pymunk"):
            return STRUCT[kls.__name__]
    return None


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


def readable() -> bool:
    """True when the declarations read this pymunk build's structs right (see
    :func:`problem`)."""
    return problem() is None
