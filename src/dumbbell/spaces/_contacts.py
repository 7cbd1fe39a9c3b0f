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
solver has just run: the reads are two gathers from :func:`._memory.memory` (every word an
arbiter needs, then each field of both its contacts; an arbiter with one contact reads its
second from a contact of zeros, which adds nothing), the arithmetic runs on both contacts
at once, and the rows of an arbiter's bodies and its pair's slot are found in dense maps,
or kept from the last step while the same arbiters touch the same bodies (about half the
steps of the awake pyramid). Pointers are read as 8 bytes (:func:`._memory.platform_problem` sends other
platforms to the public-API ledger).
"""

from __future__ import annotations

import numpy as np

from . import _memory as mem
from ._inventory import Pairs, Table, UnknownBody
from ._records import Step

__all__ = ["Contacts", "UnknownBody", "arbiters_address"]

#: (-ny, nx) from (nx, ny) reversed: the normal's perpendicular, as the tangent impulse uses.
_PERP = np.array([[-1.0], [1.0]])


class _Layout:
    """Where the fields are, in 8-byte words of :func:`._memory.memory` from an arbiter's
    (or a contact's) address shifted right by 3, from pymunk's compiled declarations:
    an arbiter's (body_a, body_b, contacts, n.x, n.y, and the words holding count and
    state, each 4 bytes: ``count`` and ``state`` say which half), (7, 1); each field of an
    arbiter's two contacts from its first contact's (jnAcc, jtAcc, r1.x, r2.x, r1.y, r2.y,
    jBias; the first and the second contact), (7, 2, 1)."""

    def __init__(self) -> None:
        p = mem._pymunk_ffi()
        arb = {name: p.offsetof("cpArbiter", name) for name in
               ("body_a", "body_b", "contacts", "n", "count", "state")}
        self.asize, self.csize = p.sizeof("cpArbiter"), p.sizeof("cpContact")
        # The word at address a is a // 8 - LOWEST // 8 (LOWEST and a are multiples of 8).
        lowest = mem.memory().LOWEST // 8
        self.arbiter = (np.array([arb["body_a"], arb["body_b"], arb["contacts"], arb["n"],
                                  arb["n"] + 8, arb["count"], arb["state"]]) // 8
                        - lowest)[:, None]
        # Each 4-byte field is one half of its word (the same bytes, whatever the order).
        self.count, self.state = arb["count"] % 8 // 4, arb["state"] % 8 // 4
        con = {name: p.offsetof("cpContact", name) for name in
               ("jnAcc", "jtAcc", "jBias", "r1", "r2")}
        self.fields = (np.array([con["jnAcc"], con["jtAcc"], con["r1"], con["r2"],
                                 con["r1"] + 8, con["r2"] + 8, con["jBias"]]) // 8)[:, None]
        # An arbiter's second contact is the next one: (7, 2, 1).
        self.contact = (self.fields[:, None] + np.array([[0], [self.csize // 8]])) - lowest


class Contacts:
    """The step's contacts of the space whose arbiters array is at ``arbiters_at``."""

    def __init__(self, arbiters_at: int) -> None:
        p = mem._pymunk_ffi()
        self.arr = p.cast("cpArray *", arbiters_at)
        self.buffer = p.buffer
        self.L = L = _Layout()
        memory = mem.memory()
        self.words, self.floats = memory.i64, memory.f64
        # An arbiter with one contact reads its second from here: a contact of zeros (the
        # ledger's own memory, never written), so that it adds nothing.
        self._zeros = np.zeros(L.csize // 8)
        zero = (self._zeros.ctypes.data - memory.LOWEST) >> 3
        self._zero_at = L.fields + zero  # (7, 1)
        # What the last step's arbiters gave (the same arbiters touch step after step).
        self._arb_key: bytes | None = None
        self._ends_key: tuple[Table, Pairs, bytes] | None = None

    def before(self, table: Table, pairs: Pairs, coef: float) -> bool:
        """Read the step's contacts and the impulses they carry in; False if none. Raises
        :class:`UnknownBody` when a contact touches a body not in ``table``."""
        arr = self.arr
        num = arr.num
        if num == 0 or not 0 < num <= arr.max:
            return False
        L = self.L
        arb = np.frombuffer(self.buffer(arr.arr, 8 * num), dtype=np.int64)
        key = arb.tobytes()
        if key != self._arb_key:  # where each arbiter's words are
            self._arb_at = L.arbiter + (arb >> 3)
            self._arb_key = key
        # (7, m): body_a, body_b, contacts, n.x, n.y, the words of count and state
        A = self.words.take(self._arb_at)
        count = A[5].view(np.uint32)[L.count::2]
        fewest = count.min()
        if not fewest:  # arbiters without contacts: left out
            keep = count > 0
            if not keep.any():
                return False
            A, count = A[:, keep], count[keep]
            fewest = count.min()
        self._rows(table, A[0:2], pairs)
        n = A[3:5].view(np.float64)
        self.nx, self.ny = n[0], n[1]
        self.n, self.perp = n, n[::-1] * _PERP
        self.first = A[6].view(np.uint32)[L.state::2] == 0
        self.single = None if fewest > 1 else count < 2
        at = L.contact + (A[2] >> 3)  # (7, 2, m): each field of both contacts
        if self.single is not None:  # no second contact: it reads the zeros
            at[:, 1, self.single] = self._zero_at
        self.at = at
        # The impulses carried in that the step does not apply: all of a first contact's,
        # (1 - coef) of the others' (none when dt did not change).
        self.carried = None
        if coef != 1.0:
            self.carried = slice(None)
            self.j0 = self.floats.take(at[0:2]) * (1.0 - np.where(self.first, 0.0, coef))
        else:  # all of a first contact's (x 1.0)
            carried = self.first.nonzero()[0]
            if len(carried):
                self.carried = carried
                self.j0 = self.floats.take(at[0:2, :, carried])  # (2, 2, k): jn, jt
        return True

    def _rows(self, table: Table, ends: np.ndarray, pairs: Pairs) -> None:
        """The rows of each arbiter's bodies (``ends``: their addresses, (2, m)), its
        pair's slot and the sign of the push on its ends, through the table's maps. The same
        bodies in the same order as the last step's, on the same table, keep them."""
        key = ends.tobytes()
        last = self._ends_key
        if last is not None and last[0] is table and last[1] is pairs and last[2] == key:
            return
        self._ends_key = None
        # As numpy's index type once: each take and bincount would cast them again.
        rows = table.rows_of(ends).astype(np.intp, copy=False)
        slots = table.slots_of(rows, pairs)  # raises UnknownBody on a row -1
        self.slots = slots.astype(np.intp, copy=False)
        self.rows = rows
        free = table.lin_free_f.take(rows)
        self.sign = free[1] - free[0]
        self.ends = rows.ravel()  # a's rows, then b's: the order of each end's sums
        self._ends_key = (table, pairs, key)

    def work(self, step: Step, table: Table, pairs: Pairs, drive: np.ndarray
             ) -> tuple[float, np.ndarray]:
        """Work of the step's contact impulses, summed per pair into ``pairs.work`` and per
        row (its linear and angular parts) into ``step.work``; the work of driven ends into
        ``drive`` (rows); and the bias impulse along the normal on the dynamic ends of each
        arbiter (its position correction's push)."""
        f = self.floats.take(self.at)  # (7, 2, m): jn, jt, r1.x, r2.x, r1.y, r2.y, jBias
        if self.carried is not None:
            f[0:2, :, self.carried] -= self.j0
        # Each contact's impulse on b, in world axes (2, 2, m): (x, y) of both contacts,
        # n jn + (-ny, nx) jt.
        q = self.n[:, None] * f[0]
        q += self.perp[:, None] * f[1]
        # r1 x q and r2 x q of each contact (2, 2, m): (r.x qy, r.y qx) of r1 and r2.
        rq = f[2:6].reshape(2, 2, 2, -1) * q[::-1, None]
        moment = rq[0] - rq[1]
        # The impulse on each end (3, 2, m): x, y and angular; on a, the opposite of b's.
        imp = np.empty((3, 2, len(self.nx)))
        np.add(q[:, 0], q[:, 1], out=imp[0:2, 1])
        np.add(moment[:, 0], moment[:, 1], out=imp[2])
        np.negative(imp[0:2, 1], out=imp[0:2, 0])
        np.negative(imp[2, 0], out=imp[2, 0])
        # Its work on the velocities of the ends: linear (x + y) and angular, (2, m) each
        # (-a + -b is -(a + b) bit for bit: the work on a is the same as on b, negated).
        np.multiply(imp, step.u.take(self.rows, axis=1), out=imp)
        lin, ang = imp[0], imp[2]
        lin += imp[1]
        rel = lin[0] + lin[1] + ang[0] + ang[1]
        pairs.work += np.bincount(self.slots, weights=rel, minlength=len(pairs.work))
        n = table.rows
        # Per row: linear (x + y) and angular, each summed in the order of the ends.
        lin_rows = np.bincount(self.ends, weights=lin.ravel(), minlength=n)
        ang_rows = np.bincount(self.ends, weights=ang.ravel(), minlength=n)
        work = step.work
        work[0] += lin_rows
        work[1] += ang_rows
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
        return self.nx, self.ny


def arbiters_address(space_at: int) -> int:
    """Address of the space's arbiters array (validated by :func:`._layout.check_space`)."""
    return mem.address(mem.view("space", space_at).arbiters)
