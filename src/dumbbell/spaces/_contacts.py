"""The contacts the solver uses in a step, read from the space's arbiters (at most two
contacts each) with numpy: before the solver, the bodies' rows, the normals and the
impulses carried in; after it, each contact's impulse and its work.

The arbiters and contacts are read through pymunk's compiled declarations of ``cpArbiter``
and ``cpContact`` (their offsets are the compiler's); the list of the step's arbiters is the
space's ``arbiters`` array, whose place :func:`._memory.check_space` validated. Each
contact applies, over the step, its accumulated impulse less what it carried in and did not
apply: pymunk applies the carried impulse scaled by dt / previous dt (``coef``), and none on
a first contact (it keeps one cached from an earlier touch there without applying it). The
work of every contact impulse on the bodies' relative motion, J . (u0 + u1) / 2 at each
contact point, is summed per pair of bodies.

Each read is one numpy gather of several fields of every arbiter (or contact) at once; what
depends only on which bodies an arbiter joins (their rows, their pair's slot, where the
impulses go) is kept from one step to the next while the arbiters and their bodies are the
same.
"""

from __future__ import annotations

import numpy as np

from . import _memory as mem
from ._inventory import Pairs, Table
from ._records import Step


class UnknownBody(Exception):
    """A contact touches a body that is not in the ledger's table (one pymunk made since:
    the space's static body, say): the table must be built again."""


class _Layout:
    """Where each field is, in 8-byte words from a contact's (or arbiter's) start."""

    def __init__(self) -> None:
        p = mem._pymunk_ffi()
        ps = mem.pointer_size()
        arb = {name: p.offsetof("cpArbiter", name) for name in
               ("contacts", "body_a", "body_b", "count", "state", "n")}
        self.asize, self.csize = p.sizeof("cpArbiter"), p.sizeof("cpContact")
        # Pointers (body_a, body_b, contacts) in pointer-sized words, the normal in 8-byte
        # words, count and state in 4-byte words.
        self.ptr = np.array([arb["body_a"], arb["body_b"], arb["contacts"]]) // ps
        self.pshift = 3 if ps == 8 else 2
        self.normal = np.array([arb["n"], arb["n"] + 8]) // 8
        self.ints = np.array([arb["count"], arb["state"]]) // 4
        con = {name: p.offsetof("cpContact", name) for name in
               ("jnAcc", "jtAcc", "jBias", "r1", "r2")}
        self.words8 = np.concatenate([self.ptr, self.normal]) if ps == 8 else None
        # As complex numbers (x + i y): the impulse jn + i jt (along the normal and the
        # tangent), r1, r2, and jBias (its real part).
        self.contact = np.array([con["jnAcc"], con["jtAcc"], con["r1"], con["r1"] + 8,
                                 con["r2"], con["r2"] + 8, con["jBias"], con["jBias"]]) // 8
        self.carried = self.contact[:2]


