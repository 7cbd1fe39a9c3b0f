"""The ledger's per-contact loops, compiled with numba on first use (and cached): reading
hundreds of arbiters and contacts from pymunk's memory and summing their work takes
microseconds compiled, against the dozens of numpy temporaries it would take per step.

The memory is passed as numpy views (:class:`._memory.Span`: float64, int64 and uint32
views of one range starting at ``lo``); an address ``a`` plus a field offset ``o`` is at
index ``(a - lo + o) >> 3`` of the 8-byte views and ``>> 2`` of the 4-byte one. Addresses
are int64 here (user-space addresses are below 2**63).
"""

from __future__ import annotations

import functools
from typing import Any


@functools.cache
def arbiters() -> Any:
    """``read(arb, i64, u32, f64, lo, o_contacts, o_body_a, o_body_b, o_count, o_state,
    o_n, csize, sorted_at, order, uid, keys, key_slot, lin_free, rows_out, n_out,
    first_out, at_out, weight_out, slot_out, sign_out, cf64, clo, chi, o_jn, o_jt, coef,
    j0_out)``: for each arbiter address in
    ``arb``, the table rows of its two bodies (-1 when unknown; ``sorted_at`` the table's
    body addresses sorted, ``order`` their rows), its normal, whether it is a first contact,
    the addresses of its contacts (``at_out`` (2, arbiters): the second repeats the first
    when it has one, with weight 0 in ``weight_out``; 0 when it has none), its pair's slot
    (the pair key min(uid) * 2**31 + max(uid) looked up in the sorted ``keys``; -1 when
    new), the sign of the push on its dynamic ends, and into ``j0_out`` the impulses its
    contacts carry in (for a first contact or ``coef`` != 1, when they are in the span
    ``cf64`` from ``clo`` to ``chi``). Returns (lowest contact address, highest, first
    contacts present, carried impulses not read)."""
    from .._install import njit

    return njit(cache=True, nogil=True)(_read)


@functools.cache
def contacts() -> Any:
    """``work(at, weight2, f64, lo, o_jn, o_jt, o_jb, o_r1, o_r2, j0, has_j0, first, coef,
    n, ra, rb, u, lin_free, ang_free, slots, imp, pair_work, drive, push, sign)``: the
    impulse each contact applied in the step (its accumulator less what it carried in and
    did not apply: ``j0``, read before the solver, when ``has_j0``), and the work of every
    contact impulse of the step (see :mod:`.ledger`), added per pair into ``pair_work``, the
    impulses into ``imp`` (3, rows), the work of driven ends into ``drive`` (rows), and the
    bias impulse along the normal on the dynamic ends into ``push`` (arbiters). Returns the
    total (J)."""
    from .._install import njit

    return njit(cache=True, nogil=True)(_work)


# The loops, compiled by the functions above. They stay long, with their arguments flat:
# packed in tuples, the arguments are typed by numba's dispatcher in Python, which doubles
# the cost of a call (the contacts' loop: 11 -> 26 us a step on pymunk's box2d_pyramid,
# 624 arbiters); the arbiters' binary searches moved into an inlined helper cost 5-6 us of
# its 16 (numba counts references to the arrays the helper is given).


