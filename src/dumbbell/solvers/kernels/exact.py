"""The numba kernels of ``exact``: the impact searches and the samplings of its closed forms.

:mod:`dumbbell.solvers.exact` (1D) and :mod:`dumbbell.solvers.exact_rigid` (the rigid 2D
dumbbell) explain the method and why no impact can be missed; this module is their
arithmetic, compiled. The floats are the contract: every operation, its order and its
library call (``math.cos``, ``math.sqrt``, Python's own ``math.hypot`` algorithm, scipy's
``brentq`` iteration) reproduce the pure-Python and numpy evaluation this solver was defined
by, bit for bit, so that impact times and samples do not depend on whether the search runs
compiled. Change them only on purpose. Imported only when the solver runs, so
``import dumbbell`` does not load numba.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..._install import njit

#: Search status codes: the run ended at ``t_end``; a particle came to rest on the floor; the
#: impact budget or the search's work budget was reached; the root finder failed.
DONE, REST, IMPACT_LIMIT, OVER_BUDGET, ROOT_FAILED = 0, 1, 2, 3, 4
#: Bodies, as the kernels number them.
A, B = 0, 1
#: Columns of a segment row: start time (s), centre of mass X0 (m), V0 (m/s), stretch s0 (m)
#: and its rate sd0 (m/s).
T0, X0, V0, S0, SD0 = 0, 1, 2, 3, 4

_DBL_MIN = 2.2250738585072014e-308
_SPLITTER = 134217729.0  # 2**27 + 1: Veltkamp's split of a double into two halves
#: Intervals scanned per block, and the stack of intervals a search may hold.
_BLOCK = 64
_STACK = 256
#: scipy's brentq: iterations, and its relative tolerance 4 * machine epsilon.
_BRENT_ITER = 100
_BRENT_RTOL = 4 * np.finfo(float).eps


class Motion(NamedTuple):
    """The scalars of the closed-form motion, in one record (a typed tuple to numba)."""

    g: float  #: gravitational acceleration (m/s^2)
    w: float  #: angular frequency of the stretch, sqrt(k / mu) (rad/s)
    w2: float  #: ``w**2`` as Python computes it (1/s^2)
    cA: float  #: mB / M: xA = X + cA (b + s)
    cB: float  #: mA / M: xB = X - cB (b + s)
    b: float  #: rest length (m)
    e: float  #: the floor's elasticity
    xtol: float  #: root tolerance of impact times (s)
    min_split: float  #: intervals shorter than this (s) are not split
    rest_speed: float  #: an impact slower than this (m/s) is a particle at rest


@njit(cache=True, nogil=True)
def _two_product(x, y):  # pragma: no cover
    """x * y rounded, and its exact rounding error (Veltkamp-Dekker)."""
    z = x * y
    c = _SPLITTER * x
    xh = c - (c - x)
    xl = x - xh
    c = _SPLITTER * y
    yh = c - (c - y)
    yl = y - yh
    return z, ((xh * yh - z) + xh * yl + xl * yh) + xl * yl


@njit(cache=True, nogil=True)
def hypot(x, y):  # pragma: no cover
    """``math.hypot(x, y)`` to the last bit: CPython's (3.10 and later) scaled, compensated sum
    of squares with a corrected square root. The C library's ``hypot``, which numba calls,
    differs from it in the last bit for about one argument pair in 400."""
    x = abs(x)
    y = abs(y)
    biggest = max(y, x)
    if math.isinf(x) or math.isinf(y):
        return math.inf
    if math.isnan(x) or math.isnan(y):
        return math.nan
    if biggest == 0.0:
        return biggest
    factor = 1.0
    _, e = math.frexp(biggest)
    if e < -1023:  # subnormal: scale up first, as CPython does
        x /= _DBL_MIN
        y /= _DBL_MIN
        factor = _DBL_MIN
        _, e = math.frexp(biggest / _DBL_MIN)
    scale = math.ldexp(1.0, -e)
    csum = 1.0
    frac1 = 0.0
    frac2 = 0.0
    for v in (x, y):
        v *= scale
        hi, lo = _two_product(v, v)
        total = csum + hi
        frac2 += (csum - total) + hi
        csum = total
        frac1 += lo
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    hi, lo = _two_product(-h, h)
    total = csum + hi
    frac2 += (csum - total) + hi
    csum = total
    frac1 += lo
    h += (csum - 1.0 + (frac1 + frac2)) / (2.0 * h)
    return factor * (h / scale)


@njit(cache=True, nogil=True)
def _np_min(x, y):  # pragma: no cover
    """``np.minimum(x, y)``: a NaN wins (numba's ``min`` is Python's, where it need not)."""
    if math.isnan(x):
        return x
    if math.isnan(y):
        return y
    return min(y, x)


@njit(cache=True, nogil=True)
def state(seg, tau, m):  # pragma: no cover
    """xA, vA, xB, vB (m, m/s) at ``tau`` (s) after the start of segment ``seg``, as numpy
    evaluates the closed form on an array of times."""
    X = seg[X0] + seg[V0] * tau - 0.5 * m.g * tau * tau
    V = seg[V0] - m.g * tau
    if m.w > 0:
        cos = math.cos(m.w * tau)
        sin = math.sin(m.w * tau)
        s = seg[S0] * cos + (seg[SD0] / m.w) * sin
        sd = -seg[S0] * m.w * sin + seg[SD0] * cos
    else:
        s = seg[S0] + seg[SD0] * tau
        sd = seg[SD0] + 0.0 * tau
    return (X + m.cA * (m.b + s), V + m.cA * sd, X - m.cB * (m.b + s), V - m.cB * sd)


@njit(cache=True, nogil=True)
def _height(seg, body, tau, m):  # pragma: no cover
    """Height (m) and vertical velocity (m/s) of ``body`` at one time: :func:`state`'s. (The
    scalar evaluation the search was written with differs without a spring, in the sign of a
    zero rate, which no decision of the search can see.)"""
    xA, vA, xB, vB = state(seg, tau, m)
    return (xA, vA) if body == A else (xB, vB)


@njit(cache=True, nogil=True)
def _fall_point(args, tau):  # pragma: no cover
    """:func:`_height` for the searches; ``args`` = (seg, body, m)."""
    return _height(args[0], args[1], tau, args[2])


@njit(cache=True, nogil=True)
def _fall(args, tau):  # pragma: no cover
    """The height (m) of :func:`_height`, for :func:`brentq_of`; ``args`` = (seg, body, m)."""
    return _height(args[0], args[1], tau, args[2])[0]


@njit(cache=True, nogil=True)
def amplitude(seg, m):  # pragma: no cover
    """Largest |s| the segment reaches (m); inf without a spring."""
    return hypot(seg[S0], seg[SD0] / m.w) if m.w > 0 else math.inf


@njit(cache=True, nogil=True)
def _earliest(seg, body, m):  # pragma: no cover
    """No impact of ``body`` before this time (s after the segment's start): its height stays
    within c*S of the centre-of-mass curve, which must first fall to that level."""
    S = amplitude(seg, m)
    if not math.isfinite(S):
        return 0.0
    level = m.cB * (m.b + S) if body == B else m.cA * (S - m.b)
    gap = seg[X0] - level
    if gap <= 0:
        return 0.0
    V = seg[V0]
    if m.g > 0:
        return (V + math.sqrt(V * V + 2.0 * m.g * gap)) / m.g
    return gap / -V if V < 0 else math.inf


@njit(cache=True, nogil=True)
def _brent_ends(xpre, fpre, xcur, fcur):  # pragma: no cover
    """scipy's ``brentq`` on the values at the ends: (done, root, ok), done where it stops
    there (a NaN value, a root at an end, no sign change)."""
    if math.isnan(fpre):
        return True, xpre, False
    if math.isnan(fcur):
        return True, xcur, False
    if fpre == 0:
        return True, xpre, True
    if fcur == 0:
        return True, xcur, True
    if math.copysign(1.0, fpre) == math.copysign(1.0, fcur):
        return True, 0.0, False
    return False, 0.0, True


@njit(cache=True, nogil=True)
def _brent_bracket(s):  # pragma: no cover
    """An iteration's start: the state ``s`` = (xpre, xcur, xblk, fpre, fcur, fblk, spre,
    scur) with [xcur, xblk] around the root and xcur the end nearer to it."""
    xpre, xcur, xblk, fpre, fcur, fblk, spre, scur = s
    if fpre != 0 and fcur != 0 and math.copysign(1.0, fpre) != math.copysign(1.0, fcur):
        xblk = xpre
        fblk = fpre
        spre = scur = xcur - xpre
    if abs(fblk) < abs(fcur):
        xpre = xcur
        xcur = xblk
        xblk = xpre
        fpre = fcur
        fcur = fblk
        fblk = fpre
    return (xpre, xcur, xblk, fpre, fcur, fblk, spre, scur)


@njit(cache=True, nogil=True)
def _brent_step(s, delta, sbis):  # pragma: no cover
    """The next (spre, scur) of the state ``s``: an interpolated or extrapolated step when
    it is short enough, else the bisection ``sbis``."""
    xpre, xcur, xblk, fpre, fcur, fblk, spre, scur = s
    if not (abs(spre) > delta and abs(fcur) < abs(fpre)):
        return sbis, sbis
    if xpre == xblk:
        stry = -fcur * (xcur - xpre) / (fcur - fpre)  # interpolate
    else:
        dpre = (fpre - fcur) / (xpre - xcur)  # extrapolate
        dblk = (fblk - fcur) / (xblk - xcur)
        stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
    if 2 * abs(stry) < min(3 * abs(sbis) - delta, abs(spre)):  # C's MIN(|spre|, ...)
        return scur, stry  # a good short step
    return sbis, sbis


@njit(cache=True, nogil=True)
def _brent_move(xcur, scur, delta, sbis):  # pragma: no cover
    """The next point: ``xcur`` moved by the step ``scur``, by at least ``delta``."""
    if abs(scur) > delta:
        return xcur + scur
    return xcur + (delta if sbis > 0 else -delta)


def brentq_of(f):
    """scipy's ``brentq`` (its C iteration, step for step) on ``f(args, x)``, compiled for this
    one ``f`` (a function passed as an argument would keep numba from caching its callers):
    ``brentq(args, xa, xb, xtol)`` is (root, ok), with rtol 4 eps; not ok where scipy raises
    (a NaN value, no sign change, no convergence in 100 iterations)."""

    @njit(cache=True, nogil=True)
    def brentq(args, xa, xb, xtol):  # pragma: no cover
        fpre = f(args, xa)
        fcur = f(args, xb)
        done, root, ok = _brent_ends(xa, fpre, xb, fcur)
        if done:
            return root, ok
        s = (xa, xb, 0.0, fpre, fcur, 0.0, 0.0, 0.0)
        for _ in range(_BRENT_ITER):
            s = _brent_bracket(s)
            xcur, xblk, fcur = s[1], s[2], s[4]
            delta = (xtol + _BRENT_RTOL * abs(xcur)) / 2
            sbis = (xblk - xcur) / 2
            if fcur == 0 or abs(sbis) < delta:
                return xcur, True
            spre, scur = _brent_step(s, delta, sbis)
            xnew = _brent_move(xcur, scur, delta, sbis)
            fnew = f(args, xnew)
            if math.isnan(fnew):
                return xnew, False
            s = (xcur, xnew, xblk, fcur, fnew, s[5], spre, scur)
        return s[1], False

    return brentq


#: :func:`brentq_of` the falling particle's height (:func:`_fall`).
brentq_fall = brentq_of(_fall)


#: What an interval of a height search holds: no crossing, a crossing (found), or unknown.
CLEARED, FOUND, SPLIT = 0, 1, 2


def search_of(point, judge):
    """The depth-first search of one suspect interval, compiled for one height curve:
    ``point(args, tau)`` is (height, rate) at ``tau``; ``judge(args, left, right, C)`` says
    what [lo, hi] holds (``left`` = (lo, height, rate) at lo, ``right`` the same at hi), as
    (:data:`CLEARED`, :data:`FOUND` or :data:`SPLIT`, root, status). Unknown intervals are
    split at their middle, the left half searched first, each split one unit of ``work`` =
    [spent, allowed]. ``search(args, left, right, C, budget)`` is (first root or inf,
    status); ``budget`` = (work, block_work, stack), the stack of intervals it may hold."""

    @njit(cache=True, nogil=True)
    def search(args, left, right, C, budget):  # pragma: no cover
        work, stack = budget[0], budget[2]
        lo, flo, dlo = left
        hi, fhi, dhi = right
        stack[0, 0], stack[0, 1], stack[0, 2] = lo, flo, dlo
        stack[0, 3], stack[0, 4], stack[0, 5] = hi, fhi, dhi
        top = 1
        while top > 0:
            top -= 1
            lo, flo, dlo = stack[top, 0], stack[top, 1], stack[top, 2]
            hi, fhi, dhi = stack[top, 3], stack[top, 4], stack[top, 5]
            kind, root, status = judge(args, (lo, flo, dlo), (hi, fhi, dhi), C)
            if kind == FOUND:
                return root, status
            if kind == CLEARED:
                continue
            work[0] += 1
            if work[0] > work[1]:
                return math.inf, OVER_BUDGET
            if top + 2 > stack.shape[0]:
                return math.inf, ROOT_FAILED
            mid = 0.5 * (lo + hi)
            fmid, dmid = point(args, mid)
            # The right half waits below the left one.
            stack[top, 0], stack[top, 1], stack[top, 2] = mid, fmid, dmid
            stack[top, 3], stack[top, 4], stack[top, 5] = hi, fhi, dhi
            stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2] = lo, flo, dlo
            stack[top + 1, 3], stack[top + 1, 4], stack[top + 1, 5] = mid, fmid, dmid
            top += 2
        return math.inf, DONE

    return search


def scan_of(point, search):
    """The scan for a first root, compiled for one height curve (``point`` and ``search`` as
    for :func:`search_of`): ``scan(args, grid, C, budget)`` walks ``grid`` = (lo, stop, h),
    [lo, stop] in blocks of 64 intervals of ``h`` (``block_work`` units of ``work`` each,
    ``budget`` = (work, block_work, stack)), clears an interval whose ends lie above the floor
    by more than its dip below the chord (at most C h^2 / 8), searches the others in order,
    and returns the first root (or inf) and a status. A block's points are evaluated as the
    scan reaches them: an interval's verdict reads its two ends only, and the scan stops at
    the first root."""

    @njit(cache=True, nogil=True)
    def scan(args, grid, C, budget):  # pragma: no cover
        lo, stop, h = grid
        work, block_work = budget[0], budget[1]
        taus = np.empty(_BLOCK + 1)
        fs = np.empty(_BLOCK + 1)
        ds = np.empty(_BLOCK + 1)
        while lo < stop:
            work[0] += block_work
            if work[0] > work[1]:
                return math.inf, OVER_BUDGET
            for k in range(_BLOCK + 1):
                taus[k] = _np_min(lo + h * k, stop)
                fs[k], ds[k] = point(args, taus[k])
                if k == 0:
                    continue
                j = k - 1
                width = taus[k] - taus[j]
                lower = _np_min(fs[j], fs[k]) - C * width * width / 8.0
                if lower <= 0 and width > 0:
                    root, status = search(args, (taus[j], fs[j], ds[j]),
                                          (taus[k], fs[k], ds[k]), C, budget)
                    if status != DONE or root < math.inf:
                        return root, status
            lo = taus[_BLOCK]
        return math.inf, DONE

    return scan


@njit(cache=True, nogil=True)
def _fall_judge(args, left, right, C):  # pragma: no cover
    """What [lo, hi] holds of the particle's downward crossing (``args`` = (seg, body, m);
    ``left`` = (lo, height, rate) at lo, ``right`` at hi): cleared (above the floor by more
    than the dip C h^2/8), one crossing (strictly decreasing, as min(rate) + C h < 0 proves:
    refined by Brent's method), or, below ``m.min_split``, a crossing at ``hi`` if it is at
    or below the floor."""
    lo, flo, dlo = left
    hi, fhi, dhi = right
    width = hi - lo
    if flo > 0 and fhi > 0 and min(flo, fhi) - C * width * width / 8.0 > 0:
        return CLEARED, math.inf, DONE
    if flo > 0 and fhi <= 0 and min(dlo, dhi) + C * width < 0:
        root, ok = brentq_fall(args, lo, hi, args[2].xtol)
        return FOUND, root, DONE if ok else ROOT_FAILED
    if width < args[2].min_split:
        return (FOUND, hi, DONE) if fhi <= 0 else (CLEARED, math.inf, DONE)
    return SPLIT, math.inf, DONE


_fall_scan = scan_of(_fall_point, search_of(_fall_point, _fall_judge))


@njit(cache=True, nogil=True)
def first_root(seg, body, window, m, budget):  # pragma: no cover
    """First time in ``window`` = (start, stop] (s after the segment's start) at which
    ``body`` crosses the floor going down, or inf, and a status: the scan (:func:`scan_of`,
    ``budget`` as there) in steps of a sixteenth of a period (at most 0.05 s) from the
    earliest possible time."""
    start, stop = window
    S = amplitude(seg, m)
    c = m.cB if body == B else m.cA
    C = m.g + (c * m.w2 * S if m.w > 0 else 0.0)
    period = 2 * math.pi / m.w if m.w > 0 else math.inf
    h = min(period / 16.0, 0.05)
    a = max(start, _earliest(seg, body, m))
    return _fall_scan((seg, body, m), (a, stop, h), C, budget)


@njit(cache=True, nogil=True)
def _grow(rows, count):  # pragma: no cover
    """``rows`` with room for twice as many, its first ``count`` rows kept. (Element by
    element: a slice assignment would compile numba's shape-mismatch error path, seconds.)"""
    bigger = np.empty((2 * rows.shape[0], rows.shape[1]))
    for i in range(count):
        for j in range(rows.shape[1]):
            bigger[i, j] = rows[i, j]
    return bigger


@njit(cache=True, nogil=True)
def impacts(first, m, limits, floor):  # pragma: no cover
    """The free-flight segments from the segment ``first`` up to ``t_end`` (s) and the impacts
    between them: (segments, impacts, status, rest, work). Segment rows as ``first``
    (:data:`T0`...:data:`SD0`); impact rows (t, body, v_before, v_after); ``rest`` the row of
    the impact a particle came to rest at (status :data:`REST`); ``work`` the search work spent.
    ``limits`` = (t_end, max_impacts, work_limit, block_work): the search ends at ``t_end``,
    at rest, after ``max_impacts`` impacts or ``work_limit`` units of search work (a block of
    the scan costs ``block_work``). Without a ``floor``, the one segment."""
    t_end, max_impacts, work_limit, block_work = limits
    segs = np.empty((32, 5))
    for j in range(5):
        segs[0, j] = first[j]
    n_seg = 1
    events = np.empty((32, 4))
    n_ev = 0
    rest = np.empty(4)
    work = np.empty(2)
    work[0] = 0.0
    work[1] = work_limit
    budget = (work, block_work, np.empty((_STACK, 6)))
    if not floor:
        return segs[:1], events[:0], DONE, rest, work[0]
    starts = np.zeros(2)
    roots = np.empty(2)
    while n_ev < max_impacts:
        seg = segs[n_seg - 1]
        horizon = t_end - seg[T0]
        status = _first_roots(seg, m, horizon, budget, (starts, roots))
        if status != DONE:
            return segs[:n_seg], events[:n_ev], status, rest, work[0]
        tau = min(roots[A], roots[B])
        if not tau <= horizon:
            return segs[:n_seg], events[:n_ev], DONE, rest, work[0]
        xA, vA, xB, vB = state(seg, tau, m)
        t_hit = seg[T0] + tau
        hit_a = roots[A] - tau <= m.xtol * 10
        hit_b = roots[B] - tau <= m.xtol * 10
        if n_ev + 2 > events.shape[0]:
            events = _grow(events, n_ev)
        n_ev, vA, vB, at_rest = _bounce(events, n_ev, (t_hit, hit_a, hit_b, vA, vB), m, rest)
        if at_rest:
            return segs[:n_seg], events[:n_ev], REST, rest, work[0]
        if n_seg + 1 > segs.shape[0]:
            segs = _grow(segs, n_seg)
        _restart(segs[n_seg], (t_hit, xA, vA, xB, vB), m, (hit_a, hit_b, horizon), starts)
        n_seg += 1
    return segs[:n_seg], events[:n_ev], IMPACT_LIMIT, rest, work[0]


@njit(cache=True, nogil=True, inline="always")
def _first_roots(seg, m, horizon, budget, ends):  # pragma: no cover
    """Each body's first downward crossing of the floor in (start, ``horizon``] of ``seg``
    into ``roots`` (``ends`` = (starts, roots), by body), and the search's status."""
    starts, roots = ends
    for body in range(2):  # one call site: each is compiled in full
        root, status = first_root(seg, body, (starts[body], horizon), m, budget)
        if status != DONE:
            return status
        roots[body] = root
    return DONE


@njit(cache=True, nogil=True, inline="always")
def _bounce(events, n_ev, hit, m, rest):  # pragma: no cover
    """The bodies that hit the floor (``hit`` = (t, hit_a, hit_b, vA, vB)) bounce: each
    impact is a row of ``events`` from ``n_ev`` on, unless the body is at rest (its row then
    goes to ``rest``). Returns (impacts now, vA, vB after, at rest)."""
    t_hit, hit_a, hit_b, vA, vB = hit
    for body in range(2):
        if not (hit_a if body == A else hit_b):
            continue
        v = vA if body == A else vB
        if abs(v) < m.rest_speed:
            rest[0], rest[1], rest[2], rest[3] = t_hit, body, v, v
            return n_ev, vA, vB, True
        after = -m.e * v
        if body == A:
            vA = after
        else:
            vB = after
        events[n_ev, 0], events[n_ev, 1], events[n_ev, 2], events[n_ev, 3] = (
            t_hit, body, v, after)
        n_ev += 1
    return n_ev, vA, vB, False


@njit(cache=True, nogil=True, inline="always")
def _restart(new, after, m, hits, starts):  # pragma: no cover
    """The segment row ``new`` from the state ``after`` = (t, xA, vA, xB, vB) of the
    impacts, and into ``starts`` when each body may next cross (``hits`` = (hit_a, hit_b,
    horizon))."""
    t_hit, xA, vA, xB, vB = after
    hit_a, hit_b, horizon = hits
    mA_M, mB_M = m.cB, m.cA
    new[T0] = t_hit
    new[X0] = mA_M * xA + mB_M * xB
    new[V0] = mA_M * vA + mB_M * vB
    new[S0] = xA - xB - m.b
    new[SD0] = vA - vB
    C = m.g + max(m.cA, m.cB) * m.w2 * amplitude(new, m)
    # After an impact the particle is on the floor moving up: no new root before v_up / C.
    starts[A] = (vA / C if hit_a and C > 0 else 0.0)
    if hit_a and C == 0:
        starts[A] = horizon  # a straight line up, never to return
    starts[B] = (vB / C if hit_b and C > 0 else 0.0)
    if hit_b and C == 0:
        starts[B] = horizon


@njit(cache=True, nogil=True)
def sample(segs, t, m):  # pragma: no cover
    """xA, vA, xB, vB (rows, m and m/s) at the sorted times ``t`` (s), each from the last
    segment that starts at or before it (the first segment for earlier times)."""
    out = np.empty((4, t.shape[0]))
    k = 0
    last = segs.shape[0] - 1
    for i in range(t.shape[0]):
        while k < last and segs[k + 1, T0] <= t[i]:
            k += 1
        out[0, i], out[1, i], out[2, i], out[3, i] = state(segs[k], t[i] - segs[k, T0], m)
    return out


# --- the rigid 2D dumbbell (:mod:`dumbbell.solvers.exact_rigid`) ----------------------------


class End(NamedTuple):
    """One end of the rigid dumbbell over one segment, as its height search reads it."""

    arm: float  #: signed arm a (m): the end's height is Y + a sin(theta)
    omega: float  #: angular velocity (rad/s)
    theta: float  #: axis angle at the segment's start (rad)
    VY: float  #: vertical velocity of the centre of mass at the start (m/s)
    g: float  #: gravitational acceleration (m/s^2)
    h0: float  #: the end's height at the start (m)


@njit(cache=True, nogil=True)
def end_height(end, tau):  # pragma: no cover
    """Height (m) and vertical velocity (m/s) of the end ``end`` at ``tau`` (s) after the
    segment's start, relative to its start: ``a (sin(theta) - sin(theta0))`` written as
    ``2 a cos(theta0 + w tau / 2) sin(w tau / 2)``."""
    a, w, theta, VY, g, h0 = end
    half = 0.5 * w * tau
    y = (h0 + VY * tau - 0.5 * g * tau * tau
         + 2.0 * a * math.cos(theta + half) * math.sin(half))
    return y, VY - g * tau + a * w * math.cos(theta + w * tau)


@njit(cache=True, nogil=True)
def _end_point(args, tau):  # pragma: no cover
    """:func:`end_height` for the searches; ``args`` = (end, D, xtol, min_split)."""
    return end_height(args[0], tau)


@njit(cache=True, nogil=True)
def _end_y(end, tau):  # pragma: no cover
    """The height of :func:`end_height`, for :func:`brentq_of`."""
    return end_height(end, tau)[0]


@njit(cache=True, nogil=True)
def _end_v(end, tau):  # pragma: no cover
    """The vertical velocity of :func:`end_height`, for :func:`brentq_of`."""
    return end_height(end, tau)[1]


_brentq_end_y = brentq_of(_end_y)
_brentq_end_v = brentq_of(_end_v)


@njit(cache=True, nogil=True)
def _end_judge(args, left, right, C):  # pragma: no cover
    """What [lo, hi] holds of the end's first contact, moving down (``args`` = (end, D, xtol,
    min_split)): as :func:`_fall_judge`, and besides: an end already at the floor moving down
    at ``lo`` touches there; an interval on which the height is provably convex
    (``|y'''| <= D``) and the velocity changes sign holds one minimum, found as the root of
    the velocity, and the end touches the floor iff that minimum is <= 0."""
    end, D, xtol, min_split = args
    lo, flo, dlo = left
    hi, fhi, dhi = right
    if flo <= 0 and dlo < 0:
        return FOUND, lo, DONE  # at the floor moving down already (see exact_rigid)
    width = hi - lo
    if flo > 0 and fhi > 0 and min(flo, fhi) - C * width * width / 8.0 > 0:
        return CLEARED, math.inf, DONE
    if flo > 0 and fhi <= 0 and min(dlo, dhi) + C * width < 0:
        root, ok = _brentq_end_y(end, lo, hi, xtol)
        return FOUND, root, DONE if ok else ROOT_FAILED
    if flo > 0 and fhi > 0 and dlo < 0 < dhi and (dhi - dlo) - D * width * width / 4 > 0:
        t_min, ok = _brentq_end_v(end, lo, hi, xtol)
        if not ok:
            return FOUND, t_min, ROOT_FAILED
        if end_height(end, t_min)[0] > 0:
            return CLEARED, math.inf, DONE
        root, ok = _brentq_end_y(end, lo, t_min, xtol)
        return FOUND, root, DONE if ok else ROOT_FAILED
    if width < min_split:
        return (FOUND, hi, DONE) if flo > 0 and fhi <= 0 else (CLEARED, math.inf, DONE)
    return SPLIT, math.inf, DONE


_end_scan = scan_of(_end_point, search_of(_end_point, _end_judge))


@njit(cache=True, nogil=True)
def end_contact(end, grid, bounds, budget):  # pragma: no cover
    """First time in [lo, stop] (s after the segment's start) at which ``end`` reaches the
    floor moving down, or inf, and a status: the scan (:func:`scan_of`) of ``grid`` = (lo,
    stop, h) in steps of ``h``; ``bounds`` = (C, D, xtol, min_split): C and D bounds on the
    height's second and third derivatives, the root tolerance (s) and the shortest interval
    split (s); ``budget`` = (work, block_work) as for :func:`scan_of`."""
    C, D, xtol, min_split = bounds
    return _end_scan((end, D, xtol, min_split), grid, C,
                     (budget[0], budget[1], np.empty((_STACK, 6))))


@njit(cache=True, nogil=True)
def rigid_sample(segs, t, arm_a, arm_b, g):  # pragma: no cover
    """xA, yA, vxA, vyA, xB, yB, vxB, vyB (m, m/s) and omega (rad/s), as rows, at the sorted
    times ``t`` (s), each from the last segment (rows t, X, Y, VX, VY, theta, omega) that
    starts at or before it (the first for earlier times)."""
    out = np.empty((9, t.shape[0]))
    k = 0
    last = segs.shape[0] - 1
    for i in range(t.shape[0]):
        while k < last and segs[k + 1, 0] <= t[i]:
            k += 1
        t0, X0, Y0, VX, VY0, theta0, omega = segs[k, 0], segs[k, 1], segs[k, 2], \
            segs[k, 3], segs[k, 4], segs[k, 5], segs[k, 6]
        tau = t[i] - t0
        X = X0 + VX * tau
        Y = Y0 + VY0 * tau - 0.5 * g * tau * tau
        VY = VY0 - g * tau
        th = theta0 + omega * tau
        cos = math.cos(th)
        sin = math.sin(th)
        for row, a in ((0, arm_a), (4, arm_b)):
            out[row, i] = X + a * cos
            out[row + 1, i] = Y + a * sin
            out[row + 2, i] = VX - omega * a * sin + 0.0 * tau
            out[row + 3, i] = VY + omega * a * cos
        out[8, i] = omega
    return out
