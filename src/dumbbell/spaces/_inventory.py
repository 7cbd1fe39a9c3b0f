"""What the ledger sees in a space, and when it changed: the bodies it reads (:class:`Table`),
the constraints by struct kind (:class:`._constraints.Group`), the pairs of bodies that touched
(:class:`Pairs`), the declared fields, all gathered in one :class:`Build`, rebuilt when
:func:`changed` says the space is no longer what it was built from.

Bodies are named as :func:`dumbbell.spaces.energy` names them when the ledger attaches
('body i', i their place in ``space.bodies``); bodies that come later take the next numbers
(:class:`Names`)."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np

from . import _constraints as constraints
from . import _layout as layout
from . import _memory as mem
from ._constraints import Group

#: Body fields read before the solver: position (x, y, angle), velocity (vx, vy, w),
#: force (fx, fy, torque), settings (mass, moment, centre of gravity), idle time (infinite
#: for a static body).
PRE = ("p.x", "p.y", "a", "v.x", "v.y", "w", "f.x", "f.y", "t", "m", "i", "cog.x", "cog.y",
       "idle_time")
#: ... after it: velocity, and the bias velocity the next move adds.
POST = ("v.x", "v.y", "w", "v_bias.x", "v_bias.y", "w_bias")
PTRS = ("root", "velocity_func", "position_func")
#: Pair keys: min(uid) * PAIR + max(uid).
PAIR = 1 << 31
#: Longest name of a declared potential (characters).
NAME_CHARS = 60


def other_ends(constraints: tuple[Any, ...], seen: set[int]) -> list[Any]:
    """The bodies ``constraints`` join that are not among ``seen`` (their ids, which this
    extends), in the order first met: the static body, bodies outside the space."""
    out = []
    for c in constraints:
        for b in (c.a, c.b):
            if id(b) not in seen:
                seen.add(id(b))
                out.append(b)
    return out


class UnknownBody(Exception):
    """A contact touches a body that is not in the ledger's table (one pymunk made since:
    the space's static body, say): the table must be built again."""


class Names:
    """Stable ids and labels of the bodies the ledger has seen, and the bodies themselves
    (kept, so that an id is never reused while the ledger lives)."""

    def __init__(self, space: Any) -> None:
        self.space = space
        self.uids: dict[int, int] = {}
        self.labels: list[str] = []
        self.kept: list[Any] = []
        self.places = {id(b): i for i, b in enumerate(space.bodies)}
        self.next = len(self.places)

    def uid(self, body: Any) -> int:
        """The stable id of ``body`` (its label is ``labels[uid]``)."""
        import pymunk

        uid = self.uids.get(id(body))
        if uid is None:
            space = self.space
            if body.body_type == pymunk.Body.STATIC and body.space is space and \
                    body not in space.bodies:
                label = "static body"  # the space's own (pymunk makes it on first use)
            else:
                place = self.places.pop(id(body), None)
                if place is None:
                    place = self.next
                    self.next += 1
                kind = {pymunk.Body.KINEMATIC: "kinematic body ",
                        pymunk.Body.STATIC: "static body "}.get(body.body_type, "body ")
                outside = "" if body.space is space else " (not in the space)"
                label = f"{kind}{place}{outside}"
            uid = len(self.labels)
            self.uids[id(body)] = uid
            self.labels.append(label)
            self.kept.append(body)
        return uid


