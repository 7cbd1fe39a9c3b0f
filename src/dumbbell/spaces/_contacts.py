"""The contacts the solver uses in a step, read from the space's arbiters (at most two
contacts each) with numpy: before the solver, the bodies' rows, the normals and the
impulses carried in; after it, each contact's impulse and its work.

The arbiters and contacts are read through pymunk's compiled declarations of ``cpArbiter``
and ``cpContact`` (their offsets are the compiler's); the list of the step's arbiters is the
space's ``arbiters`` array, whose place :func:`._layout.check_space` validated. Each
contact applies, over the step, its accumulated impulse less what it carried in and did not
apply: pymunk applies the carried impulse scaled by dt / previous dt (``coef``), and none on
a first contact (it keeps one cached from an earlier touch there without applying it). The
work of every contact impulse on the bodies' relative motion, J . (u0 + u1) / 2 at each
contact point, is summed per pair of bodies, and per body.

A pyramid's step has hundreds of arbiters, and each numpy call costs microseconds when the
solver has just run: the reads are few, wide gathers (every field an arbiter needs in one,
every field of both its contacts in another, laid out (field, contact, arbiter) so that
each is a contiguous row), the arithmetic runs on both contacts at once, and the rows of
an arbiter's bodies and its pair's slot are found in dense maps. Pointers are
read as 8 bytes (:func:`._memory.platform_problem` sends other platforms to the
public-API ledger).
"""

from __future__ import annotations

import numpy as np

from . import _memory as mem
from ._inventory import Pairs, Table
from ._records import Step

#: Work on end a and on end b of an impulse applied to b (and its opposite to a).
_ENDS = np.array([[-1.0], [1.0]])


class UnknownBody(Exception):
    """A contact touches a body that is not in the ledger's table (one pymunk made since:
    the space's static body, say): the table must be built again."""


