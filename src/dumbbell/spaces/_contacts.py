"""The contacts the solver uses in a step, read from the space's arbiters (at most two
contacts each) with numpy: before the solver, the bodies' rows, the normals and the
impulses carried in; after it, each contact's impulse; and their work, a batch of steps at
a time.

The arbiters and contacts are read through pymunk's compiled declarations of ``cpArbiter``
and ``cpContact`` (their offsets are the compiler's); the list of the step's arbiters is the
space's ``arbiters`` array, whose place :func:`._layout.check_space` validated. Each
contact applies, over the step, its accumulated impulse less what it carried in and did not
apply: pymunk applies the carried impulse scaled by dt / previous dt (``coef``), and none on
a first contact (it keeps one cached from an earlier touch there without applying it). The
work of every contact impulse on the bodies' relative motion, J . (u0 + u1) / 2 at each
contact point, is summed per pair of bodies, and per body.

A pyramid's step has hundreds of arbiters, and each numpy call costs microseconds when the
solver has just run. The reads must happen in their step: two gathers from
:func:`._memory.memory` (every word an arbiter needs, then each field of both its contacts;
an arbiter with one contact reads its second from a contact of zeros, which adds nothing),
and the rows of an arbiter's bodies, found in a dense map or kept from the last step while
the same arbiters touch the same bodies. The arithmetic need not: each step's impulses,
normals, rows and velocities are held (:meth:`Contacts.record`) and their work is done
:data:`Contacts.BATCH` steps at a time (:meth:`Contacts.flush`, and whenever the ledger
folds its sums or its table changes), so that each numpy call serves every held step. A
step's energy balance does not wait: the contacts' work on each body is in the step's
unexplained impulses (:func:`._physics.unexplained` counts every velocity change no other
source explains), and the batch moves it from there to each pair. Pointers are read as 8
bytes (:func:`._memory.platform_problem` sends other platforms to the public-API ledger).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _memory as mem
from ._inventory import Pairs, Table, UnknownBody

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

    #: Steps held before their work is done in one batch (each numpy call then serves
    #: them all), and most arbiters held: past a few thousand the batch's arrays leave the
    #: caches and cost what the calls save. Against the ledger without batches, stepped
    #: alternately in one process on benchmarks/spaces_ledger.py's spaces: the 325-box
    #: pyramid (625 arbiters a step, batches of 14 steps) costs about a tenth less, the
    #: 1,080-body space (2,300 a step, batches of 4) about the same.
    BATCH = 16
    MOST = 8192

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
        self._ends_key: tuple[Table, bytes] | None = None
        # Steps whose work waits for a batch (:meth:`record`), the dt of the step after
        # each (None until it begins), and a push whose next dt came after its batch.
        self._held: list[tuple[np.ndarray, ...]] = []
        self._pushes: list[float | None] = []
        self._held_m = 0
        self._carry: tuple[np.ndarray, np.ndarray] | None = None

    def before(self, table: Table, coef: float) -> bool:
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
        self._rows(table, A[0:2])
        self.n = A[3:5].view(np.float64)
        first = A[6].view(np.uint32)[L.state::2] == 0
        at = L.contact + (A[2] >> 3)  # (7, 2, m): each field of both contacts
        if fewest < 2:  # no second contact: it reads the zeros
            at[:, 1, count < 2] = self._zero_at
        self.at = at
        # The impulses carried in that the step does not apply: all of a first contact's,
        # (1 - coef) of the others' (none when dt did not change).
        self.carried = None
        if coef != 1.0:
            self.carried = slice(None)
            self.j0 = self.floats.take(at[0:2]) * (1.0 - np.where(first, 0.0, coef))
        else:  # all of a first contact's (x 1.0)
            carried = first.nonzero()[0]
            if len(carried):
                self.carried = carried
                self.j0 = self.floats.take(at[0:2, :, carried])  # (2, 2, k): jn, jt
        return True

    def _rows(self, table: Table, ends: np.ndarray) -> None:
        """The rows of each arbiter's bodies (``ends``: their addresses, (2, m)), through
        the table's map; raises :class:`UnknownBody` on a body not in ``table``. The same
        bodies in the same order as the last step's, on the same table, keep them."""
        key = ends.tobytes()
        last = self._ends_key
        if last is not None and last[0] is table and last[1] == key:
            return
        self._ends_key = None
        # As numpy's index type once: each take and bincount would cast them again.
        rows = table.rows_of(ends).astype(np.intp, copy=False)
        if rows.min() < 0:
            raise UnknownBody
        self.rows = rows
        self._ends_key = (table, key)

    # -- the work, in batches of steps ----------------------------------------------------

    def record(self, u: np.ndarray) -> None:
        """After the solver: read each contact's impulse and keep it, with the step's
        normals, rows and the velocities the impulses act on (``u``, (3, rows)), for
        :meth:`flush`. Less what it carried in and did not apply."""
        f = self.floats.take(self.at)  # (7, 2, m): jn, jt, r1.x, r2.x, r1.y, r2.y, jBias
        if self.carried is not None:
            f[0:2, :, self.carried] -= self.j0
        self._held.append((f, self.n, self.rows, u))
        self._held_m += f.shape[2]
        self._pushes.append(None)

    @property
    def due(self) -> bool:
        """Enough steps are held to do their work in one batch."""
        return len(self._held) >= self.BATCH or self._held_m >= self.MOST

    def next_dt(self, dt: float, pairs: Pairs, sums: Any) -> None:
        """The step after a step with contacts begins, of ``dt``: the position correction's
        push of that step's contacts moves its bodies over this dt (gravity's part of it is
        each pair's, out of the one correction term)."""
        if self._pushes and self._pushes[-1] is None:
            self._pushes[-1] = dt
        elif self._carry is not None:
            slots, work = self._carry
            self._carry = None
            _pushed(pairs, sums, slots, work * dt)

    def flush(self, table: Table, pairs: Pairs, sums: Any, b: Any) -> None:
        """The work of the held steps' contact impulses (all on ``table``): summed per pair
        into ``pairs.work``; per row, what the driven ends did into ``sums.kin``, and the
        dynamic rows' out of the sums their step's unexplained impulses went into (which
        counted the contacts' work with them); gravity's part of the pushes per pair."""
        if not self._held:
            return
        held, dts = self._held, self._pushes
        self._held, self._pushes, self._held_m = [], [], 0
        f = np.concatenate([h[0] for h in held], axis=2)
        n = np.concatenate([h[1] for h in held], axis=1)
        perp = n[::-1] * _PERP
        rows = np.concatenate([h[2] for h in held], axis=1)
        k = len(held)
        R = table.rows
        counts = [h[0].shape[2] for h in held]  # each held step's arbiters
        # Each end's velocity in its own step: (3, k * rows), indexed by step * rows + row.
        u = np.stack([h[3] for h in held], axis=1).reshape(3, k * R)
        step_of = np.repeat(np.arange(k) * R, counts)
        # Each contact's impulse on b, in world axes (2, 2, m): n jn + (-ny, nx) jt.
        q = n[:, None] * f[0]
        q += perp[:, None] * f[1]
        # r1 x q and r2 x q of each contact (2, 2, m): (r.x qy, r.y qx) of r1 and r2.
        rq = f[2:6].reshape(2, 2, 2, -1) * q[::-1, None]
        moment = rq[0] - rq[1]
        # The impulse on each end (3, 2, m): x, y and angular; on a, the opposite of b's.
        imp = np.empty((3, 2, n.shape[1]))
        np.add(q[:, 0], q[:, 1], out=imp[0:2, 1])
        np.add(moment[:, 0], moment[:, 1], out=imp[2])
        np.negative(imp[0:2, 1], out=imp[0:2, 0])
        np.negative(imp[2, 0], out=imp[2, 0])
        # Its work on the velocities of the ends: linear (x + y) and angular, (2, m) each.
        np.multiply(imp, u.take(rows + step_of, axis=1), out=imp)
        lin, ang = imp[0], imp[2]
        lin += imp[1]
        rel = lin[0] + lin[1] + ang[0] + ang[1]
        slots = table.slots_of(rows, pairs).astype(np.intp, copy=False)
        pairs.work += np.bincount(slots, weights=rel, minlength=len(pairs.work))
        ends = rows.ravel()  # a's rows, then b's
        lin_rows = np.bincount(ends, weights=lin.ravel(), minlength=R)
        ang_rows = np.bincount(ends, weights=ang.ravel(), minlength=R)
        _unexplained_less(b, sums, lin_rows, ang_rows)
        if table.any_driven:
            # Work of driven ends (kinematic bodies, bodies outside the space, the spin of
            # bodies of infinite moment): what the relative work leaves out of theirs.
            sums.kin -= (np.where(table.lin_free, 0.0, lin_rows)
                         + np.where(table.ang_free, 0.0, ang_rows))
        # Gravity's work per unit time of each arbiter's push on its dynamic ends, over the
        # next step's dt (the last held step's next dt may not be known yet: carried).
        push = f[6, 0] + f[6, 1]
        if not np.count_nonzero(push):
            return
        free = table.lin_free_f.take(rows)
        gx, gy = b.gravity
        work = -(gx * n[0] + gy * n[1]) * (push * (free[1] - free[0]))
        if dts[-1] is None:
            last = step_of == (k - 1) * R
            self._carry = (slots[last], work[last])
            dts[-1] = 0.0
        span = np.repeat(np.array(dts, dtype=float), counts)
        _pushed(pairs, sums, slots, work * span)


