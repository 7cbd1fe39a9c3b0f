"""The numba kernel of ``verlet``: velocity Verlet with impacts located inside the step (1D and 2D).

The arithmetic and its order are the solver's contract (the 1D Euler-Cromer kernel
reproduces the textbook listing's floats bit for bit): change them only on purpose.
Imported only when the solver runs, so ``import dumbbell`` does not load numba.
"""

from __future__ import annotations

import math

from ..._install import njit
from . import BIG, BLOWUP, OK, REST, TUNNEL_A, TUNNEL_B

#: An impact slower than this (m/s), or more impacts than MAX_HITS in one step, means a
#: particle has come to rest on the floor (the exact solver uses the same speed).
REST_SPEED = 1e-9
MAX_HITS = 64


@njit(cache=True, nogil=True)
def _first_root(c, b, a, h):  # pragma: no cover
    """First tau in (0, h] where c + b tau + a tau^2/2 reaches 0 going down; -1 if none.

    ``c`` is the height at tau = 0 (m), ``b`` the velocity (m/s), ``a`` the acceleration."""
    if c <= 0.0:
        # On (or, by rounding, just under) the floor: an impact now if moving down; after a
        # reflection (b > 0) the quadratic returns to the floor at tau = -2b/a.
        if b < 0.0 or (b == 0.0 and a < 0.0):
            return 0.0
        if b > 0.0 and a < 0.0:
            tau = -2.0 * b / a
            if tau <= h:
                return tau
        return -1.0
    if c > h * (abs(b) + 0.5 * h * abs(a)):
        return -1.0  # too high to reach the floor within h: the common case, decided cheaply
    end = c + h * (b + 0.5 * a * h)
    if end > 0.0:
        # Both ends above the floor: a crossing needs a dip, i.e. a minimum inside the step.
        if a <= 0.0:
            return -1.0
        t_min = -b / a
        if not (0.0 < t_min < h) or c + t_min * (b + 0.5 * a * t_min) > 0.0:
            return -1.0
    half_a = 0.5 * a
    disc = b * b - 4.0 * half_a * c
    disc = max(disc, 0.0)  # a tangential touch, rounded
    if half_a == 0.0:
        tau = -c / b
    else:
        # Stable roots: q = -(b + sign(b) sqrt(disc))/2, roots q/half_a and c/q.
        sq = math.sqrt(disc)
        q = -0.5 * (b + sq) if b >= 0.0 else -0.5 * (b - sq)
        r1 = q / half_a
        r2 = c / q if q != 0.0 else r1
        lo = min(r1, r2)
        hi = max(r1, r2)
        tau = lo if lo > 0.0 else hi
    tau = min(tau, h)
    tau = max(tau, 0.0)
    return tau


@njit(cache=True, nogil=True)
def advance(st, i, i_stop, p, every, out, ev):  # pragma: no cover
    dt, mA, mB, k, b, g, e, floor, _, _ = p
    xA = st[0]
    vA = st[1]
    xB = st[2]
    vB = st[3]
    f = k * (xA - xB - b)
    aA = (-f - mA * g) / mA
    aB = (f - mB * g) / mB
    n_ev = 0
    status = OK
    while i < i_stop:
        rem = dt
        hits = 0
        while True:
            tau = rem + 1.0
            body = -1
            if floor:
                tA = _first_root(xA, vA, aA, rem)
                tB = _first_root(xB, vB, aB, rem)
                if tB >= 0.0:
                    tau = tB
                    body = 1
                if tA >= 0.0 and tA < tau:
                    tau = tA
                    body = 0
            h = rem if body < 0 else tau
            xA = xA + h * (vA + 0.5 * aA * h)
            xB = xB + h * (vB + 0.5 * aB * h)
            f = k * (xA - xB - b)
            aA_new = (-f - mA * g) / mA
            aB_new = (f - mB * g) / mB
            vA = vA + 0.5 * (aA + aA_new) * h
            vB = vB + 0.5 * (aB + aB_new) * h
            aA = aA_new
            aB = aB_new
            if body < 0:
                break
            rem = rem - h
            hits += 1
            # The root is where the step's own quadratic meets the floor: place it there
            # exactly, so rounding cannot leave it a hair below.
            v_in = vA if body == 0 else vB
            v_out = e * abs(v_in) if v_in < 0.0 else v_in
            ev[n_ev, 0] = i * dt + (dt - rem)
            ev[n_ev, 1] = body
            ev[n_ev, 2] = v_in
            ev[n_ev, 3] = v_out
            n_ev += 1
            if body == 0:
                xA = 0.0
                vA = v_out
            else:
                xB = 0.0
                vB = v_out
            f = k * (xA - xB - b)
            aA = (-f - mA * g) / mA
            aB = (f - mB * g) / mB
            if abs(v_in) < REST_SPEED or hits > MAX_HITS:
                status = REST
                break
        if status == REST:
            break
        i += 1
        if floor:
            if xA < 0.0 and vA < 0.0:
                status = TUNNEL_A
            if xB < 0.0 and vB < 0.0:
                status = TUNNEL_B
        if not (abs(xA) < BIG and abs(vA) < BIG and abs(xB) < BIG and abs(vB) < BIG):
            status = BLOWUP
        if i % every == 0:
            j = i // every
            out[j, 0] = xA
            out[j, 1] = vA
            out[j, 2] = xB
            out[j, 3] = vB
        # One step records at most MAX_HITS + 1 impacts: hand back while they still fit.
        if status != OK or n_ev >= ev.shape[0] - 2 * MAX_HITS:
            break
    st[0] = xA
    st[1] = vA
    st[2] = xB
    st[3] = vB
    return i, status, n_ev


