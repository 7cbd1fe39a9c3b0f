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
solver has just run: the reads are two gathers (every field an arbiter needs, then every
field of both its contacts, each a row of consecutive words of :func:`._memory.memory`,
so that no index is built per field and no span is found first), the arithmetic runs on
both contacts at once, and the rows of an arbiter's bodies and its pair's slot are found
in dense maps. Pointers are read as 8 bytes (:func:`._memory.platform_problem` sends
other platforms to the public-API ledger).
"""

from __future__ import annotations

import numpy as np

from . import _memory as mem
from ._inventory import Pairs, Table, UnknownBody
from ._records import Step

__all__ = ["Contacts", "UnknownBody", "arbiters_address"]

#: The x, y and angular components of a row's impulse, in :meth:`Contacts.work`'s sums.
_XYW = np.arange(3)[:, None, None]


class _Layout:
    """Where the fields are, in 8-byte words from an arbiter's (or a contact's) start,
    from pymunk's compiled declarations: an arbiter's (body_a, body_b, contacts, n.x, n.y,
    and the words holding count and state, each 4 bytes: ``count`` and ``state`` say which
    half); a contact's (jnAcc, jtAcc, r1.x, r2.x, r1.y, r2.y, jBias)."""

    def __init__(self) -> None:
        p = mem._pymunk_ffi()
        arb = {name: p.offsetof("cpArbiter", name) for name in
               ("body_a", "body_b", "contacts", "n", "count", "state")}
        self.asize, self.csize = p.sizeof("cpArbiter"), p.sizeof("cpContact")
        self.arbiter = (np.array([arb["body_a"], arb["body_b"], arb["contacts"], arb["n"],
                                  arb["n"] + 8, arb["count"], arb["state"]]) // 8)[:, None]
        # Each 4-byte field is one half of its word (the same bytes, whatever the order).
        self.count, self.state = arb["count"] % 8 // 4, arb["state"] % 8 // 4
        con = {name: p.offsetof("cpContact", name) for name in
               ("jnAcc", "jtAcc", "jBias", "r1", "r2")}
        self.contact = (np.array([con["jnAcc"], con["jtAcc"], con["r1"], con["r2"],
                                  con["r1"] + 8, con["r2"] + 8, con["jBias"]]) // 8
                        )[:, None, None]
        # An arbiter's second contact, in words from its first: (2, 1).
        self.pair = np.array([[0], [self.csize // 8]])


class Contacts:
    """The step's contacts of the space whose arbiters array is at ``arbiters_at``."""

    def __init__(self, arbiters_at: int) -> None:
        p = mem._pymunk_ffi()
        self.arr = p.cast("cpArray *", arbiters_at)
        self.buffer = p.buffer
        self.L = _Layout()
        memory = mem.memory()
        self.lowest = memory.LOWEST
        self.words, self.floats = memory.i64, memory.f64

    def before(self, table: Table, pairs: Pairs, coef: float) -> bool:
        """Read the step's contacts and the impulses they carry in; False if none. Raises
        :class:`UnknownBody` when a contact touches a body not in ``table``."""
        arr = self.arr
        num = arr.num
        if num == 0 or not 0 < num <= arr.max:
            return False
        L = self.L
        arb = np.frombuffer(self.buffer(arr.arr, 8 * num), dtype=np.int64)
        # (7, m): body_a, body_b, contacts, n.x, n.y, the words of count and state
        A = self.words.take(L.arbiter + ((arb - self.lowest) >> 3))
        count = A[5].view(np.uint32)[L.count::2]
        if not count.all():  # arbiters without contacts: left out
            keep = count > 0
            if not keep.any():
                return False
            A, count = A[:, keep], count[keep]
        self._rows(table, A[0:2], pairs)
        n = A[3:5].view(np.float64)
        self.nx, self.ny = n[0], n[1]
        self.first = A[6].view(np.uint32)[L.state::2] == 0
        self.single = None if count.min() > 1 else count < 2
        # Each contact's first word: (2, m), the first and the second contact.
        cw = ((A[2] - self.lowest) >> 3) + L.pair
        if self.single is not None:  # no second contact: read the first twice, zeroed later
            cw[1, self.single] = cw[0, self.single]
        self.at = L.contact + cw  # (7, 2, m): each field of both contacts
        # The impulses carried in that the step does not apply: all of a first contact's,
        # (1 - coef) of the others' (none when dt did not change).
        self.carried = None
        if coef != 1.0:
            self.carried = slice(None)
            self.j0 = self.floats.take(self.at[0:2]) * (1.0 - np.where(self.first, 0.0, coef))
        elif self.first.any():  # all of it (x 1.0)
            self.carried = np.nonzero(self.first)[0]
            self.j0 = self.floats.take(self.at[0:2, :, self.carried])  # (2, 2, k): jn, jt
        return True

    def _rows(self, table: Table, ends: np.ndarray, pairs: Pairs) -> None:
        """The rows of each arbiter's bodies (``ends``: their addresses, (2, m)), its
        pair's slot and the sign of the push on its ends, through the table's maps; and
        where each end's impulse adds up per row (``rows3``: x, y and angular)."""
        rows = table.rows_of(ends)
        self.slots = table.slots_of(rows, pairs)  # raises UnknownBody on a row -1
        self.rows = rows
        free = table.lin_free_f.take(rows)
        self.sign = free[1] - free[0]
        self.rows3 = rows + table.rows * _XYW

    def work(self, step: Step, table: Table, pairs: Pairs, drive: np.ndarray
             ) -> tuple[float, np.ndarray]:
        """Work of the step's contact impulses, summed per pair into ``pairs.work`` and per
        row (its linear and angular parts) into ``step.work``; the work of driven ends into
        ``drive`` (rows); and the bias impulse along the normal on the dynamic ends of each
        arbiter (its position correction's push)."""
        f = self.floats.take(self.at)  # (7, 2, m): jn, jt, r1.x, r2.x, r1.y, r2.y, jBias
        if self.carried is not None:
            f[0:2, :, self.carried] -= self.j0
        if self.single is not None:  # the first contact read twice: not a second one
            f[:, 1, self.single] = 0.0
        jn, jt = f[0], f[1]
        nx, ny = self.nx, self.ny
        qx = nx * jn - ny * jt  # each contact's impulse on b, in world axes (2, m)
        qy = ny * jn + nx * jt
        # The impulse on each end (3, 2, m): x, y and angular; on a, the opposite of b's.
        imp = np.empty((3, 2, len(nx)))
        np.add(qx[0], qx[1], out=imp[0, 1])
        np.add(qy[0], qy[1], out=imp[1, 1])
        moment = f[2:4] * qy - f[4:6] * qx  # (2, 2, m): r1 x q and r2 x q of each contact
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
        per_row = np.bincount(self.rows3.ravel(), weights=imp.ravel(), minlength=3 * n)
        lin_rows, ang_rows = per_row[:n], per_row[2 * n:]
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
        return self.nx, self.ny


def arbiters_address(space_at: int) -> int:
    """Address of the space's arbiters array (validated by :func:`._layout.check_space`)."""
    return mem.address(mem.view("space", space_at).arbiters)
