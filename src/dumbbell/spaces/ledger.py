"""An energy ledger for any pymunk space: E(t) + heat + work_out - work_in = E(0), with
every term measured step by step and named by its source.

How a pymunk step moves energy (Munk2D's ``cpSpaceStep``): positions move first with the
velocities plus the contacts' bias velocities (``p += (v + v_bias) dt``); collisions are found;
each constraint is prepared (a ``DampedSpring`` or ``DampedRotarySpring`` applies its spring
impulse there); velocities are integrated (``v = v d + (g + f/m) dt`` with d =
``space.damping ** dt``, or the body's own ``velocity_func``); then the contacts' and joints'
impulses, the cached ones first, then ``iterations`` passes.

The ledger hooks into every step twice, with a hidden motor constraint that applies nothing,
put first in the space's C constraint list (it is not in ``space.constraints``, is not drawn,
copied or pickled): before the constraints are prepared (velocities v0, positions after the
move, applied forces) and after the solver (velocities v1, every impulse the step applied).
It reads bodies, joints and contacts in bulk from pymunk's C structs (:mod:`._memory`).

Every change of velocity in the step is an impulse (gravity's m g dt, damping's (d - 1) m v,
springs, joints, contacts, forces). Kinetic energy is quadratic and the velocity change is
linear in the impulses, so the change of kinetic energy over the step is exactly the sum over
sources of impulse . (u0 + u1) / 2, u the velocity the source acts on before and after, however
the solver ordered them. The position move changes the potentials (gravity, springs, declared
fields) by an amount computed from the positions. The terms:

- ``contact`` (one per pair of bodies): the work of its impulses; heat when negative
  (inelastic impacts, friction), energy put in when positive (a surface velocity, ...);
- ``correction``: the energy the contacts' position correction gives by pushing overlapping
  shapes apart (gravity's part per pair, the springs' and fields' part as one term);
- ``constraint``: the work of each joint's impulses on the bodies' relative motion: a stop
  or limit reached (``SlideJoint`` snapping taut, ``RotaryLimitJoint``, ``RatchetJoint``), a
  finite ``max_force`` slipping, ``max_bias``/``error_bias`` correcting a drift, a
  ``SimpleMotor`` driving; a rigid joint's share is the step's error and tends to 0 with dt;
- ``spring damping``: what a spring's damping takes out;
- ``kinematic``: what a kinematic body (or the fixed spin of a body of infinite moment) does
  through the joints and contacts it drives;
- ``damping``: what ``space.damping`` takes out; ``force``: the work of ``Body.force``;
- ``step error``: the integrator's own error on each conservative force (gravity, each
  spring, each declared field): what its kick added minus what its potential lost over the
  move. For gravity it is exactly 1/2 dt g . (P1 - P0) per step (P the momentum), so it
  adds up to 1/2 dt g . (P(t) - P(0)) at a fixed dt: bounded while the momentum is;
- ``velocity_func``: the kick of a custom velocity function and the move it causes; with a
  declared potential (:meth:`Ledger.declare_potential`) it is the field's step error,
  without one the body is named in ``unaccounted`` and ``complete`` is False;
- ``program``: what the program changed outside pymunk's step (velocities or positions set,
  impulses applied between steps, settings changed): measured, named per body, and
  ``complete`` is False; ``entered``/``left``: bodies added or removed, with their energy;
- ``unattributed``: an impulse inside the step that no source explains (a callback that
  applies one): named per body, ``complete`` is False; ``rounding``: what the sums round off.

``E`` counts the dynamic bodies as :func:`dumbbell.spaces.energy` does, plus the declared
fields' potential. ``closure`` = E(t) - E(0) - the sum of all terms is the ledger's own error
(rounding). ``complete`` is True only when nothing is named in ``unaccounted`` (the sources
above that say so, beyond ``tolerance`` times the energy ``scale``) and the closure is within
``tolerance`` of the scale: the largest of the kinetic energy and of the change of each
potential (gravity, springs, fields) from its start, over the steps seen. The potentials'
zero is arbitrary (pixel spaces put U_g near -1e8), so |E(0)| is no scale.
"""

from __future__ import annotations

import math
import warnings
import weakref
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from .._display import counted
from . import _memory as mem

__all__ = ["Balance", "Ledger", "Term"]

#: Kinds of terms that are heat (energy turned into heat, negative when energy leaves).
HEAT_KINDS = ("contact", "spring damping", "damping")


@dataclass(frozen=True)
class Term:
    """One source in the ledger: ``energy`` (J) it put into the bodies over the run (negative
    when it took energy out), its ``kind`` (see the module docstring) and a note."""

    source: str
    kind: str
    energy: float
    note: str = ""


@dataclass(frozen=True)
class Balance:
    """The ledger over a run: E(0) and E(t) (J, with the declared fields), the terms, and
    the check. ``E + heat + work_out - work_in = E0 + closure`` holds exactly; ``heat`` is
    what contacts, spring damping and ``space.damping`` dissipated, ``work_in`` and
    ``work_out`` the other terms' inputs and outputs (J). ``scale`` (J) is the largest
    kinetic energy and change of a potential seen; ``complete`` is True when the closure and
    anything unattributed stay within ``tolerance`` of it and every source is accounted for
    (``unaccounted`` names the others, with why)."""

    E0: float
    E: float
    terms: tuple[Term, ...]
    closure: float
    worst_step: float
    scale: float
    tolerance: float
    unaccounted: tuple[tuple[str, str], ...]
    steps: int
    t: float
    notes: tuple[str, ...] = ()

    @property
    def heat(self) -> float:
        """Energy dissipated (J): minus the heat-kind terms."""
        return -math.fsum(t.energy for t in self.terms if t.kind in HEAT_KINDS)

    @property
    def work_in(self) -> float:
        """Energy the other terms put in (J)."""
        return math.fsum(t.energy for t in self.terms
                         if t.kind not in HEAT_KINDS and t.energy > 0)

    @property
    def work_out(self) -> float:
        """Energy the other terms took out (J, positive)."""
        return -math.fsum(t.energy for t in self.terms
                          if t.kind not in HEAT_KINDS and t.energy < 0)

    @property
    def relative_closure(self) -> float:
        """|closure| / scale (0 when nothing moved)."""
        return abs(self.closure) / self.scale if self.scale > 0 else 0.0

    @property
    def complete(self) -> bool:
        """True when every joule is accounted for: nothing in ``unaccounted`` and the
        closure within ``tolerance`` of ``scale``."""
        return not self.unaccounted and abs(self.closure) <= self.tolerance * self.scale

    def by_kind(self) -> dict[str, float]:
        """Energy (J) per kind of term."""
        out: dict[str, float] = {}
        for t in self.terms:
            out[t.kind] = out.get(t.kind, 0.0) + t.energy
        return out

    def sources(self, kind: str | None = None, at_least: float = 0.0) -> list[Term]:
        """Terms (of ``kind``, all when None) with |energy| >= ``at_least`` (J), largest
        first."""
        from ..model import args

        at_least = args.real(at_least, "at_least", "J", lo=0.0)
        chosen = [t for t in self.terms if (kind is None or t.kind == kind)
                  and abs(t.energy) >= at_least]
        return sorted(chosen, key=lambda t: -abs(t.energy))

    def table(self, top: int = 4) -> str:
        """The ledger as text: totals per kind with the ``top`` largest sources of each,
        then the check."""
        from ..model import args

        top = args.whole(top, "top", "sources", lo=0)
        lines = [f"energy ledger over {counted(self.steps, 'step')}, t = {self.t:.6g}",
                 f"  E(0) = {self.E0:.9g}   E(t) = {self.E:.9g}   scale = {self.scale:.4g}"]
        for kind, total in sorted(self.by_kind().items(), key=lambda kv: -abs(kv[1])):
            terms = self.sources(kind)
            lines.append(f"  {kind:16s} {total:+.6g}  ({len(terms)} source"
                         f"{'' if len(terms) == 1 else 's'})")
            for t in terms[:top]:
                lines.append(f"      {t.source:40s} {t.energy:+.6g}")
        lines.append(f"  closure E(t) - E(0) - sum = {self.closure:+.3g} "
                     f"({self.relative_closure:.2e} of the scale; worst step "
                     f"{self.worst_step:.2e})")
        for note in self.notes:
            lines.append(f"  note: {note}")
        for source, why in self.unaccounted:
            lines.append(f"  unaccounted: {source}: {why}")
        lines.append(f"  complete: {self.complete}")
        return "\n".join(lines)


# --------------------------------------------------------------------------------------
# Reading structs in bulk, at fixed addresses, through precomputed indices.

#: Body fields read before the solver: position (x, y, angle), velocity (vx, vy, w),
#: force (fx, fy, torque), settings (mass, moment, centre of gravity).
_PRE = ("p.x", "p.y", "a", "v.x", "v.y", "w", "f.x", "f.y", "t", "m", "i", "cog.x", "cog.y")
#: ... after it: velocity, and the bias velocity the next move adds.
_POST = ("v.x", "v.y", "w", "v_bias.x", "v_bias.y", "w_bias")
_PTRS = ("root", "velocity_func", "position_func")
#: Per constraint struct: fields read before the solver (the impulse carried in; a spring's
#: settings), and after it (the impulse, its geometry).
_BEFORE = {"pin": ("j",), "slide": ("j",), "pivot": ("j.x", "j.y"), "groove": ("j.x", "j.y"),
           "spring": ("rest", "stiffness", "damping", "c.max_force"),
           "rotary_spring": ("rest", "stiffness", "damping", "c.max_force"),
           "rotary_limit": ("j",), "ratchet": ("j",), "gear": ("j",), "motor": ("j",)}