class Table:
    """The bodies the ledger reads at every hook: dynamic rows [0, n), kinematic rows
    [n, n + k) (in the space, moved by its steps), then the other bodies constraints and
    contacts touch: static ones (the bodies of the space's shapes that are not among its
    bodies: its own static body, if pymunk made it), and bodies a constraint joins that are
    not in the space (they do not move with it; what they take is work leaving the
    system)."""

    def __init__(self, space: Any, names: Names) -> None:
        import pymunk

        bodies = list(space.bodies)
        dyn = [b for b in bodies if b.body_type == pymunk.Body.DYNAMIC]
        kin = [b for b in bodies if b.body_type == pymunk.Body.KINEMATIC]
        other = [b for b in bodies if b.body_type == pymunk.Body.STATIC]
        seen = {id(b) for b in bodies}
        for shape in space.shapes:
            if id(shape.body) not in seen:
                seen.add(id(shape.body))
                other.append(shape.body)
        self.constraint_key = tuple(space.constraints)
        other += other_ends(self.constraint_key, seen)
        self.bodies = [*dyn, *kin, *other]
        self.body_key = tuple(bodies)
        # What stands witness that space.bodies still holds body_key (:func:`same_bodies`).
        self.arrays = mem.BodyArrays(space)
        self.arrays_seen = self.arrays.read(space)
        n, k = len(dyn), len(kin)
        self.n, self.k, self.rows = n, k, len(self.bodies)
        self.uid = np.array([names.uid(b) for b in self.bodies], dtype=np.int64)
        self.labels = [names.labels[u] for u in self.uid.tolist()]
        self.at = mem.addresses(self.bodies, "_body")
        self.pre = mem.Reader("body", self.at, PRE, PTRS)
        self.post = mem.Reader("body", self.at, POST, ("root",))
        # What the end of a step reads: positions, velocities, and what changes a body's
        # energy from a callback without moving it (mass, moment, centre, body type).
        self.state = mem.Reader("body", self.at, PRE)
        first = self.pre.floats()
        self.settings = first[9:13].copy()
        self.static = np.isinf(first[13])
        self.idle = first[13, n:].copy()  # 0 kinematic, infinite static: a type changed
        Table._derive(self, first)
        for r in range(n + k, self.rows):
            self.drives[r] = self.bodies[r].body_type != pymunk.Body.STATIC
        self.any_driven = bool(self.drives.any())
        order = np.argsort(self.at)
        self.order, self.sorted_at = order, self.at[order]
        self.sorted_i64 = self.sorted_at.view(np.int64)

    @staticmethod
    def _derive(t: Any, first: np.ndarray) -> None:
        """The arrays derived from the bodies' settings (``first``: rows as :data:`PRE`) of
        a table ``t`` with ``n``, ``k`` and ``rows`` set."""
        n, k = t.n, t.k
        t.m = first[9, :n].copy()
        moment = first[10, :n]
        t.finite = np.isfinite(moment)
        t.all_finite = bool(t.finite.all())
        t.I = np.where(t.finite, moment, 0.0)
        t.mass3 = np.stack([t.m, t.m, t.I])
        # The same over every row (0 past the dynamic ones): products over whole rows.
        t.m_rows = np.zeros(t.rows)
        t.m_rows[:n] = t.m
        t.mass3_rows = np.zeros((3, t.rows))
        t.mass3_rows[:, :n] = t.mass3
        # A dynamic body of mass or moment 0 cannot be stepped (pymunk divides by them):
        # named in the build, and counted as if it had none.
        t.unsteppable = ~(t.m > 0) | ~(moment > 0)
        lin = t.m > 0
        ang = t.finite & (moment > 0)
        t.inv3 = np.stack([np.where(lin, 1.0 / np.where(lin, t.m, 1.0), 0.0),
                           np.where(lin, 1.0 / np.where(lin, t.m, 1.0), 0.0),
                           np.where(ang, 1.0 / np.where(ang, moment, 1.0), 0.0)])
        t.lin_free = np.zeros(t.rows, dtype=bool)
        t.lin_free[:n] = True
        t.lin_free_f = t.lin_free.astype(float)
        t.ang_free = np.zeros(t.rows, dtype=bool)
        t.ang_free[:n] = t.finite
        t.moves = np.zeros(t.rows, dtype=bool)
        t.moves[: n + k] = True
        t.none_asleep = np.zeros(n, dtype=bool)
        t.none_asleep.flags.writeable = False
        # What every step compares its reads with, as bytes (see :func:`changed`).
        t.settings_bytes, t.idle_bytes = t.settings.tobytes(), t.idle.tobytes()
        t.by_dt = {}
        # Rows whose motion is imposed and not counted in E: kinematic bodies and bodies
        # outside the space (linear and angular), the spin of a body of infinite moment.
        t.drives = np.zeros(t.rows, dtype=bool)
        t.drives[n: n + k] = True
        t.drives[:n] = ~t.finite
        t.any_driven = bool(t.drives.any())

    #: Most rows for which their pairs' slots are looked up in a dense map of rows (4 bytes
    #: each: 16 MB at most).
    DENSE = 2048
    #: Most entries of the map from a body's address to its row (4 bytes each: 8 MB at
    #: most): one entry every 2**k bytes from the lowest body to the highest (2**k at most
    #: a body's size: 256 bytes); farther apart, rows are searched for in the sorted
    #: addresses.
    MAP = 1 << 21

    def rows_of(self, at: np.ndarray) -> np.ndarray:
        """The rows of the bodies at the addresses ``at`` (int64); -1 where none."""
        if not hasattr(self, "_rowmap"):
            self._rowmap = self._address_map()
        if self._rowmap is None:
            if not self.rows:
                return np.full(at.shape, -1)
            pos = np.minimum(np.searchsorted(self.sorted_i64, at), self.rows - 1)
            return np.where(self.sorted_i64[pos] == at, self.order[pos], -1)
        lo, shift, rowmap = self._rowmap
        # Addresses outside the map clip to its ends, which hold no row.
        return rowmap.take((at - lo) >> shift, mode="clip")

    def _address_map(self) -> tuple[int, int, np.ndarray] | None:
        """(lo, shift, map): the row of the body at address a is ``map[(a - lo) >>
        shift]`` (-1 where no body of the table is). An entry covers 2**shift bytes, at most
        a body's struct: two live bodies' addresses are at least that far apart, so that no
        other live body's address falls on a table body's entry (and the map is small
        enough to stay in the caches); the first and the last entry hold no body. None when
        the map would pass :data:`MAP`."""
        if not self.rows:
            return None
        at = self.at.astype(np.int64)
        shift = max(3, mem.size("body").bit_length() - 1)
        lo = int(at.min()) - (1 << shift)
        entries = ((int(at.max()) - lo) >> shift) + 2
        if entries > self.MAP:
            return None
        rowmap = np.full(entries, -1, dtype=np.int32)
        rowmap[(at - lo) >> shift] = np.arange(self.rows)
        return lo, shift, rowmap

    def slots_of(self, rows: np.ndarray, pairs: Pairs) -> np.ndarray:
        """The slots in ``pairs`` of the pairs of rows (``rows``: (2, m), -1 where a body
        is not in the table, which raises :class:`UnknownBody`), new ones added: looked up
        in a dense map of rows for a small table (a row and a column of -1 past its end,
        which row -1 reads)."""
        ra, rb = rows[0], rows[1]
        if self.rows > self.DENSE:
            if rows.min() < 0:
                raise UnknownBody
            return self.pair_slots(ra, rb, pairs)
        if not hasattr(self, "_pairmap"):
            self._pairmap = np.full((self.rows + 1, self.rows + 1), -1, dtype=np.int32)
        # One flat take (row -1 wraps to the last row or column, all -1).
        slots = self._pairmap.ravel().take(ra * (self.rows + 1) + rb)
        if slots.min() < 0:
            if rows.min() < 0:
                raise UnknownBody
            new = slots < 0
            slots[new] = self.pair_slots(ra[new], rb[new], pairs)
            self._pairmap[ra[new], rb[new]] = slots[new]
        return slots

    def pair_slots(self, ra: np.ndarray, rb: np.ndarray, pairs: Pairs) -> np.ndarray:
        """The slots in ``pairs`` of the pairs of rows (ra, rb), new ones added."""
        ua, ub = self.uid[ra], self.uid[rb]
        return pairs.slots(np.minimum(ua, ub) * PAIR + np.maximum(ua, ub))


