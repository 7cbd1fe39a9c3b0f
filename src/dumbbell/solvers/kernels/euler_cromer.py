"""The step of ``euler-cromer``: Euler-Cromer (1D) in the textbook listing's operation order.

The arithmetic and its order are the solver's contract (with the driver's flip at the floor,
it reproduces the textbook listing's floats bit for bit): change them only on purpose.
Imported only when the solver runs, so ``import dumbbell`` does not load numba.
"""

from __future__ import annotations

from . import Kernel


def step(s, p):  # pragma: no cover - compiled
    dt, mA, mB, k, b, g = p.dt, p.mA, p.mB, p.k, p.b, p.g
    xA, vA, xB, vB = s
    f = k * (xA - xB - b)
    fA = -f - mA * g
    fB = f - mB * g
    aA = fA / mA
    vA = vA + aA * dt
    xA = xA + vA * dt
    aB = fB / mB
    vB = vB + aB * dt
    xB = xB + vB * dt
    return (xA, vA, xB, vB)


#: The textbook's step; the driver flips velocities at the floor as the listing does.
KERNEL = Kernel(step)
