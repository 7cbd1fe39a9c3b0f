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
"""

from __future__ import annotations

import numpy as np

from . import _memory as mem
from ._inventory import PAIR, Pairs, Table
from ._records import Step


class UnknownBody(Exception):
    """A contact touches a body that is not in the ledger's table (one pymunk made since:
    the space's static body, say): the table must be built again."""


class Contacts:
    """The step's contacts of the space whose arbiters array is at ``arbiters_at``."""

    def __init__(self, arbiters_at: int) -> None:
        p = mem._pymunk_ffi()
        self.arr = p.cast("cpArray *", arbiters_at)
        self.buffer = p.buffer
        self.o = {name: p.offsetof("cpArbiter", name) for name in
                  ("contacts", "body_a", "body_b", "count", "state", "n")}
        self.c = {name: p.offsetof("cpContact", name) for name in
                  ("jnAcc", "jtAcc", "jBias", "r1", "r2")}
        self.asize = p.sizeof("cpArbiter")
        self.csize = p.sizeof("cpContact")
        self.psize = mem.pointer_size()
        self.cspan: mem.Span | None = None

    def _contact_span(self, low: int, high: int) -> mem.Span:
        """A span over the contact buffers, grown to cover [low, high)."""
        span = self.cspan
        if span is None or low < span.lo or high > span.lo + len(span.u8):
            lo = low if span is None else min(low, span.lo)
            hi = high if span is None else max(high, span.lo + len(span.u8))
            span = self.cspan = mem.Span(lo, hi)
        return span

    def before(self, table: Table, pairs: Pairs, coef: float) -> bool:
        """Read the step's contacts and the impulses they carry in; False if none. Raises
        :class:`UnknownBody` when a contact touches a body not in ``table``."""
        num = int(self.arr.num)
        if num == 0 or not 0 < num <= int(self.arr.max):
            return False
        arb = np.frombuffer(self.buffer(self.arr.arr, self.psize * num),
                            dtype=mem.pointer_dtype()).astype(np.int64)
        span = mem.Span(int(arb.min()), int(arb.max()) + self.asize)
        rel = arb - span.lo
        o, ps = self.o, span.pshift
        count = span.u32[(rel + o["count"]) >> 2].astype(np.int64)
        keep = count > 0
        if not keep.all():
            rel, count = rel[keep], count[keep]
            if not len(rel):
                return False
        ends = np.stack([span.ptr[(rel + o["body_a"]) >> ps],
                         span.ptr[(rel + o["body_b"]) >> ps]]).astype(np.int64)
        nb = len(table.sorted_i64)
        pos = np.minimum(np.searchsorted(table.sorted_i64, ends), max(nb - 1, 0))
        if nb == 0 or not np.all(table.sorted_i64[pos] == ends):
            raise UnknownBody
        ra, rb = table.order[pos]
        self.n = np.stack([span.f64[(rel + o["n"]) >> 3], span.f64[(rel + o["n"] + 8) >> 3]])
        self.first = span.u32[(rel + o["state"]) >> 2] == 0
        first_c = span.ptr[(rel + o["contacts"]) >> ps].astype(np.int64)
        self.at = np.stack([first_c, first_c + np.where(count > 1, self.csize, 0)])
        self.weight = np.stack([np.ones(len(rel)), (count > 1).astype(float)])
        ua, ub = table.uid[ra], table.uid[rb]
        slots = pairs.lookup(np.minimum(ua, ub) * PAIR + np.maximum(ua, ub))
        if slots.min() < 0:
            slots = table.pair_slots(ra, rb, pairs)
        self.ra, self.rb, self.slots = ra, rb, slots
        self.sign = table.lin_free[rb].astype(float) - table.lin_free[ra].astype(float)
        cspan = self._contact_span(int(first_c.min()), int(self.at[1].max()) + self.csize)
        self.has_j0 = coef != 1.0 or bool(self.first.any())
        if self.has_j0:
            idx = self.at - cspan.lo
            c = self.c
            self.j0 = np.stack([cspan.f64[(idx + c["jnAcc"]) >> 3],
                                cspan.f64[(idx + c["jtAcc"]) >> 3]])
            self.kept = 1.0 - np.where(self.first, 0.0, coef)
        return True

    def work(self, step: Step, table: Table, pairs: Pairs, drive: np.ndarray
             ) -> tuple[float, np.ndarray]:
        """Work (energy units) of the step's contact impulses, summed per pair into
        ``pairs.work``; their impulses added to ``step.imp``, the work of driven ends to
        ``drive`` (rows); and the bias impulse along the normal on the dynamic ends of each
        arbiter (its position correction's push)."""
        span, c = self.cspan, self.c
        idx = self.at - span.lo
        f64 = span.f64
        jn = f64[(idx + c["jnAcc"]) >> 3]
        jt = f64[(idx + c["jtAcc"]) >> 3]
        if self.has_j0:
            jn = jn - self.kept * self.j0[0]
            jt = jt - self.kept * self.j0[1]
        w = self.weight
        nx, ny = self.n
        qx = (nx * jn - ny * jt) * w
        qy = (ny * jn + nx * jt) * w
        r1x, r1y = f64[(idx + c["r1"]) >> 3], f64[(idx + c["r1"] + 8) >> 3]
        r2x, r2y = f64[(idx + c["r2"]) >> 3], f64[(idx + c["r2"] + 8) >> 3]
        px, py = qx.sum(axis=0), qy.sum(axis=0)
        ta = (r1x * qy - r1y * qx).sum(axis=0)
        tb = (r2x * qy - r2y * qx).sum(axis=0)
        jbias = (f64[(idx + c["jBias"]) >> 3] * w).sum(axis=0)
        a, b, u = self.ra, self.rb, step.u
        rel = px * (u[0, b] - u[0, a]) + py * (u[1, b] - u[1, a]) + tb * u[2, b] - ta * u[2, a]
        pairs.work += np.bincount(self.slots, weights=rel, minlength=len(pairs.work))
        rows = table.rows
        imp = step.imp
        imp[0] += _scatter(b, px, rows) - _scatter(a, px, rows)
        imp[1] += _scatter(b, py, rows) - _scatter(a, py, rows)
        imp[2] += _scatter(b, tb, rows) - _scatter(a, ta, rows)
        total = float(rel.sum())
        # Work of driven ends (kinematic bodies, bodies outside the space, the spin of
        # bodies of infinite moment): what the relative work leaves out of theirs.
        lin, ang = table.lin_free, table.ang_free
        da = (np.where(lin[a], 0.0, px * u[0, a] + py * u[1, a])
              + np.where(ang[a], 0.0, ta * u[2, a]))
        db = -(np.where(lin[b], 0.0, px * u[0, b] + py * u[1, b])
               + np.where(ang[b], 0.0, tb * u[2, b]))
        if da.any() or db.any():
            drive += _scatter(a, da, rows) + _scatter(b, db, rows)
            total += float(da.sum() + db.sum())
        return total, jbias * self.sign


def _scatter(rows: np.ndarray, values: np.ndarray, size: int) -> np.ndarray:
    return np.bincount(rows, weights=values, minlength=size)


def arbiters_address(space_at: int) -> int:
    """Address of the space's arbiters array (validated by :func:`._memory.check_space`)."""
    return mem.address(mem.view("space", space_at).arbiters)