def _read(arb, i64, u32, f64, lo, o_contacts, o_body_a, o_body_b, o_count, o_state, o_n,
          csize, sorted_at, order, uid, keys, key_slot, lin_free, rows_out, n_out,
          first_out, at_out, weight_out, slot_out, sign_out, cf64, clo, chi, o_jn, o_jt,
          coef, j0_out):  # pragma: no cover
    low = arb[0] * 0 + 9223372036854775807
    high = arb[0] * 0
    any_first = False
    missing = False
    nb = sorted_at.size
    for i in range(arb.size):
        a = arb[i] - lo
        count = u32[(a + o_count) >> 2]
        for end in range(2):
            body = i64[(a + (o_body_a if end == 0 else o_body_b)) >> 3]
            lo_k, hi_k = 0, nb
            while lo_k < hi_k:  # the first sorted address >= body
                mid = (lo_k + hi_k) >> 1
                if sorted_at[mid] < body:
                    lo_k = mid + 1
                else:
                    hi_k = mid
            rows_out[end, i] = order[lo_k] if lo_k < nb and sorted_at[lo_k] == body else -1
        ra, rb = rows_out[0, i], rows_out[1, i]
        slot_out[i] = -1
        if ra >= 0 and rb >= 0:
            key = min(uid[ra], uid[rb]) * 2147483648 + max(uid[ra], uid[rb])
            lo_k, hi_k = 0, keys.size
            while lo_k < hi_k:
                mid = (lo_k + hi_k) >> 1
                if keys[mid] < key:
                    lo_k = mid + 1
                else:
                    hi_k = mid
            if lo_k < keys.size and keys[lo_k] == key:
                slot_out[i] = key_slot[lo_k]
        sign_out[i] = (1.0 if rb >= 0 and lin_free[rb] else 0.0) - (
            1.0 if ra >= 0 and lin_free[ra] else 0.0)
        n_out[0, i] = f64[(a + o_n) >> 3]
        n_out[1, i] = f64[(a + o_n + 8) >> 3]
        first = u32[(a + o_state) >> 2] == 0
        first_out[i] = first
        weight_out[0, i] = 1.0 if count > 0 else 0.0
        weight_out[1, i] = 1.0 if count > 1 else 0.0
        if count == 0:
            at_out[0, i] = 0
            at_out[1, i] = 0
            continue
        any_first = any_first or first
        c = i64[(a + o_contacts) >> 3]
        at_out[0, i] = c
        at_out[1, i] = c + (csize if count > 1 else 0)
        low = min(low, c)
        high = max(high, at_out[1, i])
        if first or coef != 1.0:
            # The impulses the contacts carry in, if the contacts are in the span.
            if c >= clo and at_out[1, i] + csize <= chi:
                for k in range(2):
                    ck = at_out[k, i] - clo
                    j0_out[0, k, i] = cf64[(ck + o_jn) >> 3]
                    j0_out[1, k, i] = cf64[(ck + o_jt) >> 3]
            else:
                missing = True
    return low, high, any_first, missing


def _work(at, weight2, f64, lo, o_jn, o_jt, o_jb, o_r1, o_r2, j0, has_j0, first, coef, n,
          ra, rb, u, lin_free, ang_free, slots, imp, pair_work, drive, push,
          sign):  # pragma: no cover
    total = 0.0
    for i in range(ra.size):
        a, b = ra[i], rb[i]
        nx, ny = n[0, i], n[1, i]
        px = py = ta = tb = jbias = 0.0
        for k in range(2):
            if weight2[k, i] == 0.0:
                continue
            c = at[k, i] - lo
            jn = f64[(c + o_jn) >> 3]
            jt = f64[(c + o_jt) >> 3]
            if has_j0:
                kept = 1.0 - (0.0 if first[i] else coef)
                jn -= kept * j0[0, k, i]
                jt -= kept * j0[1, k, i]
            qx = nx * jn - ny * jt
            qy = ny * jn + nx * jt
            r1x = f64[(c + o_r1) >> 3]
            r1y = f64[(c + o_r1 + 8) >> 3]
            r2x = f64[(c + o_r2) >> 3]
            r2y = f64[(c + o_r2 + 8) >> 3]
            px += qx
            py += qy
            ta += r1x * qy - r1y * qx
            tb += r2x * qy - r2y * qx
            jbias += f64[(c + o_jb) >> 3]
        rel = (px * (u[0, b] - u[0, a]) + py * (u[1, b] - u[1, a]) + tb * u[2, b]
               - ta * u[2, a])
        pair_work[slots[i]] += rel
        total += rel
        imp[0, b] += px
        imp[1, b] += py
        imp[2, b] += tb
        imp[0, a] -= px
        imp[1, a] -= py
        imp[2, a] -= ta
        # Work of driven ends (kinematic bodies, bodies outside the space, the spin of
        # bodies of infinite moment): what the relative work leaves out of theirs.
        da = 0.0
        db = 0.0
        if not lin_free[a]:
            da += px * u[0, a] + py * u[1, a]
        if not ang_free[a]:
            da += ta * u[2, a]
        if not lin_free[b]:
            db -= px * u[0, b] + py * u[1, b]
        if not ang_free[b]:
            db -= tb * u[2, b]
        drive[a] += da
        drive[b] += db
        total += da + db
        push[i] = jbias * sign[i]
    return total