def spans(t: Any, dt: float) -> np.ndarray:
    """How long each row of the table ``t`` moves in a step of ``dt`` when no body sleeps:
    dt for the dynamic and kinematic rows, 0 for the others."""
    return _per_dt(t, "spans", dt, lambda: np.where(t.moves, dt, 0.0))


def gravity_dt(t: Any, g: tuple[float, float], dt: float) -> np.ndarray:
    """The velocity gravity gives in a step of ``dt``, (g.x dt, g.y dt, 0) as a column
    (the build's gravity ``g``: a new one makes a new table)."""
    return _per_dt(t, "gravity_dt", dt, lambda: np.array([[g[0] * dt], [g[1] * dt], [0.0]]))


def mass_dt(t: Any, dt: float) -> np.ndarray:
    """m dt of each dynamic row of the table ``t``."""
    return _per_dt(t, "mass_dt", dt, lambda: t.m * dt)


def _per_dt(t: Any, name: str, dt: float, make: Callable[[], np.ndarray]) -> np.ndarray:
    """An array of the table ``t`` that depends on dt only: made once for the last dt seen
    (a space steps at one dt, or at few), read-only."""
    got = t.by_dt.get(name)
    if got is None or got[0] != dt:
        value = make()
        value.flags.writeable = False
        got = t.by_dt[name] = (dt, value)
    return got[1]


