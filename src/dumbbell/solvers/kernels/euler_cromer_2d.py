"""The numba kernel of ``euler-cromer-2d``: 2D Euler-Cromer in pymunk's step order.

The arithmetic and its order are the solver's contract (the 1D Euler-Cromer kernel
reproduces the textbook listing's floats bit for bit): change them only on purpose.
Imported only when the solver runs, so ``import dumbbell`` does not load numba.
"""

from __future__ import annotations

import math

from ..._install import njit
from . import BIG, BLOWUP, OK, TUNNEL_A, TUNNEL_B


@njit(cache=True, nogil=True)
def advance(st, i, i_stop, p, every, out, ev):  # pragma: no cover
    dt, mA, mB, k, b, g, e, floor, rA, rB = p
    xA, yA, vxA, vyA, xB, yB, vxB, vyB = st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7]
    invA = 1.0 / mA
    invB = 1.0 / mB
    n_ev = 0
    status = OK
    while i < i_stop:
        # 1. positions
        xA = xA + vxA * dt
        yA = yA + vyA * dt
        xB = xB + vxB * dt
        yB = yB + vyB * dt
        i += 1
        # 2. contacts at the new positions; the bounce target uses the velocity before the step
        hitA = floor and yA < 0.0 and vyA < 0.0
        hitB = floor and yB < 0.0 and vyB < 0.0
        vyA_pre = vyA
        vyB_pre = vyB
        # 3. spring impulse (explicit, damping 0)
        if k > 0.0:
            dx = xB - xA
            dy = yB - yA
            dist = math.sqrt(dx * dx + dy * dy)
            inv = 1.0 / dist if dist != 0.0 else 0.0
            nx = dx * inv
            ny = dy * inv
            j = ((b - dist) * k) * dt
            vxA = vxA + (-nx * j) * invA
            vyA = vyA + (-ny * j) * invA
            vxB = vxB + (nx * j) * invB
            vyB = vyB + (ny * j) * invB
        # 4. gravity
        vxA = vxA + 0.0 * dt
        vyA = vyA + (-g) * dt
        vxB = vxB + 0.0 * dt
        vyB = vyB + (-g) * dt
        # 5. contact impulses
        if hitA:
            ev[n_ev, 0] = i
            ev[n_ev, 1] = 0.0
            ev[n_ev, 2] = vyA_pre
            vyA = -e * vyA_pre
            ev[n_ev, 3] = vyA
            n_ev += 1
        if hitB:
            ev[n_ev, 0] = i
            ev[n_ev, 1] = 1.0
            ev[n_ev, 2] = vyB_pre
            vyB = -e * vyB_pre
            ev[n_ev, 3] = vyB
            n_ev += 1
        if floor:
            if yA < -rA and vyA < 0.0:
                status = TUNNEL_A
            if yB < -rB and vyB < 0.0:
                status = TUNNEL_B
        if not (abs(xA) < BIG and abs(yA) < BIG and abs(vxA) < BIG and abs(vyA) < BIG
                and abs(xB) < BIG and abs(yB) < BIG and abs(vxB) < BIG and abs(vyB) < BIG):
            status = BLOWUP
        if i % every == 0:
            jj = i // every
            out[jj, 0] = xA
            out[jj, 1] = yA
            out[jj, 2] = vxA
            out[jj, 3] = vyA
            out[jj, 4] = xB
            out[jj, 5] = yB
            out[jj, 6] = vxB
            out[jj, 7] = vyB
        if status != OK or n_ev >= ev.shape[0] - 2:
            break
    st[0], st[1], st[2], st[3] = xA, yA, vxA, vyA
    st[4], st[5], st[6], st[7] = xB, yB, vxB, vyB
    return i, status, n_ev