class Contacts:
    """The step's contacts of the space whose arbiters array is at ``arbiters_at``."""

    def __init__(self, arbiters_at: int) -> None:
        p = mem._pymunk_ffi()
        self.arr = p.cast("cpArray *", arbiters_at)
        self.buffer = p.buffer
        self.psize = mem.pointer_size()
        self.dtype = mem.pointer_dtype()
        self.L = _Layout()
        self.span: mem.Span | None = None
        self.cspan: mem.Span | None = None
        self._cache: _Cache | None = None

    @staticmethod
    def _grown(span: mem.Span | None, low: int, high: int) -> mem.Span:
        """``span``, or a new one covering it and [low, high)."""
        if span is not None and low >= span.lo and high <= span.lo + len(span.u8):
            return span
        if span is not None:
            low, high = min(low, span.lo), max(high, span.lo + len(span.u8))
        return mem.Span(low, high)

    def before(self, table: Table, pairs: Pairs, coef: float) -> bool:
        """Read the step's contacts and the impulses they carry in; False if none. Raises
        :class:`UnknownBody` when a contact touches a body not in ``table``."""
        num = int(self.arr.num)
        if num == 0 or not 0 < num <= int(self.arr.max):
            return False
        L = self.L
        arb = np.frombuffer(self.buffer(self.arr.arr, self.psize * num),
                            dtype=self.dtype).astype(np.int64)
        span = self.span
        lo, hi = int(arb.min()), int(arb.max()) + L.asize
        if span is None or lo < span.lo or hi > span.lo + len(span.u8):
            span = self.span = self._grown(span, lo, hi)
            self._cache = None  # its positions are the span's
        rel = arb - span.lo
        ints = span.u32[(rel >> 2)[:, None] + L.ints]
        words = rel >> 3
        if L.pshift == 3:  # the pointers and the normal in one gather of 8-byte words
            g = span.u64[words[:, None] + L.words8]
            ptr, n = g[:, :3].view(np.int64), g[:, 3:].view(np.float64)
        else:
            ptr = span.ptr[(rel >> L.pshift)[:, None] + L.ptr].astype(np.int64)
            n = span.f64[words[:, None] + L.normal]
        count = ints[:, 0]
        if not count.all():  # arbiters without contacts: left out
            keep = count > 0
            if not keep.any():
                return False
            words, count, ints, ptr, n = words[keep], count[keep], ints[keep], ptr[keep], \
                n[keep]
        self._rows(table, pairs, words, ptr[:, 0], ptr[:, 1])
        self.n = n[:, 0] + 1j * n[:, 1]
        two = count > 1
        self.single = None if two.all() else ~two
        self.first = ints[:, 1] == 0
        first_c = ptr[:, 2]
        second = first_c + L.csize * two
        cspan = self.cspan = self._grown(self.cspan, int(first_c.min()),
                                         int(second.max()) + L.csize)
        self.words = (np.stack([first_c, second]) - cspan.lo) >> 3
        self.has_j0 = coef != 1.0 or bool(self.first.any())
        if self.has_j0:
            j0 = cspan.f64[self.words[..., None] + L.carried]  # (2, m, 2): jn, jt
            self.j0 = j0.view(np.complex128)[..., 0] * (1.0 - np.where(self.first, 0.0, coef))
        return True

    def _rows(self, table: Table, pairs: Pairs, words: np.ndarray, end_a: np.ndarray,
              end_b: np.ndarray) -> None:
        """The rows of each arbiter's bodies, its pair's slot, the sign of its push, and
        where its impulses go; kept, at the arbiter's place in the span, while the same
        arbiter joins the same bodies (a few arbiters come and go each step)."""
        c = self._cache
        if c is None or c.table is not table:
            c = self._cache = _Cache(len(self.span.u8) >> 3, table)
        hit = (c.end_a[words] == end_a) & (c.end_b[words] == end_b)
        if not hit.all():
            c.fill(words[~hit], end_a[~hit], end_b[~hit], pairs)
        self.ra, self.rb, self.slots = c.ra[words], c.rb[words], c.slot[words]
        self.sign = c.sign[words]
        self.both = np.concatenate([self.ra, self.rb])

    def work(self, step: Step, table: Table, pairs: Pairs, drive: np.ndarray
             ) -> tuple[float, np.ndarray]:
        """Work of the step's contact impulses, summed per pair into ``pairs.work`` and per
        row (its linear and angular parts) into ``step.work``; the work of driven ends into
        ``drive`` (rows); and the bias impulse along the normal on the dynamic ends of each
        arbiter (its position correction's push). Vectors are complex numbers x + i y: a
        product with a conjugate gives the dot product (real part) and the cross product
        (imaginary part)."""
        f = self.cspan.f64[self.words[..., None] + self.L.contact].view(np.complex128)
        if self.single is not None:  # arbiters of one contact: no second one
            f[1, self.single] = 0.0
        J, r1, r2 = f[..., 0], f[..., 1], f[..., 2]  # (2, m) each
        if self.has_j0:
            J = J - self.j0
        q = self.n * J  # each contact's impulse on b, in world axes
        P = q[0] + q[1]
        ta = (r1.conj() * q).imag.sum(axis=0)
        tb = (r2.conj() * q).imag.sum(axis=0)
        jbias = f[0, :, 3].real + f[1, :, 3].real
        a, b, u = self.ra, self.rb, step.u
        uc = np.empty(u.shape[1], dtype=np.complex128)
        uc.real, uc.imag = u[0], u[1]
        cP = P.conj()
        lin_b = (cP * uc[b]).real
        lin_a = -(cP * uc[a]).real
        ang_b = tb * u[2, b]
        ang_a = -ta * u[2, a]
        rel = lin_a + lin_b + ang_a + ang_b
        pairs.work += np.bincount(self.slots, weights=rel, minlength=len(pairs.work))
        rows = table.rows
        lin = np.bincount(self.both, weights=np.concatenate([lin_a, lin_b]), minlength=rows)
        ang = np.bincount(self.both, weights=np.concatenate([ang_a, ang_b]), minlength=rows)
        step.work[0] += lin
        step.work[1] += ang
        total = float(rel.sum())
        if table.any_driven:
            # Work of driven ends (kinematic bodies, bodies outside the space, the spin of
            # bodies of infinite moment): what the relative work leaves out of theirs.
            driven = -(np.where(table.lin_free, 0.0, lin) + np.where(table.ang_free, 0.0, ang))
            drive += driven
            total += float(driven.sum())
        return total, jbias * self.sign


class _Cache:
    """What :meth:`Contacts._rows` keeps for each place (8-byte word) of the arbiters' span:
    the bodies the arbiter there joins (0: none yet), their rows in ``table``, their pair's
    slot and the sign of the push on them."""

    def __init__(self, words: int, table: Table) -> None:
        self.table = table
        self.end_a = np.zeros(words, dtype=np.int64)
        self.end_b = np.zeros(words, dtype=np.int64)
        self.ra = np.zeros(words, dtype=np.int64)
        self.rb = np.zeros(words, dtype=np.int64)
        self.slot = np.zeros(words, dtype=np.int64)
        self.sign = np.zeros(words)

    def fill(self, words: np.ndarray, end_a: np.ndarray, end_b: np.ndarray,
             pairs: Pairs) -> None:
        """What the arbiters at ``words`` joining ``end_a`` and ``end_b`` need."""
        t = self.table
        nb = len(t.sorted_i64)
        ends = np.concatenate([end_a, end_b])
        if nb == 0:
            raise UnknownBody
        pos = np.minimum(np.searchsorted(t.sorted_i64, ends), nb - 1)
        if not np.array_equal(t.sorted_i64[pos], ends):
            raise UnknownBody
        rows = t.order[pos]
        ra, rb = rows[: len(end_a)], rows[len(end_a):]
        self.end_a[words], self.end_b[words] = end_a, end_b
        self.ra[words], self.rb[words] = ra, rb
        self.slot[words] = t.pair_slots(ra, rb, pairs)
        self.sign[words] = t.lin_free[rb].astype(float) - t.lin_free[ra].astype(float)


def arbiters_address(space_at: int) -> int:
    """Address of the space's arbiters array (validated by :func:`._memory.check_space`)."""
    return mem.address(mem.view("space", space_at).arbiters)