def _pushed(pairs: Pairs, sums: Any, slots: np.ndarray, share: np.ndarray) -> None:
    """Gravity's part of the position correction, ``share`` per arbiter, to its pair (out
    of the one ``position correction`` term, which counted it)."""
    pairs.push += np.bincount(slots, weights=share, minlength=len(pairs.push))
    sums.add("position correction", "correction", -float(share.sum()))


def _unexplained_less(b: Any, sums: Any, lin_rows: np.ndarray, ang_rows: np.ndarray) -> None:
    """Take the contacts' work on each dynamic row out of the sum its steps' unexplained
    impulses went into (:func:`._physics.unexplained`, which counted it): a custom velocity
    function's (or its declared field's), else what nothing explains. The spin of a body of
    infinite moment is imposed: not counted there."""
    t = b.table
    n = t.n
    work = lin_rows[:n] + (ang_rows[:n] if t.all_finite else np.where(t.finite, ang_rows[:n],
                                                                      0.0))
    if not b.any_custom:
        sums.unattributed -= work
        return
    custom = b.custom
    vf = np.where(custom, work, 0.0)
    sums.vf -= np.where(b.declared, 0.0, vf)
    sums.unattributed -= np.where(custom, 0.0, work)
    for j, fld in enumerate(b.fields):
        sums.field[j] -= float(np.sum(vf[fld.idx]))


def arbiters_address(space_at: int) -> int:
    """Address of the space's arbiters array (validated by :func:`._layout.check_space`)."""
    return mem.address(mem.view("space", space_at).arbiters)