class _Layout:
    """Where the fields are, in 8-byte (or 4-byte) words from an arbiter's (or a
    contact's) start."""

    def __init__(self) -> None:
        p = mem._pymunk_ffi()
        arb = {name: p.offsetof("cpArbiter", name) for name in
               ("body_a", "body_b", "contacts", "n", "count", "state")}
        self.asize, self.csize = p.sizeof("cpArbiter"), p.sizeof("cpContact")
        # One gather of 8-byte words: body_a, body_b, contacts, n.x, n.y; one of 4-byte
        # words: count, state.
        self.arbiter = (np.array([arb["body_a"], arb["body_b"], arb["contacts"], arb["n"],
                                  arb["n"] + 8]) // 8)[:, None]
        self.ints = (np.array([arb["count"], arb["state"]]) // 4)[:, None]
        con = {name: p.offsetof("cpContact", name) for name in
               ("jnAcc", "jtAcc", "jBias", "r1", "r2")}
        # Per contact (jn, jt, r1.x, r2.x, r1.y, r2.y, jBias), for each of an arbiter's two
        # contacts: (7, 2, 1) word offsets from its first contact.
        one = np.array([con["jnAcc"], con["jtAcc"], con["r1"], con["r2"], con["r1"] + 8,
                        con["r2"] + 8, con["jBias"]]) // 8
        self.contacts = np.stack([one, one + self.csize // 8], axis=1)[:, :, None]


class Contacts:
    """The step's contacts of the space whose arbiters array is at ``arbiters_at``."""

    def __init__(self, arbiters_at: int) -> None:
        p = mem._pymunk_ffi()
        self.arr = p.cast("cpArray *", arbiters_at)
        self.buffer = p.buffer
        self.L = _Layout()
        self.span: mem.Span | None = None
        self.cspan: mem.Span | None = None

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
        arb = np.frombuffer(self.buffer(self.arr.arr, 8 * num), dtype=np.int64)
        lo, hi = int(arb.min()), int(arb.max()) + L.asize
        span = self.span
        if span is None or lo < span.lo or hi > span.lo + len(span.u8):
            span = self.span = self._grown(span, lo, hi)
        words = (arb - span.lo) >> 3
        g = span.i64[L.arbiter + words]  # (5, m): body_a, body_b, contacts, n.x, n.y
        count, state = span.u32[L.ints + 2 * words]
        if not count.all():  # arbiters without contacts: left out
            keep = count > 0
            if not keep.any():
                return False
            arb, g, count, state = arb[keep], g[:, keep], count[keep], state[keep]
        self._rows(table, g[0:2], pairs)
        self.n = g[3:5].view(np.float64)
        self.first = state == 0
        first_c = g[2]
        self.single = None if (count > 1).all() else count < 2
        cspan = self.cspan = self._grown(self.cspan, int(first_c.min()),
                                         int(first_c.max()) + 2 * L.csize)
        idx = L.contacts + ((first_c - cspan.lo) >> 3)  # (7, 2, m)
        if self.single is not None:  # no second contact: read the first twice, zeroed later
            idx[:, 1, self.single] = idx[:, 0, self.single]
        self.idx = idx
        # The impulses carried in that the step does not apply: all of a first contact's,
        # (1 - coef) of the others' (none when dt did not change).
        self.carried = np.arange(len(first_c)) if coef != 1.0 else np.nonzero(self.first)[0]
        if len(self.carried):  # (2, 2, k): jn, jt of each contact
            kept = 1.0 - np.where(self.first[self.carried], 0.0, coef)
            self.j0 = cspan.f64[idx[0:2, :, self.carried]] * kept
        return True

    def _rows(self, table: Table, ends: np.ndarray, pairs: Pairs) -> None:
        """The rows of each arbiter's bodies (``ends``: their addresses, (2, m)), its
        pair's slot and the sign of the push on its ends, through the table's maps."""
        rows = table.rows_of(ends)
        if rows.min() < 0:
            raise UnknownBody
        slots = table.slots_of(rows[0], rows[1], pairs)
        self.rows, self.slots = rows, slots
        free = table.lin_free[rows]
        self.sign = free[1].astype(float) - free[0]

    def work(self, step: Step, table: Table, pairs: Pairs, drive: np.ndarray
             ) -> tuple[float, np.ndarray]:
        """Work of the step's contact impulses, summed per pair into ``pairs.work`` and per
        row (its linear and angular parts) into ``step.work``; the work of driven ends into
        ``drive`` (rows); and the bias impulse along the normal on the dynamic ends of each
        arbiter (its position correction's push)."""
        f = self.cspan.f64[self.idx]  # (7, 2, m): each field of both contacts
        jn, jt = f[0], f[1]
        if len(self.carried):
            jn[:, self.carried] -= self.j0[0]
            jt[:, self.carried] -= self.j0[1]
        if self.single is not None:  # the first contact read twice: not a second one
            f[:, 1, self.single] = 0.0
        n = self.n
        nx, ny = n[0], n[1]
        qx = nx * jn - ny * jt  # each contact's impulse on b, in world axes (2, m)
        qy = ny * jn + nx * jt
        px, py = qx[0] + qx[1], qy[0] + qy[1]
        moment = f[2:4] * qy - f[4:6] * qx  # (2, 2, m): r1 x q and r2 x q of each contact
        U = step.u[:, self.rows]  # (3, 2, m): the velocities of ends a and b
        lin = (px * U[0] + py * U[1]) * _ENDS
        ang = (moment[:, 0] + moment[:, 1]) * U[2] * _ENDS
        rel = lin[0] + lin[1] + ang[0] + ang[1]
        pairs.work += np.bincount(self.slots, weights=rel, minlength=len(pairs.work))
        rows, n = self.rows.ravel(), table.rows
        lin_rows = np.bincount(rows, weights=lin.ravel(), minlength=n)
        ang_rows = np.bincount(rows, weights=ang.ravel(), minlength=n)
        step.work[0] += lin_rows
        step.work[1] += ang_rows
        total = float(rel.sum())
        if table.any_driven:
            # Work of driven ends (kinematic bodies, bodies outside the space, the spin of
            # bodies of infinite moment): what the relative work leaves out of theirs.
            driven = -(np.where(table.lin_free, 0.0, lin_rows)
                       + np.where(table.ang_free, 0.0, ang_rows))
            drive += driven
            total += float(driven.sum())
        return total, (f[6, 0] + f[6, 1]) * self.sign

    @property
    def normals(self) -> tuple[np.ndarray, np.ndarray]:
        """Each arbiter's normal: (x, y)."""
        return self.n[0], self.n[1]


def arbiters_address(space_at: int) -> int:
    """Address of the space's arbiters array (validated by :func:`._layout.check_space`)."""
    return mem.address(mem.view("space", space_at).arbiters)