class Pairs:
    """Running contact work, and gravity's part of the position correction, per pair of
    bodies (stable ids). A pair's slot is given when it first touches and never moves.

    ``keys``, ``work`` and ``push`` are the first slots of buffers that grow by doubling
    (pairs come a few at a time, step after step); the sorted keys a search needs are
    sorted again only when a search comes after pairs were added."""

    #: Most keys looked up one by one in a dict (more are searched for in the sorted keys).
    FEW = 32

    def __init__(self) -> None:
        self._bufs = (np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0))
        self.keys, self.work, self.push = self._bufs  # by slot
        self.sorted = np.zeros(0, dtype=np.int64)    # keys, sorted (when a search needs it)
        self.slot_of = np.zeros(0, dtype=np.int64)   # slot of each sorted key
        self.slot: dict[int, int] = {}               # key -> slot

    def lookup(self, keys: np.ndarray) -> np.ndarray:
        """The slots of ``keys`` (-1 where new)."""
        if len(keys) <= self.FEW:
            slot = self.slot
            return np.array([slot.get(k, -1) for k in keys.tolist()], dtype=np.int64)
        if not len(self.keys):
            return np.full(len(keys), -1, dtype=np.int64)
        if len(self.sorted) != len(self.keys):  # pairs added since the last search
            order = np.argsort(self.keys, kind="stable")
            self.sorted, self.slot_of = self.keys[order], order
        pos = np.minimum(np.searchsorted(self.sorted, keys), len(self.sorted) - 1)
        return np.where(self.sorted[pos] == keys, self.slot_of[pos], -1)

    def slots(self, keys: np.ndarray) -> np.ndarray:
        """The slots of ``keys``, adding the new ones (in the order of their keys)."""
        if len(keys) <= self.FEW:  # a few: in Python
            slot = self.slot
            listed = keys.tolist()
            fresh = sorted({k for k in listed if k not in slot})
            if fresh:
                self._add(fresh)
            return np.array([slot[k] for k in listed], dtype=np.int64)
        found = self.lookup(keys)
        if found.min(initial=0) >= 0:
            return found
        self._add(np.unique(keys[found < 0]).tolist())
        return self.lookup(keys)

    def _add(self, fresh: list[int]) -> None:
        """Give the new keys ``fresh`` (sorted) the next slots."""
        k, f = len(self.keys), len(fresh)
        if k + f > len(self._bufs[0]):
            cap = max(64, 2 * (k + f))
            grown = []
            for old in self._bufs:
                buf = np.zeros(cap, dtype=old.dtype)
                buf[:k] = old[:k]
                grown.append(buf)
            self._bufs = (grown[0], grown[1], grown[2])
        keys, work, push = self._bufs
        keys[k: k + f] = fresh
        self.slot.update(zip(fresh, range(k, k + f), strict=True))
        self.keys, self.work, self.push = keys[: k + f], work[: k + f], push[: k + f]


class Field(NamedTuple):
    """A declared potential on the dynamic rows ``idx``: ``potential(x, y, m)`` and its
    label."""

    idx: np.ndarray
    potential: Callable[..., Any]
    label: str


