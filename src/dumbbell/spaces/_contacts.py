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
from ._inventory import Pairs, Table
from ._records import Step

#: Work on end a and on end b of an impulse applied to b (and its opposite to a).
_ENDS = np.array([[-1.0], [1.0]])


class UnknownBody(Exception):
    """A contact touches a body that is not in the ledger's table (one pymunk made since:
    the space's static body, say): the table must be built again."""


class _Layout:
    """Where the fields are, from pymunk's compiled declarations: the words of an arbiter
    its reads cover (``first``, ``words``: from ``body_a`` to ``state``) and each field's
    place among them (``count`` and ``state`` in 4-byte units); the words of a contact
    they cover (from ``r1`` to ``jBias``), and each field's place."""

    def __init__(self) -> None:
        p = mem._pymunk_ffi()
        arb = {name: p.offsetof("cpArbiter", name) for name in
               ("body_a", "body_b", "contacts", "n", "count", "state")}
        self.asize, self.csize = p.sizeof("cpArbiter"), p.sizeof("cpContact")
        self.first = min(arb.values()) // 8
        self.words = (max(arb.values()) + 8) // 8 - self.first
        start = 8 * self.first
        self.ends = (arb["body_a"] - start) // 8  # body_b follows (checked by the platform)
        self.contacts = (arb["contacts"] - start) // 8
        self.n = (arb["n"] - start) // 8
        self.count = (arb["count"] - start) // 4
        self.state = (arb["state"] - start) // 4
        con = {name: p.offsetof("cpContact", name) // 8 for name in
               ("r1", "r2", "jnAcc", "jtAcc", "jBias")}
        self.cfirst = min(con.values())
        self.cwords = max(con.values()) + 1 - self.cfirst
        at = {name: w - self.cfirst for name, w in con.items()}
        self.jn, self.jt, self.jb = at["jnAcc"], at["jtAcc"], at["jBias"]
        # r1.x and r2.x (and their y) of a contact, as one strided slice.
        gap = at["r2"] - at["r1"]
        self.rx = slice(at["r1"], at["r2"] + 1, gap)
        self.ry = slice(at["r1"] + 1, at["r2"] + 2, gap)
        # A contact's words from its arbiter's first contact: (2, 1), the second one next.
        self.pair = np.array([[0], [self.csize // 8]])


class Contacts:
    """The step's contacts of the space whose arbiters array is at ``arbiters_at``."""

    def __init__(self, arbiters_at: int) -> None:
        p = mem._pymunk_ffi()
        self.arr = p.cast("cpArray *", arbiters_at)
        self.buffer = p.buffer
        self.L = L = _Layout()
        memory = mem.memory()
        self.lowest = memory.LOWEST
        self.arbiters = memory.window(L.first, L.words)
        self.contacts = memory.window(L.cfirst, L.cwords, floats=True)

    def before(self, table: Table, pairs: Pairs, coef: float) -> bool:
        """Read the step's contacts and the impulses they carry in; False if none. Raises
        :class:`UnknownBody` when a contact touches a body not in ``table``."""
        arr = self.arr
        num = arr.num
        if num == 0 or not 0 < num <= arr.max:
            return False
        L = self.L
        arb = np.frombuffer(self.buffer(arr.arr, 8 * num), dtype=np.int64)
        A = self.arbiters[(arb - self.lowest) >> 3]  # (m, words) from body_a to state
        count = A.view(np.uint32)[:, L.count]
        if not count.all():  # arbiters without contacts: left out
            keep = count > 0
            if not keep.any():
                return False
            A, count = A[keep], count[keep]
        self._rows(table, A[:, L.ends: L.ends + 2].T, pairs)
        n = A[:, L.n: L.n + 2].view(np.float64)
        self.nx, self.ny = n[:, 0], n[:, 1]
        self.first = A.view(np.uint32)[:, L.state] == 0
        self.single = None if count.min() > 1 else count < 2
        # Each contact's row of words: (2, m), the first and the second contact.
        cw = ((A[:, L.contacts] - self.lowest) >> 3) + L.pair
        if self.single is not None:  # no second contact: read the first twice, zeroed later
            cw[1, self.single] = cw[0, self.single]
        self.cw = cw
        # The impulses carried in that the step does not apply: all of a first contact's,
        # (1 - coef) of the others' (none when dt did not change).
        self.carried = None
        if coef != 1.0 or self.first.any():
            carried = np.arange(len(count)) if coef != 1.0 else np.nonzero(self.first)[0]
            kept = (1.0 - np.where(self.first[carried], 0.0, coef))[:, None]
            # (2, k, 2): jn, jt of each contact
            self.j0 = self.contacts[cw[:, carried]][:, :, [L.jn, L.jt]] * kept
            self.carried = carried
        return True

    def _rows(self, table: Table, ends: np.ndarray, pairs: Pairs) -> None:
        """The rows of each arbiter's bodies (``ends``: their addresses, (2, m)), its
        pair's slot and the sign of the push on its ends, through the table's maps."""
        rows = table.rows_of(ends)
        if rows.min() < 0:
            raise UnknownBody
        self.rows, self.slots = rows, table.slots_of(rows[0], rows[1], pairs)
        free = table.lin_free_f[rows]
        self.sign = free[1] - free[0]

    def work(self, step: Step, table: Table, pairs: Pairs, drive: np.ndarray
             ) -> tuple[float, np.ndarray]:
        """Work of the step's contact impulses, summed per pair into ``pairs.work`` and per
        row (its linear and angular parts) into ``step.work``; the work of driven ends into
        ``drive`` (rows); and the bias impulse along the normal on the dynamic ends of each
        arbiter (its position correction's push)."""
        L = self.L
        f = self.contacts[self.cw]  # (2, m, words): each field of both contacts
        jn, jt = f[:, :, L.jn], f[:, :, L.jt]
        if self.carried is not None:
            jn[:, self.carried] -= self.j0[:, :, 0]
            jt[:, self.carried] -= self.j0[:, :, 1]
        if self.single is not None:  # the first contact read twice: not a second one
            f[1, self.single] = 0.0
        nx, ny = self.nx, self.ny
        qx = nx * jn - ny * jt  # each contact's impulse on b, in world axes (2, m)
        qy = ny * jn + nx * jt
        px, py = qx[0] + qx[1], qy[0] + qy[1]
        # r1 x q and r2 x q of each contact (2, m, 2), then of the arbiter (m, 2)
        moment = f[:, :, L.rx] * qy[:, :, None] - f[:, :, L.ry] * qx[:, :, None]
        moment = moment[0] + moment[1]
        U = step.u[:, self.rows]  # (3, 2, m): the velocities of ends a and b
        lin = (px * U[0] + py * U[1]) * _ENDS
        ang = moment.T * U[2] * _ENDS
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
        return total, (f[0, :, L.jb] + f[1, :, L.jb]) * self.sign

    @property
    def normals(self) -> tuple[np.ndarray, np.ndarray]:
        """Each arbiter's normal: (x, y)."""
        return self.nx, self.ny


def arbiters_address(space_at: int) -> int:
    """Address of the space's arbiters array (validated by :func:`._layout.check_space`)."""
    return mem.address(mem.view("space", space_at).arbiters)