_AFTER = {"pin": ("j", "n.x", "n.y", "r1.x", "r1.y", "r2.x", "r2.y"),
          "slide": ("j", "n.x", "n.y", "r1.x", "r1.y", "r2.x", "r2.y"),
          "pivot": ("j.x", "j.y", "r1.x", "r1.y", "r2.x", "r2.y"),
          "groove": ("j.x", "j.y", "r1.x", "r1.y", "r2.x", "r2.y"),
          "spring": ("j", "n.x", "n.y", "r1.x", "r1.y", "r2.x", "r2.y"),
          "rotary_spring": ("j",), "rotary_limit": ("j", "bias"), "ratchet": ("j", "bias"),
          "gear": ("j", "ratio_inv"), "motor": ("j",)}


def _offset(kind: str, path: str) -> int:
    return mem.offset(kind, *path.split("."))


class _Reader:
    """Fields of structs of one kind at fixed addresses, read in one numpy gather each:
    ``floats()`` (fields, structs) float64, ``pointers()`` (fields, structs) uint64."""

    def __init__(self, kind: str, at: np.ndarray, floats: tuple[str, ...],
                 ptrs: tuple[str, ...] = ()) -> None:
        self.span = mem.Span.over(at, mem.size(kind))
        self.fi = self.pi = None
        if self.span is None:
            return
        rel = at - np.uint64(self.span.lo)
        if floats:
            self.fi = np.stack([(rel + np.uint64(_offset(kind, f))) >> np.uint64(3)
                                for f in floats])
        if ptrs:
            self.pi = np.stack([(rel + np.uint64(_offset(kind, f))) >> np.uint64(3)
                                for f in ptrs])

    def floats(self) -> np.ndarray:
        return self.span.f64[self.fi]

    def pointers(self) -> np.ndarray:
        return self.span.u64[self.pi]


class _Members(NamedTuple):
    """The constraints of one struct kind as the build lists them: the objects, their
    labels, the table rows of their two bodies, and whether each (a spring) has pymunk's
    own force."""

    objs: list[Any]
    labels: list[str]
    a: list[int]
    b: list[int]
    default: list[bool]


class _Group:
    """The constraints of one struct kind: rows of their two bodies in the table, readers,
    and running sums (J) per constraint: ``work`` (work of its impulses on the relative
    motion; for a spring, its elastic part), ``extra`` (a spring's damping part), ``pot``
    (a spring's potential change over the steps' moves), ``kin_a``/``kin_b`` (work of a
    driven end through it)."""

    def __init__(self, kind: str, members: _Members) -> None:
        objs = members.objs
        self.kind = kind
        self.objs = objs
        self.labels = members.labels
        self.at = np.array([mem.address(c._constraint) for c in objs], dtype=np.uint64)
        self.a = np.array(members.a, dtype=np.int64)
        self.b = np.array(members.b, dtype=np.int64)
        self.default = np.array(members.default, dtype=bool)
        self.spring = kind in ("spring", "rotary_spring")
        self.slot = -1  # place among the space's spring groups
        func = {"spring": ("force_func",), "rotary_spring": ("torque_func",)}.get(kind, ())
        self.before = _Reader(kind, self.at, _BEFORE[kind], func)
        self.after = _Reader(kind, self.at, _AFTER[kind])
        z = np.zeros(len(objs))
        self.work, self.extra, self.pot, self.kin_a, self.kin_b = (z.copy() for _ in range(5))
        self.settings = self.before.floats().copy() if self.spring else None
        self.funcs = self.before.pointers().copy() if self.spring else None
        if kind == "spring":
            self.anchor = np.array(
                [[c.anchor_a[0] - c.a.center_of_gravity[0],
                  c.anchor_a[1] - c.a.center_of_gravity[1],
                  c.anchor_b[0] - c.b.center_of_gravity[0],
                  c.anchor_b[1] - c.b.center_of_gravity[1]] for c in objs],
                dtype=float).reshape(len(objs), 4)

    def changed(self) -> bool:
        """A spring's settings or force function changed since the build."""
        return self.spring and not (np.array_equal(self.before.floats(), self.settings)
                                    and np.array_equal(self.before.pointers(), self.funcs))


class _Table:
    """The bodies the ledger reads at every hook: dynamic rows [0, n), kinematic rows
    [n, n + k) (in the space, moved by its steps), then the other bodies constraints and
    contacts touch: static ones, and bodies a constraint joins that are not in the space
    (they do not move with it; what they take is work leaving the system)."""

    def __init__(self, ledger: Ledger) -> None:
        import pymunk

        space = ledger.space
        bodies = list(space.bodies)
        dyn = [b for b in bodies if b.body_type == pymunk.Body.DYNAMIC]
        kin = [b for b in bodies if b.body_type == pymunk.Body.KINEMATIC]
        other = [space.static_body] + [b for b in bodies if b.body_type ==
                                       pymunk.Body.STATIC and b is not space.static_body]
        seen = {id(b) for b in [*dyn, *kin, *other]}
        self.constraint_key = tuple(space.constraints)
        for c in self.constraint_key:
            for b in (c.a, c.b):
                if id(b) not in seen:
                    seen.add(id(b))
                    other.append(b)
        self.bodies = [*dyn, *kin, *other]
        self.body_key = tuple(bodies)
        n, k = len(dyn), len(kin)
        self.n, self.k, self.rows = n, k, len(self.bodies)
        self.uid = np.array([ledger._uid(b) for b in self.bodies], dtype=np.int64)
        self.at = np.array([mem.address(b._body) for b in self.bodies], dtype=np.uint64)
        self.pre = _Reader("body", self.at, _PRE, _PTRS)
        self.post = _Reader("body", self.at, _POST, ("root",))
        first = self.pre.floats()
        self.settings = first[9:13].copy()
        self.m = first[9, :n].copy()
        moment = first[10, :n]
        self.finite = np.isfinite(moment)
        self.all_finite = bool(self.finite.all())
        self.I = np.where(self.finite, moment, 0.0)
        self.mass3 = np.stack([self.m, self.m, self.I])
        self.inv3 = np.stack([1.0 / self.m, 1.0 / self.m,
                              np.where(self.finite, 1.0 / np.where(self.finite, moment, 1.0),
                                       0.0)])
        self.lin_free = np.zeros(self.rows, dtype=bool)
        self.lin_free[:n] = True
        self.ang_free = np.zeros(self.rows, dtype=bool)
        self.ang_free[:n] = self.finite
        self.moves = np.zeros(self.rows, dtype=bool)
        self.moves[: n + k] = True
        # Rows whose motion is imposed and not counted in E: kinematic bodies and bodies
        # outside the space (linear and angular), the spin of a body of infinite moment.
        self.drives = np.zeros(self.rows, dtype=bool)
        self.drives[n: n + k] = True
        self.drives[:n] = ~self.finite
        for r in range(n + k, self.rows):
            self.drives[r] = self.bodies[r] is not space.static_body and \
                self.bodies[r].body_type != pymunk.Body.STATIC
        order = np.argsort(self.at)
        self.order, self.sorted_at = order, self.at[order]
        self.sorted_i64 = self.sorted_at.view(np.int64)

    def pair_slots(self, ra: np.ndarray, rb: np.ndarray, pairs: _Pairs) -> np.ndarray:
        """The slots in ``pairs`` of the pairs of rows (ra, rb), new ones added."""
        ua, ub = self.uid[ra], self.uid[rb]
        return pairs.slots(np.minimum(ua, ub) * _PAIR + np.maximum(ua, ub))


class _Pairs:
    """Running contact work, and gravity's part of the position correction, per pair of
    bodies (stable ids). A pair's slot is given when it first touches and never moves."""

    def __init__(self) -> None:
        self.keys = np.zeros(0, dtype=np.int64)      # by slot
        self.sorted = np.zeros(0, dtype=np.int64)    # keys, sorted
        self.slot_of = np.zeros(0, dtype=np.int64)   # slot of each sorted key
        self.work = np.zeros(0)
        self.push = np.zeros(0)

    def slots(self, keys: np.ndarray) -> np.ndarray:
        """The slots of ``keys``, adding the new ones."""
        if len(self.sorted):
            pos = np.minimum(np.searchsorted(self.sorted, keys), len(self.sorted) - 1)
            hit = self.sorted[pos] == keys
            if np.all(hit):
                return self.slot_of[pos]
            fresh = np.unique(keys[~hit])
        else:
            fresh = np.unique(keys)
        start = len(self.keys)
        self.keys = np.concatenate([self.keys, fresh])
        self.work = np.concatenate([self.work, np.zeros(len(fresh))])
        self.push = np.concatenate([self.push, np.zeros(len(fresh))])
        order = np.argsort(self.keys, kind="stable")
        self.sorted, self.slot_of = self.keys[order], order
        del start
        return self.slot_of[np.searchsorted(self.sorted, keys)]

    def terms(self, labels: list[str]) -> list[Term]:
        out = []
        for key, w, p in zip(self.keys.tolist(), self.work.tolist(), self.push.tolist(),
                             strict=True):
            a, b = divmod(key, _PAIR)
            name = f"{labels[a]} / {labels[b]}"
            if w != 0.0:
                out.append(Term(f"contact {name}", "contact", w,
                                "work of the contact impulses (heat when negative)"))
            if p != 0.0:
                out.append(Term(f"pushed apart {name}", "correction", p,
                                "gravity's part of the contacts' position correction"))
        return out