@dataclass(frozen=True, eq=False)
class Build:
    """What the space holds, as the ledger reads it until it changes: the table, the
    constraint groups (``springs`` those of springs), the declared fields, gravity, the
    dynamic rows' velocity and position function pointers, which velocity functions are
    custom and which have a declared field, the custom functions themselves, and what
    cannot be accounted for while this holds (``current``: label -> why)."""

    table: Table
    groups: dict[str, Group]
    springs: list[Group]
    fields: list[Field]
    gravity: tuple[float, float]
    vf: np.ndarray
    pf: np.ndarray
    custom: np.ndarray
    declared: np.ndarray
    vel_funcs: list[Any]
    current: dict[str, str]

    @cached_property
    def any_custom(self) -> bool:
        return bool(self.custom.any())

    @cached_property
    def plain(self) -> bool:
        """Only gravity, the contacts and the program act: no constraint, no custom
        velocity function, no declared field, every moment finite (with no force, no
        damping and every body awake, a step's sources are :func:`._physics.plain_step`)."""
        return not (self.groups or self.fields or self.any_custom) and self.table.all_finite

    @cached_property
    def funcs(self) -> np.ndarray:
        """The velocity and position function pointers (2, dynamic rows)."""
        return np.stack([self.vf, self.pf])

    @cached_property
    def funcs_bytes(self) -> bytes:
        return self.funcs.tobytes()


def build(space: Any, names: Names, potentials: list[tuple[Any, Callable[..., Any], str]]
          ) -> Build:
    """Read what ``space`` holds now (``potentials``: the declared ones, as (key, function,
    label), key ('func', f) or ('bodies', ids))."""
    current: dict[str, str] = {}
    t = Table(space, names)
    n = t.n
    labels = t.labels
    groups, springs = constraints.groups(t, current)
    ptrs = t.pre.pointers()
    vel_default, pos_default = layout.default_funcs()
    vf, pf = ptrs[1, :n].copy(), ptrs[2, :n].copy()
    custom = ~np.isin(vf, np.array(sorted(vel_default), dtype=np.uint64))
    custom_pos = ~np.isin(pf, np.array(sorted(pos_default), dtype=np.uint64))
    vel_funcs = [layout.body_function(t.bodies[i], "velocity_func") if custom[i] else None
                 for i in range(n)]
    fields: list[Field] = []
    declared = np.zeros(n, dtype=bool)
    for key, potential, label in potentials:
        if key[0] == "func":
            idx = [i for i in range(n) if vel_funcs[i] is key[1]]
        else:
            idx = [i for i in range(n) if id(t.bodies[i]) in key[1]]
        if idx:
            fields.append(Field(np.array(idx, dtype=np.int64), potential, label))
            declared[idx] = True
    for i in np.nonzero(custom & ~declared)[0]:
        current[labels[i]] = ("custom velocity_func and no declared potential "
                              "(declare_potential): its kicks are counted as work, the "
                              "energy of its field is not in E")
    for i in np.nonzero(custom_pos)[0]:
        current[labels[i]] = "custom position_func: its moves are not predicted"
    for i in np.nonzero(t.unsteppable)[0]:
        current[labels[i]] = (f"a dynamic body of mass {t.m[i]:g} and moment "
                              f"{float(t.pre.floats()[10, i]):g}: pymunk cannot step it (it "
                              "divides by both); spaces.energy refuses it")
    gravity = tuple(float(g) for g in space.gravity)
    return Build(t, groups, springs, fields, gravity, vf, pf, custom, declared, vel_funcs,
                 current)


def changed(b: Build, space: Any, F: np.ndarray, P: np.ndarray | None = None) -> str:
    """What changed in ``space`` since the build ``b`` ('' when nothing); ``F`` and ``P``
    the table's floats and pointers read now (``P`` None: the velocity and position
    functions are not looked at, as at the end of a step, which reads floats only)."""
    t = b.table
    came = came_or_went(t, space)
    if came:
        return came
    # The same bytes are the same values; other bytes may be too (-0 and +0): compared
    # as numbers then.
    if not (F[9:13].tobytes() == t.settings_bytes and F[13, t.n:].tobytes() == t.idle_bytes
            ) and not ((F[9:13] == t.settings).all() and (
                t.n == t.rows or (F[13, t.n:] == t.idle).all())):
        return "a mass, moment, centre of gravity or body type"
    if P is not None and P[1:3, : t.n].tobytes() != b.funcs_bytes and not (
            P[1:3, : t.n] == b.funcs).all():
        return "a velocity_func or position_func"
    return changed_settings(b, space)


