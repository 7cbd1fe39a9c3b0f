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

import weakref
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

#: Most elements a solver array is believed to hold (a header past it is a misread).
_ARRAY_MAX = 1 << 28
#: Lowest address a live object can have (the first page is never mapped).
_LOWEST = 4096
#: Past the highest address a live object can have: 2**56 bytes covers every 64-bit
#: process's user space (x86-64's five-level paging, arm64's 52-bit addresses).
_TOP = 1 << 56


#: Spaces -> the addresses of the ledgers' hooks in them (:mod:`._hook`): what a space's
#: C constraint array holds beyond its constraints.
HOOKS: Any = None


def hooks(space: Any) -> set[int]:
    """Addresses of the hooks now in ``space``."""
    return set(_hooks().get(space, ()))


def _hooks() -> Any:
    global HOOKS
    if HOOKS is None:
        import weakref

        HOOKS = weakref.WeakKeyDictionary()
    return HOOKS


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


def pymunk_version() -> str:
    """The installed pymunk's version (``pymunk.version`` says Munk2D's on pymunk 7.0.x)."""
    from importlib import metadata

    try:
        return metadata.version("pymunk")
    except metadata.PackageNotFoundError:  # pragma: no cover - pymunk not from a package
        import pymunk

        return str(pymunk.version)


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
    return _sizes_problem() or _alignment_problem()


def _sizes_problem() -> str | None:
    p = _pymunk_ffi()
    ptr = p.sizeof("void *")
    if ptr != 8:
        return f"pointers are {ptr} bytes (the contact reads are written for 8)"
    wrong = [f"{name} is {p.sizeof(name)} bytes, not {want}" for name, want in
             (("cpFloat", 8), ("cpVect", 16), ("uintptr_t", ptr), ("cpHashValue", ptr),
              ("int", 4)) if p.sizeof(name) != want]
    wrong += [f"{name} is {p.sizeof(name)} bytes" for name in ("cpBool", "cpTimestamp")
              if p.sizeof(name) not in (1, 2, 4, 8)]
    if ffi().sizeof("void *") != ptr:
        wrong.append("cffi and pymunk disagree on the pointer width")
    if p.sizeof("cpCollisionHandler") % ptr:
        wrong.append("cpCollisionHandler is not a whole number of pointers")
    if p.sizeof("cpArbiter") % 8 or p.sizeof("cpContact") % 8:
        wrong.append("cpArbiter or cpContact is not a whole number of 8-byte words")
    return wrong[0] if wrong else None


def _alignment_problem() -> str | None:
    p = _pymunk_ffi()
    ptr = p.sizeof("void *")
    fields = [(kind, path, 8) for kind, paths in _FLOAT_FIELDS.items() for path in paths]
    fields += [(kind, path, ptr) for kind, paths in _POINTER_FIELDS.items() for path in paths]
    for kind, path, step in fields:
        if offset(kind, *path.split(".")) % step:
            return f"{kind}.{path} is not {step}-byte aligned on this platform"
    # pymunk's own declarations of the arbiters and contacts the gathers read.
    for struct, names, step in (("cpArbiter", ("n",), 8), ("cpArbiter", ("count", "state"), 4),
                                ("cpArbiter", ("body_a", "body_b", "contacts"), ptr),
                                ("cpContact", ("r1", "r2", "jnAcc", "jtAcc", "jBias"), 8)):
        for name in names:
            if p.offsetof(struct, name) % step:
                return f"{struct}.{name} is not aligned for the gathers on this platform"
    # The contacts' reads take an arbiter's two bodies as one pair of words, and a contact's
    # r1.x and r2.x (and their y) as one strided slice.
    if p.offsetof("cpArbiter", "body_b") != p.offsetof("cpArbiter", "body_a") + ptr:
        return "cpArbiter.body_b does not follow body_a"
    if p.offsetof("cpContact", "r2") <= p.offsetof("cpContact", "r1"):
        return "cpContact.r2 does not follow r1"
    if p.offsetof("cpContact", "jtAcc") != p.offsetof("cpContact", "jnAcc") + 8:
        return "cpContact.jtAcc does not follow jnAcc"
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
    top = min(1 << (8 * pointer_size()), _TOP)
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