_PAIR = 1 << 31


class _NoSpan:
    """Stands for a span not made yet: covers nothing."""

    f64 = np.zeros(1)
    lo = 0
    u8 = b""


_NO_SPAN = _NoSpan()


class _Contacts:
    """The contacts the solver uses in a step, read from pymunk's arbiters (at most two
    contacts each) by two compiled loops (:mod:`._kernels`): before the solver, the bodies'
    rows, the normals and the impulses carried in; after it, each contact's work."""

    def __init__(self, space_at: int) -> None:
        from pymunk._chipmunk_cffi import ffi as pffi

        self.arr = mem.ffi().cast("array *", mem.view("space", space_at).arbiters)
        self.o = {name: pffi.offsetof("cpArbiter", name) for name in
                  ("contacts", "body_a", "body_b", "count", "state", "n")}
        self.c = {name: pffi.offsetof("cpContact", name) for name in
                  ("jnAcc", "jtAcc", "jBias", "r1", "r2")}
        self.asize = pffi.sizeof("cpArbiter")
        self.csize = pffi.sizeof("cpContact")
        self.span: mem.Span | None = None
        self.cspan: mem.Span | None = None

    @staticmethod
    def _span(span: mem.Span | None, lo: int, hi: int) -> mem.Span:
        if span is None or lo < span.lo or hi > span.lo + len(span.u8):
            span = mem.Span(lo, hi)
        return span

    def before(self, table: _Table, pairs: _Pairs, coef: float) -> bool:
        """Read the step's contacts and the impulses they carry in; False if none."""
        from . import _kernels

        num = int(self.arr.num)
        if num == 0:
            return False
        arb = np.frombuffer(mem.ffi().buffer(self.arr.arr, 8 * num), dtype=np.int64)
        span = self.span = self._span(self.span, int(arb.min()), int(arb.max()) + self.asize)
        o = self.o
        rows = np.empty((2, num), dtype=np.int64)
        n = np.empty((2, num))
        first = np.empty(num, dtype=np.bool_)
        at = np.empty((2, num), dtype=np.int64)
        weight = np.empty((2, num))
        slots = np.empty(num, dtype=np.int64)
        sign = np.empty(num)
        j0 = np.zeros((2, 2, num))
        c = self.cspan or _NO_SPAN
        low, high, any_first, missing = _kernels.arbiters()(
            arb, span.i64, span.u32, span.f64, span.lo, o["contacts"], o["body_a"],
            o["body_b"], o["count"], o["state"], o["n"], self.csize, table.sorted_i64,
            table.order, table.uid, pairs.sorted, pairs.slot_of, table.lin_free, rows, n,
            first, at, weight, slots, sign, c.f64, c.lo, c.lo + len(c.u8), self.c["jnAcc"],
            self.c["jtAcc"], coef, j0)
        if high == 0:
            return False
        ra, rb = rows
        if ra.min() < 0 or rb.min() < 0:
            raise RuntimeError("a contact touches a body the ledger does not know")
        if slots.min() < 0:
            slots = table.pair_slots(ra, rb, pairs)
        if self.cspan is None or low < self.cspan.lo or high + self.csize > c.lo + len(c.u8):
            # The contact buffers the space cycles through: one span over all seen so far.
            lo = int(low) if self.cspan is None else min(int(low), self.cspan.lo)
            hi = int(high) + self.csize
            if self.cspan is not None:
                hi = max(hi, self.cspan.lo + len(self.cspan.u8))
            self.cspan = mem.Span(lo, hi)
        if missing:
            cs = self.cspan
            safe = np.where(at == 0, low, at) - cs.lo
            read = np.stack([cs.f64[(safe + self.c["jnAcc"]) >> 3],
                             cs.f64[(safe + self.c["jtAcc"]) >> 3]])
            carried = (first | (coef != 1.0))[None, None, :]
            j0 = np.where(carried, read, j0)
        self.at, self.n, self.first, self.ra, self.rb = at, n, first, ra, rb
        self.weight, self.slots, self.sign = weight, slots, sign
        self.has_j0 = coef != 1.0 or any_first
        self.j0 = j0
        return True

    def work(self, step: _Step, table: _Table, pairs: _Pairs, drive: np.ndarray
             ) -> tuple[float, np.ndarray]:
        """Work (J) of the step's contact impulses (see :func:`._kernels.contacts`), and the
        bias impulse of each arbiter on its dynamic ends."""
        from . import _kernels

        coef, u, imp = step.coef, step.u, step.imp
        c = self.c
        push = np.empty(len(self.ra))
        total = _kernels.contacts()(
            self.at, self.weight, self.cspan.f64, self.cspan.lo, c["jnAcc"], c["jtAcc"],
            c["jBias"], c["r1"], c["r2"], self.j0, self.has_j0, self.first, coef, self.n,
            self.ra, self.rb, u, table.lin_free, table.ang_free, self.slots, imp,
            pairs.work, drive, push, self.sign)
        return float(total), push


def _cross(rx: Any, ry: Any, px: Any, py: Any) -> Any:
    return rx * py - ry * px


def _scatter(rows: np.ndarray, values: np.ndarray, size: int) -> np.ndarray:
    return np.bincount(rows, weights=values, minlength=size)