@njit(cache=True, nogil=True)
def _accel_2d(xA, yA, xB, yB, p):  # pragma: no cover
    """Accelerations (m/s^2) of A and B from the spring along their axis and gravity, with
    the masses, spring and gravity of the record ``p``."""
    mA, mB, k, b, g = p.mA, p.mB, p.k, p.b, p.g
    dx = xA - xB
    dy = yA - yB
    L = math.sqrt(dx * dx + dy * dy)
    fx = 0.0
    fy = 0.0
    if k != 0.0 and L > 0.0:
        f = k * (L - b) / L  # tension per unit of separation
        fx = f * dx
        fy = f * dy
    return -fx / mA, -fy / mA - g, fx / mB, fy / mB - g


@njit(cache=True, nogil=True)
def advance_2d(st, i, i_stop, p, every, out, ev):  # pragma: no cover
    dt, e, floor = p.dt, p.e, p.floor
    xA, yA, vxA, vyA, xB, yB, vxB, vyB = st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7]
    axA, ayA, axB, ayB = _accel_2d(xA, yA, xB, yB, p)
    n_ev = 0
    status = OK
    while i < i_stop:
        rem = dt
        hits = 0
        while True:
            tau = rem + 1.0
            body = -1
            if floor:
                tA = _first_root(yA, vyA, ayA, rem)
                tB = _first_root(yB, vyB, ayB, rem)
                if tB >= 0.0:
                    tau = tB
                    body = 1
                if tA >= 0.0 and tA < tau:
                    tau = tA
                    body = 0
            h = rem if body < 0 else tau
            xA = xA + h * (vxA + 0.5 * axA * h)
            yA = yA + h * (vyA + 0.5 * ayA * h)
            xB = xB + h * (vxB + 0.5 * axB * h)
            yB = yB + h * (vyB + 0.5 * ayB * h)
            nxA, nyA, nxB, nyB = _accel_2d(xA, yA, xB, yB, p)
            vxA = vxA + 0.5 * (axA + nxA) * h
            vyA = vyA + 0.5 * (ayA + nyA) * h
            vxB = vxB + 0.5 * (axB + nxB) * h
            vyB = vyB + 0.5 * (ayB + nyB) * h
            axA, ayA, axB, ayB = nxA, nyA, nxB, nyB
            if body < 0:
                break
            rem = rem - h
            hits += 1
            # A frictionless floor reverses only the vertical velocity.
            v_in = vyA if body == 0 else vyB
            v_out = e * abs(v_in) if v_in < 0.0 else v_in
            ev[n_ev, 0] = i * dt + (dt - rem)
            ev[n_ev, 1] = body
            ev[n_ev, 2] = v_in
            ev[n_ev, 3] = v_out
            n_ev += 1
            if body == 0:
                yA = 0.0
                vyA = v_out
            else:
                yB = 0.0
                vyB = v_out
            axA, ayA, axB, ayB = _accel_2d(xA, yA, xB, yB, p)
            if abs(v_in) < REST_SPEED or hits > MAX_HITS:
                status = REST
                break
        if status == REST:
            break
        i += 1
        if floor:
            if yA < 0.0 and vyA < 0.0:
                status = TUNNEL_A
            if yB < 0.0 and vyB < 0.0:
                status = TUNNEL_B
        if not (abs(xA) < BIG and abs(yA) < BIG and abs(vxA) < BIG and abs(vyA) < BIG
                and abs(xB) < BIG and abs(yB) < BIG and abs(vxB) < BIG
                and abs(vyB) < BIG):
            status = BLOWUP
        if i % every == 0:
            j = i // every
            out[j, 0] = xA
            out[j, 1] = yA
            out[j, 2] = vxA
            out[j, 3] = vyA
            out[j, 4] = xB
            out[j, 5] = yB
            out[j, 6] = vxB
            out[j, 7] = vyB
        if status != OK or n_ev >= ev.shape[0] - 2 * MAX_HITS:
            break
    st[0], st[1], st[2], st[3] = xA, yA, vxA, vyA
    st[4], st[5], st[6], st[7] = xB, yB, vxB, vyB
    return i, status, n_ev