def came_or_went(t: Any, space: Any) -> str:
    """Whether bodies or constraints were added to or removed from ``space`` since the
    table ``t`` was built ('' when neither)."""
    if not same_bodies(t, space):
        return "bodies added or removed"
    if tuple(space.constraints) != t.constraint_key:
        return "constraints added or removed"
    return ""


def same_bodies(t: Any, space: Any) -> bool:
    """``space.bodies`` holds the table's bodies (``body_key``). While no body sleeps, the
    space's C arrays of bodies read the same as when it last did (:class:`._memory.BodyArrays`,
    a table that has them) stand witness that it still does; else the bodies are compared."""
    arrays = getattr(t, "arrays", None)
    now = None if arrays is None else arrays.read(space)
    if now is not None and now == t.arrays_seen:
        return True
    if tuple(space.bodies) != t.body_key:
        return False
    t.arrays_seen = now
    return True


def changed_settings(b: Build, space: Any) -> str:
    """What changed since the build in gravity, the springs' settings and the custom
    velocity functions ('' when nothing)."""
    t = b.table
    cspace = getattr(space, "_space", None)  # a pymunk Space (or what one held)
    if cspace is not None:  # Chipmunk's getter, as pymunk's property calls it
        g = mem._lib().cpSpaceGetGravity(cspace)
        now = (g.x, g.y)
    else:
        now = tuple(space.gravity)
    if now != b.gravity:
        return "space.gravity"
    for g in b.springs:
        if g.changed():
            return f"a {g.kind.replace('_', ' ')}'s settings"
    if b.any_custom:
        bodies = t.bodies
        for i in np.nonzero(b.custom)[0]:
            if layout.body_function(bodies[i], "velocity_func") is not b.vel_funcs[i]:
                return "a velocity_func"
    return ""


def declared(target: Any, potential: Callable[..., Any], name: str | None, steps: int,
             names: Names) -> tuple[Any, str]:
    """The key and label of a potential to declare (``Ledger.declare_potential``), checked:
    ``target`` a body, bodies or a velocity function, ``name`` at most :data:`NAME_CHARS`
    printable characters, ``potential`` callable on numpy arrays with finite energies, and
    no step counted yet (``steps``); the bodies are kept in ``names``."""
    import pymunk

    from ..errors import UsageError
    from ..model import args

    args.function(potential, "potential", "a function potential(x, y, m) -> energy")
    if isinstance(target, pymunk.Body):
        target = [target]
    if callable(target):
        key: Any = ("func", target)
        label = name or f"field of {getattr(target, '__name__', 'a velocity_func')}"
    else:
        bodies = list(target) if isinstance(target, Iterable) and not isinstance(
            target, str | bytes) else []
        if not bodies or not all(isinstance(b, pymunk.Body) for b in bodies):
            raise UsageError(f"target = {args.show(target)}: must be a body, a list of "
                             "bodies or a velocity function", param="target")
        key = ("bodies", frozenset(id(b) for b in bodies))
        names.kept.extend(bodies)
        label = name or "declared field"
    label = args.text(label, "name")
    if not (0 < len(label) <= NAME_CHARS and label.isprintable()):
        raise UsageError(f"name = {args.show(label)}: must be 1 to {NAME_CHARS} printable "
                         "characters (no newline or other control character)",
                         param="name")
    if steps:
        raise UsageError(f"potential: declare it before the first step ({steps} "
                         "counted already; attach a new Ledger to declare it)",
                         param="potential")
    probe = np.array([1.0, 2.0])
    try:
        raw = potential(probe, probe + 1.0, probe)
        value = np.asarray(raw, dtype=float)
    except Exception as e:  # noqa: BLE001 - the user's function: any failure is theirs
        raise UsageError(f"potential: calling it with numpy arrays x, y, m failed "
                         f"({type(e).__name__}: {args.show(str(e))})",
                         param="potential") from None
    if value.shape not in ((2,), ()):
        raise UsageError(f"potential: returned shape {value.shape} for 2 bodies: must "
                         "return one energy per body", param="potential")
    if not np.all(np.isfinite(value)):
        raise UsageError(f"potential: returned {args.show(raw)} for bodies at x = [1, 2], "
                         "y = [2, 3]: must return finite energies", param="potential")
    return key, label