def _same(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Equal but for a few roundings (a compiler may fuse pymunk's multiply and add)."""
    return np.abs(x - y) <= 8.0 * np.finfo(float).eps * (np.abs(x) + np.abs(y)) + 1e-300


# --------------------------------------------------------------------------------------
# The ledger.


class Ledger:
    """Attach an energy ledger to ``space``: every later ``space.step`` (whoever calls it)
    is counted while the ledger is referenced (dropping it detaches it), and
    :meth:`balance` gives the account so far.

    ``tolerance`` (relative to the energy scale) is what ``complete`` allows for the closure
    and for anything unattributed or changed by the program. See the module docstring for
    the terms. A copy or a pickle of the space carries no ledger: attach a new one."""

    def __init__(self, space: Any, tolerance: float = 1e-6) -> None:
        from ..errors import DumbbellError, UsageError
        from ..model import args

        self.space = args.space(space)
        self.tolerance = args.real(tolerance, "tolerance", "-")
        if getattr(space, "_locked", False):
            raise UsageError("space: attach the ledger between steps, not from a callback",
                             param="space")
        from .accounting import check_finite, energy

        check_finite(space)
        energy(space)  # refuses settings that are not finite and energies past the floats
        if not mem.readable():
            import pymunk

            raise DumbbellError(f"the ledger cannot read this pymunk build (pymunk "
                                f"{pymunk.version}): its structs are not laid out as in pymunk "
                                "7.3's Munk2D")
        try:
            mem.check_space(space)
            for b in space.bodies:
                mem.check_body(b)
            for c in space.constraints:
                if mem.struct_of(c) is not None:
                    mem.check_constraint(c)
        except mem.LayoutError as e:
            import pymunk

            raise DumbbellError(f"the ledger cannot read this pymunk build (pymunk "
                                f"{pymunk.version}): {e}") from None
        self._space_at = mem.address(space._space)
        self._uids: dict[int, int] = {}
        self._labels: list[str] = []
        self._kept: list[Any] = []
        # Bodies are named as spaces.energy names them when the ledger attaches ('body i',
        # i their place in space.bodies); bodies that come later take the next numbers.
        self._places = {id(b): i for i, b in enumerate(space.bodies)}
        self._next = len(self._places)
        self._potentials: list[tuple[Any, Callable[..., Any], str]] = []
        self._terms: dict[tuple[str, str], float] = {}
        self._notes: dict[tuple[str, str], str] = {}
        self._unaccounted: dict[str, str] = {}
        self._pairs = _Pairs()
        self._contacts = _Contacts(mem.address(space._space))
        self.steps = 0
        self.t = 0.0
        self._worst = 0.0
        self._error: str | None = None
        self._pending: dict[str, Any] | None = None
        self._push: tuple[np.ndarray, np.ndarray] | None = None
        self._dt_prev = float(mem.view("space", self._space_at).dt)
        self._build()
        self._snap = self._read_snapshot()
        e = self._energy(self._snap)
        self._E0 = self._E = e["E"]
        self._Uref = np.array([e["Ug"], e["Us"], e["Ud"]])
        self._scale = e["K"]
        self._sentinel: Any = None
        self._install()

    # -- public ------------------------------------------------------------------------

    @property
    def attached(self) -> bool:
        """True while the ledger is counting."""
        return self._sentinel is not None

    def detach(self) -> None:
        """Stop counting and take the hook out of the space: its constraints are back in
        the order they had. :meth:`balance` keeps the account up to here."""
        if self._sentinel is None:
            return
        from pymunk._chipmunk_cffi import lib

        self._sync()
        _rotate(self._space_at, self._sentinel, first=False)
        lib.cpSpaceRemoveConstraint(self.space._space, self._sentinel._constraint)
        self._sentinel.pre_solve = None
        self._sentinel.post_solve = None
        self._sentinel = None

    def __del__(self) -> None:
        # Dropped while attached: take the hook out, keeping the constraints' order.
        try:
            if self.__dict__.get("_sentinel") is not None:
                self.detach()
        except Exception:  # noqa: BLE001, S110 - never raise from a finalizer
            pass

    def declare_potential(self, target: Any, potential: Callable[..., Any],
                          name: str | None = None) -> None:
        """Declare the potential of a field that a custom ``velocity_func`` applies.

        ``target``: a body, a list of bodies, or a velocity function (every body that uses
        it, bodies added later included). ``potential(x, y, m)`` returns the field's
        potential energy (J) of bodies of mass ``m`` (kg) whose centres of gravity are at
        ``x``, ``y`` (m). It is called with numpy arrays: write it with numpy, e.g.
        ``lambda x, y, m: -GM * m / np.hypot(x - 300, y - 300)``. Declare it before the
        first step the ledger counts: the field's energy joins E from E(0) on, and each
        step's kicks count as the field's step error instead of unaccounted work. ``name``
        labels its term."""
        import pymunk

        from ..errors import UsageError
        from ..model import args

        args.function(potential, "potential", "a function potential(x, y, m) -> J")
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
            self._kept.extend(bodies)
            label = name or "declared field"
        label = args.text(label, "name")
        if self.steps:
            raise UsageError(f"potential: declare it before the first step ({self.steps} "
                             "counted already; attach a new Ledger to declare it)",
                             param="potential")
        probe = np.array([1.0, 2.0])
        try:
            value = np.asarray(potential(probe, probe + 1.0, probe), dtype=float)
        except Exception as e:  # noqa: BLE001 - the user's function: any failure is theirs
            raise UsageError(f"potential: calling it with numpy arrays x, y, m failed "
                             f"({type(e).__name__}: {args.show(str(e))})",
                             param="potential") from None
        if value.shape not in ((2,), ()):
            raise UsageError(f"potential: returned shape {value.shape} for 2 bodies: must "
                             "return one energy per body", param="potential")
        self._sync()
        self._fold()
        self._potentials.append((key, potential, label))
        self._build()
        self._snap = self._remap(self._snap)
        after = self._energy(self._snap)
        self._E0 += after["E"] - self._E
        self._Uref[2] = after["Ud"]
        self._E = after["E"]

    def __repr__(self) -> str:
        # What the ledger holds already: no accounting is run to show it.
        state = "attached" if self.attached else "detached"
        return (f"Ledger({state}, steps={self.steps}, t={self.t:.6g} s, "
                f"E0={self._E0:.6g}, E={self._E:.6g}; balance() for the terms)")

    def balance(self) -> Balance:
        """The account from attaching until now (what the program changed since the last
        step counts as ``program``). Raises a :class:`~dumbbell.errors.DumbbellError` naming
        the body once the space's state stopped being finite."""
        if self._bad is not None:
            from ..errors import DumbbellError

            raise DumbbellError(self._bad)
        self._sync()
        self._fold()
        terms = [Term(src, kind, val, self._notes.get((src, kind), ""))
                 for (src, kind), val in self._terms.items() if val != 0.0]
        terms += self._pairs.terms(self._labels)
        total = math.fsum(t.energy for t in terms)
        unacc = {**self._unaccounted, **self._current}
        if self._error is not None:
            unacc["ledger"] = self._error
        limit = self.tolerance * self._scale
        for t in terms:
            if t.kind == "unattributed" and abs(t.energy) > limit:
                unacc.setdefault(t.source, "an impulse inside the step that no source "
                                 "explains (a callback that applies one?)")
            elif t.kind == "program" and abs(t.energy) > limit:
                unacc.setdefault(t.source, "changed by the program outside pymunk's step "
                                 "(a velocity, position, impulse or setting)")
        return Balance(E0=self._E0, E=self._E, terms=tuple(sorted(terms, key=_order)),
                       closure=self._E - self._E0 - total, worst_step=self._worst,
                       scale=self._scale, tolerance=self.tolerance,
                       unaccounted=tuple(sorted(unacc.items())), steps=self.steps, t=self.t,
                       notes=_notes(terms, self._scale))

    # -- the hook ----------------------------------------------------------------------

    def _install(self) -> None:
        import pymunk
        from pymunk._chipmunk_cffi import lib

        space = self.space
        self._private = pymunk.Body(1.0, 1.0)
        s = pymunk.SimpleMotor(space.static_body, self._private, 0.0)
        s.max_force = 0.0
        # Hidden from Python: not in space.constraints, nor in the bodies' lists.
        space.static_body._constraints.pop(s, None)
        self._private._constraints.pop(s, None)
        # The hook holds the ledger weakly and the space does not hold it: the user's
        # reference keeps the ledger (and so the hook), and dropping it takes the hook out
        # (__del__), with no cycle left through the space.
        me = weakref.ref(self)
        s.pre_solve = _Hook(me, "_before_solver")
        s.post_solve = _Hook(me, "_after_solver")
        self._sentinel = s
        lib.cpSpaceAddConstraint(space._space, s._constraint)
        _rotate(self._space_at, s, first=True)

    def _before_solver(self, constraint: Any, space: Any) -> None:
        if self._error is None:
            try:
                with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
                    self._pre()
            except Exception as e:  # noqa: BLE001 - never break the user's step
                self._fail(e)

    def _after_solver(self, constraint: Any, space: Any) -> None:
        if self._error is None and self._pending is not None:
            try:
                with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
                    self._post()
            except Exception as e:  # noqa: BLE001 - never break the user's step
                self._fail(e)
        self._pending = None

    def _blown(self, snap: dict[str, Any]) -> None:
        """The state stopped being finite: stop counting, naming the body and the step."""
        from ..model import args

        t = self._t
        for name, rows in (("velocity", (0, 1)), ("angular_velocity", (2,)),
                           ("position", (0, 1)), ("angle", (2,))):
            block = snap["pos" if name in ("position", "angle") else "vel"]
            bad = ~np.all(np.isfinite(block[list(rows), : t.n]), axis=0)
            if bad.any():
                i = int(np.argmax(bad))
                value = tuple(float(block[r, i]) for r in rows)
                shown = value[0] if len(value) == 1 else value
                self._bad = (f"{self._row_labels[i]}: {name} = {args.show(shown)} after step "
                             f"{self.steps + 1}: the ledger stopped counting there")
                break
        else:
            self._bad = f"the energy stopped being finite after step {self.steps + 1}"
        self._error = self._bad
        self._pending = None

    _bad: str | None = None

    def _fail(self, e: Exception) -> None:
        self._pending = None
        self._error = f"stopped counting at step {self.steps}: {type(e).__name__}: {e}"
        warnings.warn(f"dumbbell.spaces.Ledger {self._error}", RuntimeWarning, stacklevel=2)

    # -- what is in the space ----------------------------------------------------------

    def _uid(self, body: Any) -> int:
        """The stable id of ``body`` in the ledger (its label is ``self._labels[uid]``)."""
        import pymunk

        uid = self._uids.get(id(body))
        if uid is None:
            if body is self.space.static_body:
                label = "static body"
            else:
                place = self._places.pop(id(body), None)
                if place is None:
                    place = self._next
                    self._next += 1
                kind = {pymunk.Body.KINEMATIC: "kinematic body ",
                        pymunk.Body.STATIC: "static body "}.get(body.body_type, "body ")
                outside = "" if body.space is self.space else " (not in the space)"
                label = f"{kind}{place}{outside}"
            uid = len(self._labels)
            self._uids[id(body)] = uid
            self._labels.append(label)
            self._kept.append(body)  # keeps id() unique while the ledger lives
        return uid

    def _build(self) -> None:
        """(Re)read what the space holds: bodies, constraints, springs, fields. What could
        not be accounted for while steps were taken stays named."""
        if self.steps > self.__dict__.get("_built_at", -1):
            self._unaccounted.update(self.__dict__.get("_current", {}))
        self._built_at = self.steps
        self._current: dict[str, str] = {}
        t = self._t = _Table(self)
        n = t.n
        labels = self._row_labels = [self._labels[u] for u in t.uid]
        self._build_groups(t)
        custom_pos = self._build_funcs(t)
        self._build_fields(t)
        for i in np.nonzero(self._custom & ~self._declared)[0]:
            self._current[labels[i]] = ("custom velocity_func and no declared potential "
                                            "(declare_potential): its kicks are counted as "
                                            "work, the energy of its field is not in E")
        for i in np.nonzero(custom_pos)[0]:
            self._current[labels[i]] = "custom position_func: its moves are not predicted"
        sp = mem.view("space", self._space_at)
        self._gravity = (float(sp.gravity.x), float(sp.gravity.y))
        z = np.zeros(n)
        self._acc = {name: z.copy() for name in ("force", "vf", "unattributed", "program")}
        self._acc_kin = np.zeros(t.rows)
        self._acc_field = np.zeros(len(self._fields))
        self._push = None

    def _build_groups(self, t: _Table) -> None:
        """The constraints by struct kind (:class:`_Group`), the springs among them, and
        the constraints the ledger cannot read or whose energy is not in E, named."""
        rows = {int(a): r for r, a in enumerate(t.at)}
        by_kind: dict[str, tuple[list[Any], ...]] = {}
        for i, c in enumerate(t.constraint_key):
            name = type(c).__name__
            kind = mem.struct_of(c)
            clabel = f"{name} {i}"
            if kind is None:
                self._current[clabel] = f"{name}: a constraint class the ledger cannot read"
                continue
            mem.check_constraint(c)
            default = True
            if kind in ("spring", "rotary_spring"):
                default = (c._torque_func if kind == "rotary_spring" else c._force_func) is None
                if not default:
                    self._current[clabel] = ("custom force function: its potential is not "
                                                 "in E (its work is counted)")
            entry = by_kind.setdefault(kind, ([], [], [], [], []))
            for lst, value in zip(entry, (c, clabel, rows[mem.address(c.a._body)],
                                          rows[mem.address(c.b._body)], default), strict=True):
                lst.append(value)
        self._groups = {kind: _Group(kind, _Members(*entry)) for kind, entry in by_kind.items()}
        self._springs = [g for g in self._groups.values() if g.spring]
        for slot, g in enumerate(self._springs):
            g.slot = slot

    def _build_funcs(self, t: _Table) -> np.ndarray:
        """The dynamic bodies' velocity and position functions, which of them are custom;
        returns where the position function is."""
        n = t.n
        ptrs = t.pre.pointers()
        vel_default, pos_default = mem.default_funcs()
        self._vf, self._pf = ptrs[1, :n].copy(), ptrs[2, :n].copy()
        self._custom = ~np.isin(self._vf, np.array(sorted(vel_default), dtype=np.uint64))
        self._any_custom = bool(np.any(self._custom))
        self._vel_funcs = [t.bodies[i]._velocity_func if self._custom[i] else None
                           for i in range(n)]
        return ~np.isin(self._pf, np.array(sorted(pos_default), dtype=np.uint64))

    def _build_fields(self, t: _Table) -> None:
        """The declared fields on the bodies they now apply to, and which bodies have one."""
        n = t.n
        self._fields: list[tuple[np.ndarray, Callable[..., Any], str]] = []
        declared = np.zeros(n, dtype=bool)
        for key, potential, lab in self._potentials:
            if key[0] == "func":
                idx = [i for i in range(n) if self._vel_funcs[i] is key[1]]
            else:
                idx = [i for i in range(n) if id(t.bodies[i]) in key[1]]
            if idx:
                self._fields.append((np.array(idx, dtype=np.int64), potential, lab))
                declared[idx] = True
        self._declared = declared

    def _changed(self, F: np.ndarray, P: np.ndarray) -> str:
        """What changed in the space since the last build ('' when nothing)."""
        t = self._t
        space = self.space
        if tuple(space._bodies) != t.body_key:
            return "bodies added or removed"
        if tuple(space._constraints) != t.constraint_key:
            return "constraints added or removed"
        if not np.array_equal(F[9:13], t.settings):
            return "a mass, moment, centre of gravity or body type"
        if not (np.array_equal(P[1, : t.n], self._vf) and np.array_equal(P[2, : t.n],
                                                                        self._pf)):
            return "a velocity_func or position_func"
        return self._changed_settings()

    def _changed_settings(self) -> str:
        """What changed since the last build in the space's gravity, the springs' settings
        and the custom velocity functions ('' when nothing)."""
        sp = mem.view("space", self._space_at)
        if (sp.gravity.x, sp.gravity.y) != self._gravity:
            return "space.gravity"
        for g in self._springs:
            if g.changed():
                return f"a {g.kind.replace('_', ' ')}'s settings"
        if self._any_custom:
            bodies = self._t.bodies
            for i in np.nonzero(self._custom)[0]:
                if bodies[i]._velocity_func is not self._vel_funcs[i]:
                    return "a velocity_func"
        return ""

    # -- state and energy --------------------------------------------------------------

    def _read_snapshot(self) -> dict[str, Any]:
        """The state of the table's bodies now, between steps."""
        t = self._t
        F = t.pre.floats()
        Q = t.post.floats()
        bias = Q[3:6].copy()
        bias[:, t.n:] = 0.0
        sleeping = t.post.pointers()[0, : t.n] != 0
        snap = {"pos": F[0:3].copy(), "vel": F[3:6].copy(), "bias": bias,
                "sleeping": sleeping}
        return self._potentials_at(snap)

    def _potentials_at(self, snap: dict[str, Any]) -> dict[str, Any]:
        snap["asleep"] = bool(snap["sleeping"].any())
        snap["biased"] = bool(snap["bias"].any())
        snap["us"] = self._spring_energy(snap["pos"])
        snap["ud"] = self._field_energy(snap["pos"])
        return snap

    def _remap(self, snap: dict[str, Any]) -> dict[str, Any]:
        """``snap`` (taken on the previous table) on the present one: bodies in both keep
        their values, new ones get their present state."""
        t = self._t
        now = self._read_snapshot()
        old = {int(u): r for r, u in enumerate(self._snap_uid)}
        src = np.array([old.get(int(u), -1) for u in t.uid], dtype=np.int64)
        have = src >= 0
        for key in ("pos", "vel", "bias"):
            now[key][:, have] = snap[key][:, src[have]]
        n_old = len(snap["sleeping"])
        keep = have[: t.n] & (src[: t.n] < n_old)
        now["sleeping"][keep] = snap["sleeping"][src[: t.n][keep]]
        self._snap_uid = t.uid.copy()
        return self._potentials_at(now)

    _snap_uid: np.ndarray = np.zeros(0, dtype=np.int64)

    def _spring_energy(self, pos: np.ndarray) -> list[np.ndarray]:
        """Potential (J) of each default spring, per group, at positions ``pos``."""
        out = []
        for g in self._springs:
            rest, k = g.settings[0], g.settings[1]
            a, b = g.a, g.b
            if g.kind == "spring":
                ca, sa = np.cos(pos[2, a]), np.sin(pos[2, a])
                cb, sb = np.cos(pos[2, b]), np.sin(pos[2, b])
                an = g.anchor
                dx = (pos[0, b] + cb * an[:, 2] - sb * an[:, 3]) - (
                    pos[0, a] + ca * an[:, 0] - sa * an[:, 1])
                dy = (pos[1, b] + sb * an[:, 2] + cb * an[:, 3]) - (
                    pos[1, a] + sa * an[:, 0] + ca * an[:, 1])
                extent = np.sqrt(dx * dx + dy * dy)
            else:
                extent = pos[2, a] - pos[2, b]
            out.append(np.where(g.default, 0.5 * k * (extent - rest) ** 2, 0.0))
        return out

    def _field_energy(self, pos: np.ndarray) -> np.ndarray:
        """Declared potential (J) of each dynamic row (0 where none is declared)."""
        t = self._t
        out = np.zeros(t.n)
        for idx, potential, _ in self._fields:
            value = np.asarray(potential(pos[0, idx], pos[1, idx], t.m[idx]), dtype=float)
            out[idx] += np.broadcast_to(value, idx.shape)
        return out

    def _energy(self, s: dict[str, Any]) -> dict[str, Any]:
        """E and its parts at the snapshot ``s`` (J); per dynamic row K, Ug, Ud."""
        t = self._t
        n = t.n
        v, p = s["vel"], s["pos"]
        gx, gy = self._gravity
        K = 0.5 * t.m * (v[0, :n] ** 2 + v[1, :n] ** 2) + 0.5 * t.I * v[2, :n] ** 2
        Ug = -t.m * (gx * p[0, :n] + gy * p[1, :n])
        Ud = s["ud"]
        Us = sum(float(np.sum(u)) for u in s["us"])
        k, ug, ud = float(np.sum(K)), float(np.sum(Ug)), float(np.sum(Ud))
        return {"E": k + ug + ud + Us, "K": k, "Ug": ug, "Us": Us, "Ud": ud,
                "body": K + Ug + Ud, "Ugb": Ug, "Udb": Ud}

    # -- changes outside the step ------------------------------------------------------

    def _add(self, source: str, kind: str, value: float, note: str = "") -> None:
        key = (source, kind)
        self._terms[key] = self._terms.get(key, 0.0) + value
        if note:
            self._notes[key] = note

    def _restructure(self, reason: str, dt: float | None) -> None:
        """The space changed (bodies, constraints, settings): fold the running sums,
        rebuild, and count the energy that entered or left with bodies, and what the change
        itself did (``program``). ``dt`` is the step under way (None between steps): bodies
        new in it start where they were before its move."""
        old = self._energy(self._snap)
        old_dyn = self._t.uid[: self._t.n].copy()
        old_rows = self._snap_uid.copy()
        self._fold()
        self._build()
        snap = self._remap(self._snap)
        t = self._t
        if dt is not None:
            new = ~np.isin(t.uid, old_rows) & t.moves
            new[: t.n] &= ~snap["sleeping"]
            if np.any(new):
                snap["pos"][:, new] -= snap["vel"][:, new] * dt
                snap = self._potentials_at(snap)
        self._snap = snap
        e = self._energy(snap)
        entered = left = 0.0
        for i in np.nonzero(~np.isin(t.uid[: t.n], old_dyn))[0]:
            self._add(self._row_labels[i], "entered", float(e["body"][i]),
                      "energy of a body added to the space")
            entered += float(e["body"][i])
            self._Uref += (e["Ugb"][i], 0.0, e["Udb"][i])
        for j in np.nonzero(~np.isin(old_dyn, t.uid[: t.n]))[0]:
            self._add(self._labels[int(old_dyn[j])], "left", -float(old["body"][j]),
                      "energy of a body removed from the space")
            left -= float(old["body"][j])
            self._Uref -= (old["Ugb"][j], 0.0, old["Udb"][j])
        rest = e["E"] - old["E"] - entered - left
        if abs(rest) > 1e-12 * max(abs(old["E"]), abs(e["E"]), self._scale):
            self._add(f"program: {reason}", "program", rest,
                      "energy changed by what the program changed in the space")
        self._Uref[1] += e["Us"] - old["Us"]
        self._E = e["E"]

    def _sync(self) -> None:
        """Between steps: count what the program changed since the last look."""
        if self._sentinel is None or self._error is not None:
            return
        t = self._t
        reason = self._changed(t.pre.floats(), t.pre.pointers())
        if reason:
            self._restructure(reason, None)
        now = self._read_snapshot()
        self._program(now["pos"], now["vel"])
        self._snap = now
        self._E = self._energy(now)["E"]

    def _program(self, pos: np.ndarray, vel: np.ndarray) -> float:
        """Count, per body, the energy of what changed from the snapshot to the state
        (pos, vel) at the same moment (J); returns their sum."""
        s = self._snap
        t = self._t
        n = t.n
        moved = np.any(pos != s["pos"], axis=0)
        sped = np.any(vel[:, :n] != s["vel"][:, :n], axis=0)
        if not (np.any(moved) or np.any(sped)):
            return 0.0
        gx, gy = self._gravity
        v0, v1 = s["vel"], vel
        dK = 0.5 * t.m * (v1[0, :n] ** 2 + v1[1, :n] ** 2 - v0[0, :n] ** 2 - v0[1, :n] ** 2) \
            + 0.5 * t.I * (v1[2, :n] ** 2 - v0[2, :n] ** 2)
        dU = -t.m * (gx * (pos[0, :n] - s["pos"][0, :n]) + gy * (pos[1, :n] - s["pos"][1, :n]))
        total = 0.0
        if np.any(moved):
            if self._fields:
                dU = dU + self._field_energy(pos) - s["ud"]
            if self._springs:
                after = self._spring_energy(pos)
                ds = sum(float(np.sum(a) - np.sum(b)) for a, b in zip(after, s["us"],
                                                                       strict=True))
                if ds:
                    self._add("program: springs stretched by moved bodies", "program", ds)
                    total += ds
        self._acc["program"] += dK + dU
        return total + float(np.sum(dK + dU))

    # -- running sums into named terms -------------------------------------------------

    def _fold(self) -> None:
        """Move the running sums into the named terms (and zero them)."""
        self._fold_bodies()
        for j, (_, _, lab) in enumerate(self._fields):
            if self._acc_field[j]:
                self._add(lab, "step error", float(self._acc_field[j]),
                          "declared field: its kicks and its potential's change over the moves")
        self._acc_field[:] = 0.0
        labels, n = self._row_labels, self._t.n
        for r in np.nonzero(self._acc_kin)[0]:
            src = (f"{labels[r]} through contacts" if r >= n else
                   f"fixed spin of {labels[r]} through contacts")
            self._add(src, "kinematic", float(self._acc_kin[r]),
                      "work of a body whose motion the program imposes")
        self._acc_kin[:] = 0.0
        for g in self._groups.values():
            self._fold_group(g)

    def _fold_bodies(self) -> None:
        """The per-body sums: forces, unexplained impulses (rounding apart), the program's
        changes and custom velocity functions."""
        labels = self._row_labels
        kinds = {"force": ("force on {}", "force", "work of Body.force"),
                 "unattributed": ("{}", "unattributed", "an impulse no source explains"),
                 "program": ("program: {}", "program", "changed between steps by the program")}
        for name, (fmt, kind, note) in kinds.items():
            acc = self._acc[name]
            if name == "unattributed":
                # What the solver's sums round off (1e-16 of the impulses) is one term;
                # a body whose residual is more than that is named.
                tiny = np.abs(acc) <= _ROUNDING * max(self._scale, 1e-300)
                if tiny.any():
                    self._add("rounding", "rounding", float(acc[tiny].sum()),
                              "what the solver's and the ledger's sums round off")
                    acc[tiny] = 0.0
            for i in np.nonzero(acc)[0]:
                self._add(fmt.format(labels[i]), kind, float(acc[i]), note)
            acc[:] = 0.0
        vf = self._acc["vf"]
        for i in np.nonzero(vf)[0]:
            self._add(f"velocity_func of {labels[i]}", "velocity_func", float(vf[i]),
                      "kicks of a custom velocity_func and the moves they cause (no declared "
                      "potential)")
        vf[:] = 0.0

    def _fold_group(self, g: _Group) -> None:
        """The sums of the constraints of ``g``: each one's work (a spring's step error and
        damping), and what driven ends did through it."""
        labels, n = self._row_labels, self._t.n
        for i, lab in enumerate(g.labels):
            if g.spring and g.default[i]:
                self._add(lab, "step error", float(g.work[i] + g.pot[i]),
                          "spring: its kicks and its potential's change over the moves")
                self._add(f"{lab} damping", "spring damping", float(g.extra[i]))
            elif g.spring:
                self._add(lab, "custom spring", float(g.work[i] + g.extra[i]),
                          "work of a spring with a custom force function")
            else:
                self._add(lab, "constraint", float(g.work[i]), _joint_note(g.objs[i]))
            for row, acc in ((g.a[i], g.kin_a), (g.b[i], g.kin_b)):
                if acc[i]:
                    who = labels[row]
                    src = (f"{who} through {lab}" if row >= n else
                           f"fixed spin of {who} through {lab}")
                    self._add(src, "kinematic", float(acc[i]),
                              "work of a body whose motion the program imposes")
        for arr in (g.work, g.extra, g.pot, g.kin_a, g.kin_b):
            arr[:] = 0.0

    # -- the step ----------------------------------------------------------------------

    def _pre(self) -> None:
        """Before the constraints are prepared: positions have moved, velocities are the
        step's start. Count the program's changes and the move's energy; read the impulses
        carried in."""
        t = self._t
        dt = float(mem.view("space", self._space_at).dt)
        F, P = t.pre.floats(), t.pre.pointers()
        reason = self._changed(F, P)
        if reason:
            self._restructure(reason, dt)
            t = self._t
            F, P = t.pre.floats(), t.pre.pointers()
        move, total = self._move(F[0:3], F[3:6], dt)
        g_int, g_rows, corr = self._gravity_over(move)
        pots, corr = self._potentials_over(move, corr)
        total, corr = self._carried_push(dt, total, corr)
        if corr:
            self._add("position correction", "correction", corr,
                      "potential energy the contacts' position correction adds (beyond each "
                      "pair's part through gravity)")
        n = t.n
        force = F[6:9, :n]
        awake = P[0, :n] == 0
        coef = 0.0 if self._dt_prev == 0.0 else dt / self._dt_prev
        self._pending = {
            "dt": dt, "coef": coef,
            "pos": move.pos, "vel": move.vel, "force": force if force.any() else None,
            "awake": None if awake.all() else awake, "g_int": g_int, "g_rows": g_rows,
            "spring_int": pots.spring_int, "d_int": pots.d_int, "u_end": pots.u_end,
            "d_end": pots.d_end,
            "initial": [g.before.floats() for g in self._groups.values()],
            "contacts": self._contacts.before(t, self._pairs, coef),
            "total": total + corr,
        }

    def _move(self, pos: np.ndarray, vel: np.ndarray, dt: float) -> tuple[_Move, float]:
        """pymunk's move, p += (v + v_bias) dt for awake dynamic and kinematic bodies, from
        the snapshot to ``pos``: where each body started (the program may have moved it,
        woken it or put it to sleep) and how long it moved; and the energy of what the
        program changed since the snapshot, counted (J)."""
        t, s = self._t, self._snap
        n = t.n
        moving = t.moves
        if s["asleep"]:
            moving = moving.copy()
            moving[:n] &= ~s["sleeping"]
        total = 0.0
        start = s["pos"]
        if not np.array_equal(pos, np.where(moving, start + (vel + s["bias"]) * dt, start)):
            moving, start = self._moved_how(pos, vel, dt, moving)
        if start is not s["pos"] or not np.array_equal(vel[:, :n], s["vel"][:, :n]):
            total += self._program(start, vel)
        step = np.where(moving, dt, 0.0) if start is not s["pos"] or s["asleep"] else dt
        return _Move(pos, vel, start, step), total

    def _gravity_over(self, move: _Move) -> tuple[float, np.ndarray | None, float]:
        """Gravity's potential over the move (J): all of it, less the bias velocities' part
        (position correction), which leaves the velocities' part; the same per dynamic row
        when custom velocity functions need it (else None); and the correction's part."""
        t, s = self._t, self._snap
        n, m = t.n, t.m
        gx, gy = self._gravity
        pos, start = move.pos, move.start
        dU = -(gx * (m @ (pos[0, :n] - start[0, :n])) + gy * (m @ (pos[1, :n] - start[1, :n])))
        corr = 0.0
        b = None
        if s["biased"]:
            b = s["bias"][:, :n] * (move.step[:n] if isinstance(move.step, np.ndarray)
                                    else move.step)
            corr = -(gx * (m @ b[0]) + gy * (m @ b[1]))
        g_rows = None
        if self._any_custom:
            g_rows = -m * (gx * (pos[0, :n] - start[0, :n]) + gy * (pos[1, :n] - start[1, :n]))
            if b is not None:
                g_rows = g_rows + m * (gx * b[0] + gy * b[1])
        return float(dU - corr), g_rows, corr

    def _potentials_over(self, move: _Move, corr: float) -> tuple[_Potentials, float]:
        """The springs' and the declared fields' potentials over the move, less the bias
        velocities' part, which is added to the correction ``corr`` (J)."""
        s = self._snap
        if not (self._springs or self._fields):
            return _Potentials([], [], None, s["ud"]), corr
        pos, start, step = move.pos, move.start, move.step
        same = start is s["pos"]
        u_start = s["us"] if same else self._spring_energy(start)
        u_end = self._spring_energy(pos)
        spring_int = [b2 - a2 for a2, b2 in zip(u_start, u_end, strict=True)]
        d_start = s["ud"] if same else self._field_energy(start)
        d_end = self._field_energy(pos)
        d_int = d_end - d_start
        if s["biased"]:
            mid = start + move.vel * step
            end = mid + s["bias"] * step
            u1, u2 = self._spring_energy(mid), self._spring_energy(end)
            for j in range(len(spring_int)):
                spring_int[j] = spring_int[j] - (u2[j] - u1[j])
                corr += float(np.sum(u2[j] - u1[j]))
            if self._fields:
                f1, f2 = self._field_energy(mid), self._field_energy(end)
                d_int = d_int - (f2 - f1)
                corr += float(np.sum(f2 - f1))
        return _Potentials(spring_int, u_end, d_int, d_end), corr

    def _carried_push(self, dt: float, total: float, corr: float) -> tuple[float, float]:
        """Gravity's part of the position correction per pair, from the bias impulses of
        the last step, moved from the correction ``corr`` to the pairs and the ``total``."""
        if self._push is None:
            return total, corr
        gx, gy = self._gravity
        slots, jx, jy = self._push
        share = -(gx * jx + gy * jy) * dt
        self._pairs.push += np.bincount(slots, weights=share, minlength=len(self._pairs.push))
        pushed = float(np.sum(share))
        self._push = None
        return total + pushed, corr - pushed

    def _moved_how(self, pos: np.ndarray, vel: np.ndarray, dt: float, moving: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
        """Which bodies pymunk moved (the program may have woken some or put them to
        sleep), and where each started: where it was, or where the program put it."""
        t = self._t
        s = self._snap
        shift = (vel + s["bias"]) * dt
        ok = np.all(_same(pos, np.where(moving, s["pos"] + shift, s["pos"])), axis=0)
        flipped = ~moving & t.moves
        other = np.all(_same(pos, np.where(flipped, s["pos"] + shift, s["pos"])), axis=0)
        moving = np.where(~ok & other, flipped, moving)
        ok |= other
        step = np.where(moving, dt, 0.0)
        start = np.where(ok, s["pos"], pos - (vel + s["bias"]) * step)
        return moving, start

    def _post(self) -> None:
        """After the solver: every impulse of the step is applied. Count each source's work
        and close the step."""
        t = self._t
        p = self._pending
        Q = t.post.floats()
        vel0, vel1 = p["vel"], Q[0:3]
        damping = float(mem.view("space", self._space_at).damping)
        # Velocities the sources act on: the mean of before and after (kinematic bodies
        # keep theirs; static ones have none).
        step = _Step(p["dt"], p["coef"], p["pos"], vel0, vel1, (vel0 + vel1) * 0.5,
                     np.zeros((3, t.rows)),
                     np.zeros((3, t.rows)) if damping != 1.0 and self._springs else None,
                     p["spring_int"])
        total = p["total"]
        for g, initial in zip(self._groups.values(), p["initial"], strict=True):
            total += _constraint_work(t, g, g.after.floats(), initial, step)
        if p["contacts"]:
            total += self._contact_work(step)
        kicked = p["awake"]
        if self._any_custom:
            kicked = ~self._custom if kicked is None else kicked & ~self._custom
        ext, w_g, total = self._external(step, kicked, damping, total)
        total = self._unexplained(step, ext, w_g, total)
        self._close_step(Q, step.dt, total)

    def _external(self, step: _Step, kicked: np.ndarray | None, damping: float,
                  total: float) -> tuple[np.ndarray, float, float]:
        """The impulses from outside the constraints and contacts (3, dynamic rows):
        gravity, m g dt on every awake body the default velocity_func moves (``kicked``:
        which, None for all), applied forces and torques (pymunk clears them after the
        step), and ``space.damping``; gravity's work (J), and ``total`` with the others'."""
        t = self._t
        n, m, dt = t.n, t.m, step.dt
        gx, gy = self._gravity
        un = step.u[:, :n]
        mk = m * dt if kicked is None else np.where(kicked, m * dt, 0.0)
        ext = np.zeros((3, n))
        ext[0] = mk * gx
        ext[1] = mk * gy
        w_g = float(gx * (mk @ un[0]) + gy * (mk @ un[1]))
        if self._pending["force"] is not None:
            force = self._pending["force"] * dt
            if kicked is not None:
                force = np.where(kicked, force, 0.0)
            force[2] = np.where(t.finite, force[2], 0.0)
            w_f = np.sum(force * un, axis=0)
            self._acc["force"] += w_f
            total += float(np.sum(w_f))
            ext += force
        if damping != 1.0:
            d = damping ** dt
            kick = step.kick
            before = step.vel0[:, :n] if kick is None else step.vel0[:, :n] + kick[:, :n] * t.inv3
            D = (d - 1.0) * t.mass3 * before
            if kicked is not None:
                D = np.where(kicked, D, 0.0)
            w_d = float(np.sum(D * un))
            ext += D
            self._add("space.damping", "damping", w_d, f"space.damping = {damping:g}")
            total += w_d
        return ext, w_g, total

    def _unexplained(self, step: _Step, ext: np.ndarray, w_g: float, total: float) -> float:
        """What no source explains, a custom velocity_func's kicks or an impulse from
        outside the solver, and gravity's step error (``w_g`` its work): counted, and added
        to ``total``."""
        t, p = self._t, self._pending
        n = t.n
        un = step.u[:, :n]
        R = t.mass3 * (step.vel1[:, :n] - step.vel0[:, :n]) - step.imp[:, :n] - ext
        if not t.all_finite:
            R[2] = np.where(t.finite, R[2], 0.0)  # an infinite moment's spin is imposed
        w_r = np.sum(R * un, axis=0)
        d_int = p["d_int"]
        if self._any_custom:
            custom = self._custom
            g_rows = p["g_rows"]
            vf = np.where(custom, w_r + g_rows + (0.0 if d_int is None else d_int), 0.0)
            step_err = w_g + p["g_int"] - float(np.sum(g_rows[custom]))
            self._acc["vf"] += np.where(self._declared, 0.0, vf)
            other = np.where(custom, 0.0, w_r)
            self._acc["unattributed"] += other
            total += float(np.sum(vf) + np.sum(other))
            for j, (idx, _, _) in enumerate(self._fields):
                own = float(np.sum(np.where(custom[idx], 0.0, d_int[idx])))
                self._acc_field[j] += float(np.sum(vf[idx])) + own
                total += own
        else:
            step_err = w_g + p["g_int"]
            self._acc["unattributed"] += w_r
            total += float(np.sum(w_r))
            for j, (idx, _, _) in enumerate(self._fields):
                own = float(np.sum(d_int[idx]))
                self._acc_field[j] += own
                total += own
        self._terms[_GRAVITY] = self._terms.get(_GRAVITY, 0.0) + step_err
        return total + step_err

    def _contact_work(self, step: _Step) -> float:
        """Work of every contact impulse of the step, summed per pair of bodies (J); the
        bias impulses are kept for the next move (gravity's part is counted then)."""
        c = self._contacts
        total, push = c.work(step, self._t, self._pairs, self._acc_kin)
        if push.any():
            self._push = (c.slots, c.n[0] * push, c.n[1] * push)
        return total

    def _close_step(self, Q: np.ndarray, dt: float, total: float) -> None:
        """Snapshot the end of the step, check it against the terms, track the scale."""
        t = self._t
        p = self._pending
        bias = Q[3:6].copy()
        bias[:, t.n:] = 0.0
        sleeping = t.post.pointers()[0, : t.n] != 0
        snap = {"pos": p["pos"], "vel": Q[0:3], "bias": bias, "sleeping": sleeping,
                "asleep": bool(sleeping.any()), "biased": bool(bias.any()),
                "us": p["u_end"], "ud": p["d_end"]}
        e = self._energy(snap)
        if not (math.isfinite(e["E"]) and math.isfinite(total)):
            self._blown(snap)
            return
        self._snap = snap
        step = e["E"] - self._E - total
        self._E = e["E"]
        self.steps += 1
        self.t += dt
        self._dt_prev = dt
        self._scale = max(self._scale, e["K"], abs(e["Ug"] - self._Uref[0]),
                          abs(e["Us"] - self._Uref[1]), abs(e["Ud"] - self._Uref[2]))
        if self._scale > 0:
            self._worst = max(self._worst, abs(step) / self._scale)


_GRAVITY = ("gravity", "step error")
#: Below this fraction of the energy scale, a body's unexplained impulse work is rounding.
_ROUNDING = 1e-12


class _Move(NamedTuple):
    """pymunk's move at the start of a step: positions after it and velocities (3, rows),
    where each body started, and how long each moved (s; one dt for all, or per row)."""

    pos: np.ndarray
    vel: np.ndarray
    start: np.ndarray
    step: np.ndarray | float


class _Potentials(NamedTuple):
    """The springs' and declared fields' potentials over a move: each spring group's
    change (J, less the position correction's part) and end value, the fields' change per
    dynamic row (None without springs or fields) and end value."""

    spring_int: list[np.ndarray]
    u_end: list[np.ndarray]
    d_int: np.ndarray | None
    d_end: np.ndarray


class _Step(NamedTuple):
    """One step as the sources' work reads it: ``dt`` (s), ``coef`` (dt over the previous
    dt: how much of the carried impulses pymunk applies), the positions after the move and
    the velocities before and after the solver (3, rows), ``u`` their mean, which the
    sources act on; ``imp`` collects the impulses applied to each row (3, rows), ``kick``
    the springs' elastic ones (None unless ``space.damping`` needs them) and ``spring_int``
    is each spring group's potential change over the move."""

    dt: float
    coef: float
    pos: np.ndarray
    vel0: np.ndarray
    vel1: np.ndarray
    u: np.ndarray
    imp: np.ndarray
    kick: np.ndarray | None
    spring_int: list[np.ndarray]


def _constraint_work(t: _Table, g: _Group, after: np.ndarray, initial: np.ndarray,
                     step: _Step) -> float:
    """Work (J) of the step's impulses of the constraints in ``g``. The impulse applied is
    the accumulator's end value less what it carried in and did not apply (pymunk applies
    the carried impulse scaled by dt / previous dt, and none when a stop resets it). A
    spring's impulse splits into its elastic part (its force at the step's positions,
    applied when the step prepares it) and its damping. Adds the impulses to ``step.imp``
    and the springs' elastic kicks to ``step.kick`` (what ``space.damping`` then scales)."""
    rows = t.rows
    ra, rb = g.a, g.b
    u, imp = step.u, step.imp
    La, Lb, Aa, Ab = _impulses(g.kind, after, initial, step.coef)
    work_a = La[0] * u[0, ra] + La[1] * u[1, ra] + Aa * u[2, ra]
    work_b = Lb[0] * u[0, rb] + Lb[1] * u[1, rb] + Ab * u[2, rb]
    rel = work_a + work_b
    both = np.concatenate([ra, rb])
    imp[0] += _scatter(both, np.concatenate([La[0], Lb[0]]), rows)
    imp[1] += _scatter(both, np.concatenate([La[1], Lb[1]]), rows)
    imp[2] += _scatter(both, np.concatenate([Aa, Ab]), rows)
    drv_a = -np.where(t.lin_free[ra], 0.0, La[0] * u[0, ra] + La[1] * u[1, ra]) - np.where(
        t.ang_free[ra], 0.0, Aa * u[2, ra])
    drv_b = -np.where(t.lin_free[rb], 0.0, Lb[0] * u[0, rb] + Lb[1] * u[1, rb]) - np.where(
        t.ang_free[rb], 0.0, Ab * u[2, rb])
    g.kin_a += drv_a
    g.kin_b += drv_b
    total = float(np.sum(rel) + np.sum(drv_a) + np.sum(drv_b))
    if not g.spring:
        g.work += rel
        return total
    # The work is linear in the impulse along the spring: its elastic part, and the rest.
    elastic = _spring_elastic(t, g, after, step)
    g.work += elastic
    g.extra += rel - elastic
    if step.spring_int:
        pot = step.spring_int[g.slot]
        g.pot += pot
        total += float(np.sum(pot))
    return total


def _impulses(kind: str, after: np.ndarray, initial: np.ndarray, coef: float
              ) -> tuple[tuple[Any, Any], tuple[Any, Any], Any, Any]:
    """The impulses a constraint of ``kind`` applied in the step (its accumulators
    ``after`` the solver, ``initial`` what they carried in): linear on its body a and on b,
    angular on a and on b."""
    if kind in ("pin", "slide", "spring", "pivot", "groove"):
        if kind in ("pivot", "groove"):
            Px = after[0] - (1.0 - coef) * initial[0]
            Py = after[1] - (1.0 - coef) * initial[1]
            r1x, r1y, r2x, r2y = after[2:6]
        else:
            j, nx, ny, r1x, r1y, r2x, r2y = after
            J = j if kind == "spring" else j - (1.0 - coef) * initial[0]
            if kind == "slide":
                J = np.where((nx == 0.0) & (ny == 0.0), 0.0, J)
            Px, Py = nx * J, ny * J
        return (-Px, -Py), (Px, Py), -_cross(r1x, r1y, Px, Py), _cross(r2x, r2y, Px, Py)
    j = after[0]
    if kind == "rotary_spring":
        J = j
    elif kind in ("rotary_limit", "ratchet"):
        J = np.where(after[1] == 0.0, 0.0, j - (1.0 - coef) * initial[0])
    else:
        J = j - (1.0 - coef) * initial[0]
    zero = (0.0 * J, 0.0 * J)
    return zero, zero, -J * (after[1] if kind == "gear" else 1.0), J


def _spring_elastic(t: _Table, g: _Group, after: np.ndarray, step: _Step) -> np.ndarray:
    """The work (J) of the elastic part of the impulses of the springs in ``g`` (their
    force at the step's positions, as the step prepares them); their kicks are added to
    ``step.kick``."""
    rows, kick, u, pos = t.rows, step.kick, step.u, step.pos
    ra, rb = g.a, g.b
    both = np.concatenate([ra, rb])
    rest, k, max_force = g.settings[0], g.settings[1], g.settings[3]
    if g.kind == "spring":
        _, nx, ny, r1x, r1y, r2x, r2y = after
        dx = (pos[0, rb] + r2x) - (pos[0, ra] + r1x)
        dy = (pos[1, rb] + r2y) - (pos[1, ra] + r1y)
        f = np.clip((rest - np.sqrt(dx * dx + dy * dy)) * k, -max_force, max_force)
        Jel = np.where(g.default, f * step.dt, 0.0)
        ex, ey = nx * Jel, ny * Jel
        if kick is not None:
            kick[0] += _scatter(both, np.concatenate([-ex, ex]), rows)
            kick[1] += _scatter(both, np.concatenate([-ey, ey]), rows)
            kick[2] += _scatter(both, np.concatenate([-_cross(r1x, r1y, ex, ey),
                                                      _cross(r2x, r2y, ex, ey)]), rows)
        unit = nx * (u[0, rb] - u[2, rb] * r2y - u[0, ra] + u[2, ra] * r1y) + ny * (
            u[1, rb] + u[2, rb] * r2x - u[1, ra] - u[2, ra] * r1x)
    else:
        f = np.clip(((pos[2, ra] - pos[2, rb]) - rest) * k, -max_force, max_force)
        Jel = np.where(g.default, f * step.dt, 0.0)
        if kick is not None:
            kick[2] += _scatter(both, np.concatenate([-Jel, Jel]), rows)
        unit = u[2, rb] - u[2, ra]
    return Jel * unit


class _Hook:
    """The hook's callback: the ledger's method, if the ledger is still there."""

    __slots__ = ("ledger", "method")

    def __init__(self, ledger: weakref.ref[Ledger], method: str) -> None:
        self.ledger = ledger
        self.method = method

    def __call__(self, constraint: Any, space: Any) -> None:
        ledger = self.ledger()
        if ledger is not None:
            getattr(ledger, self.method)(constraint, space)


def _rotate(space_at: int, sentinel: Any, first: bool) -> None:
    """Rotate the space's C constraint array so that ``sentinel`` is first (or last, to be
    removed), keeping every other constraint in its order (the solver's order)."""
    f = mem.ffi()
    arr = f.cast("array *", mem.view("space", space_at).constraints)
    ptrs = f.cast("void **", arr.arr)
    me = mem.address(sentinel._constraint)
    items = [int(f.cast("uintptr_t", ptrs[i])) for i in range(int(arr.num))]
    if me not in items:
        return
    items.remove(me)
    items = [me, *items] if first else [*items, me]
    for i, at in enumerate(items):
        ptrs[i] = f.cast("void *", at)


def _joint_note(c: Any) -> str:
    parts = [type(c).__name__]
    for name in ("max_force", "max_bias"):
        value = getattr(c, name)
        if math.isfinite(value):
            parts.append(f"{name} {value:g}")
    return ", ".join(parts)


def _notes(terms: list[Term], scale: float) -> tuple[str, ...]:
    """What deserves a word beyond the terms: shapes pushed apart (they overlapped) putting
    energy in, with the pairs that did most."""
    pushed = [t for t in terms if t.kind == "correction"]
    total = sum(abs(t.energy) for t in pushed)
    if scale <= 0 or total <= 0.01 * scale:
        return ()
    pairs = sorted((t for t in pushed if t.source.startswith("pushed apart")),
                   key=lambda t: -abs(t.energy))[:3]
    which = ", ".join(t.source.removeprefix("pushed apart ") for t in pairs)
    return (f"overlapping shapes pushed apart by the contacts' position correction moved "
            f"{total:.3g} J ({total / scale:.2g} of the scale)"
            + (f", most between {which}" if which else "")
            + " (shapes that start overlapping, or that a joint holds in another)",)


def _order(t: Term) -> tuple[str, float]:
    return (t.kind, -abs(t.energy))
