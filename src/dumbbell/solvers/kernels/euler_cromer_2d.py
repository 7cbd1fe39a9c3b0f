"""The step of ``euler-cromer-2d``: 2D Euler-Cromer in pymunk's step order.

The arithmetic and its order are the solver's contract: change them only on purpose.
Imported only when the solver runs, so ``import dumbbell`` does not load numba.
"""

from __future__ import annotations

import math

from . import Kernel


def step(s, p):  # pragma: no cover - compiled
    dt, mA, mB, k, b, g, e, floor = p.dt, p.mA, p.mB, p.k, p.b, p.g, p.e, p.floor
    xA, yA, vxA, vyA, xB, yB, vxB, vyB = s
    invA = 1.0 / mA
    invB = 1.0 / mB
    # 1. positions
    xA = xA + vxA * dt
    yA = yA + vyA * dt
    xB = xB + vxB * dt
    yB = yB + vyB * dt
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
    # 5. contact impulses, at the end of the step
    if hitA:
        vyA = -e * vyA_pre
    if hitB:
        vyB = -e * vyB_pre
    return ((xA, yA, vxA, vyA, xB, yB, vxB, vyB),
            (hitA, vyA_pre, vyA, hitB, vyB_pre, vyB))


#: pymunk's order: contacts found at the new positions, their impulse applied last; a
#: circle is caught while it overlaps the floor, so it is through only a radius below it.
KERNEL = Kernel(step, floor="end", through_at_radius=True)
