"""The numba kernel of ``euler-cromer``: Euler-Cromer (1D) in the textbook listing's operation order.

The arithmetic and its order are the solver's contract (the 1D Euler-Cromer kernel
reproduces the textbook listing's floats bit for bit): change them only on purpose.
Imported only when the solver runs, so ``import dumbbell`` does not load numba.
"""

from __future__ import annotations

from ..._install import njit
from . import BIG, BLOWUP, OK, TUNNEL_A, TUNNEL_B


@njit(cache=True, nogil=True)
def advance(st, i, i_stop, p, every, out, ev):  # pragma: no cover
    dt, mA, mB, k, b, g, e, floor, _, _ = p
    xA = st[0]
    vA = st[1]
    xB = st[2]
    vB = st[3]
    n_ev = 0
    status = OK
    # A countdown to the next kept step: an integer modulo every step costs more than the step.
    until_sample = every - i % every
    while i < i_stop:
        xA_old = xA
        xB_old = xB
        f = k * (xA - xB - b)
        fA = -f - mA * g
        fB = f - mB * g
        aA = fA / mA
        vA = vA + aA * dt
        xA = xA + vA * dt
        aB = fB / mB
        vB = vB + aB * dt
        xB = xB + vB * dt
        i += 1
        if floor:
            if xB < 0.0 and xB_old >= 0.0:
                ev[n_ev, 0] = i
                ev[n_ev, 1] = 1.0
                ev[n_ev, 2] = vB
                vB = e * abs(vB)
                ev[n_ev, 3] = vB
                n_ev += 1
            elif xB < 0.0 and vB < 0.0:
                status = TUNNEL_B
            if xA < 0.0 and xA_old >= 0.0:
                ev[n_ev, 0] = i
                ev[n_ev, 1] = 0.0
                ev[n_ev, 2] = vA
                vA = e * abs(vA)
                ev[n_ev, 3] = vA
                n_ev += 1
            elif xA < 0.0 and vA < 0.0:
                status = TUNNEL_A
        if not (abs(xA) < BIG and abs(vA) < BIG and abs(xB) < BIG and abs(vB) < BIG):
            status = BLOWUP
        until_sample -= 1
        if until_sample == 0:
            until_sample = every
            j = i // every
            out[0, j] = xA
            out[1, j] = vA
            out[2, j] = xB
            out[3, j] = vB
        if status != OK or n_ev >= ev.shape[0] - 2:
            break
    st[0] = xA
    st[1] = vA
    st[2] = xB
    st[3] = vB
    return i, status, n_ev