class BodyArrays:
    """The bodies of the space as Chipmunk holds them while none sleeps: its arrays of
    dynamic and kinematic bodies and of static bodies (places validated by
    :func:`._layout.check_space`, with that of the sleeping components' roots, which must be
    empty), read as bytes with the number of pymunk's bodies (``len(space.bodies)``).

    pymunk adds and removes a body in its Python list and in these arrays together
    (``Space.add`` and ``remove`` call ``cpSpaceAddBody`` and ``cpSpaceRemoveBody``); a body
    awake is in one of the two arrays, and a removed one the ledger still holds stays
    allocated, so that no other body takes its address. So while :meth:`read` gives what it
    gave when ``space.bodies`` last held the bodies the ledger knows, it still holds them: a
    read of a few hundred bytes instead of a tuple of every body each step."""

    def __init__(self, space: Any) -> None:
        p = _pymunk_ffi()
        r = view("space", address(space._space))
        self._space = weakref.ref(space)
        self._buffer, self._width = p.buffer, pointer_size()
        self._arrays = tuple(p.cast("cpArray *", address(getattr(r, name))) for name in
                             ("dynamic_bodies", "static_bodies", "sleeping_components"))

    def read(self, space: Any) -> tuple[Any, ...] | None:
        """The arrays' bytes and the number of pymunk's bodies; None unless ``space`` is
        the space these arrays are of and no body sleeps. A sleeping component's other
        bodies are in none of the arrays (only its root is): a body removed from it and
        another put to sleep in it read the same."""
        if space is not self._space():
            return None
        dynamic, static, sleeping = self._arrays
        if sleeping.num:
            return None
        buffer, width = self._buffer, self._width
        return (len(space.bodies),
                *(buffer(a.arr, width * a.num)[:] if a.num else b"" for a in (dynamic, static)))


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


class Memory:
    """The process's memory from :data:`_LOWEST` to :data:`_TOP` as one read-only numpy
    array of 8-byte words (``u64``, ``i64``, ``f64``): making it reads nothing, and indexing
    it reads only the words indexed. The word at address ``a`` is ``(a - LOWEST) >> 3``.

    The contacts' structs move every step (Munk2D takes each step's contacts from fresh
    buffers): indexed here, their reads need no span found first (two numpy calls fewer
    each, and no view made again when they land outside the last one): one ``take`` reads
    what a step needs of all its arbiters, another of all its contacts. Only 8-byte platforms get here
    (:func:`platform_problem`)."""

    LOWEST = _LOWEST

    def __init__(self) -> None:
        f = ffi()
        words = (_TOP - _LOWEST) >> 3
        raw = np.frombuffer(f.buffer(f.cast("char *", _LOWEST), words << 3), dtype=np.uint64)
        raw.flags.writeable = False
        self.u64 = raw
        self.i64 = raw.view(np.int64)
        self.f64 = raw.view(np.float64)


@cache
def memory() -> Memory:
    """The process's memory as numpy views (see :class:`Memory`)."""
    return Memory()


class Reader:
    """Fields of structs of one kind at fixed addresses, read in one numpy gather each:
    ``floats()`` (fields, structs) float64, ``pointers()`` (fields, structs) uint64."""

    def __init__(self, kind: str, at: np.ndarray, floats: tuple[str, ...],
                 ptrs: tuple[str, ...] = ()) -> None:
        self.span = Span.over(at, size(kind))
        self.fi = self.pi = self._all = None
        self.shape = (len(floats), len(ptrs))
        if self.span is None:
            return
        if np.any(at % np.uint64(8)):
            raise LayoutError(f"{kind}: a struct not 8-byte aligned")
        rel = at - np.uint64(self.span.lo)
        # Indices as numpy's own index type: a take casts any other type on every call.
        if floats:
            self.fi = np.stack([(rel + np.uint64(offset(kind, *f.split(".")))) >> np.uint64(3)
                                for f in floats]).astype(np.intp)
        if ptrs:
            shift = np.uint64(self.span.pshift)
            self.pi = np.stack([(rel + np.uint64(offset(kind, *f.split(".")))) >> shift
                                for f in ptrs]).astype(np.intp)

    def floats(self) -> np.ndarray:
        if self.span is None:
            return np.zeros((self.shape[0], 0))
        return self.span.f64.take(self.fi)

    def both(self) -> tuple[np.ndarray, np.ndarray]:
        """``floats()`` and ``pointers()``, in one gather where pointers are 8 bytes."""
        if self.span is None or self.span.pshift != 3 or self.fi is None or self.pi is None:
            return self.floats(), self.pointers()
        if self._all is None:
            self._all = np.concatenate([self.fi, self.pi])
        out = self.span.u64.take(self._all)
        nf = len(self.fi)
        return out[:nf].view(np.float64), out[nf:]

    def pointers(self) -> np.ndarray:
        if self.span is None:
            return np.zeros((self.shape[1], 0), dtype=np.uint64)
        out = self.span.ptr.take(self.pi)
        return out if out.dtype == np.uint64 else out.astype(np.uint64)


def struct_of(c: Any) -> str | None:
    """The declared struct of a pymunk constraint (of a subclass too), or None."""
    for kls in type(c).__mro__:
        if kls.__name__ in STRUCT and kls.__module__.startswith("pymunk"):
            return STRUCT[kls.__name__]
    return None
