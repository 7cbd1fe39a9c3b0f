"""The steps of ``verlet``: velocity Verlet with impacts located inside the step (1D and 2D).

The arithmetic and its order are the solver's contract: change them only on purpose. The
state carries the accelerations after the sampled columns, computed from the positions by
``start`` (the same operations as at the end of a step, so resuming changes no float).
Imported only when the solver runs, so ``import dumbbell`` does not load numba.
"""

from __future__ import annotations

import math

from ..._install import njit
from . import Kernel


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
def _first_impact(a, b, rem, floor):  # pragma: no cover - compiled
    """How long a step may go (s) and which particle meets the floor at its end: the first
    root in (0, ``rem``] of either particle's height (``a``, ``b``: height, vertical
    velocity, vertical acceleration of A and B), or the whole ``rem`` and -1 (none)."""
    tau = rem + 1.0
    body = -1
    if floor:
        tA = _first_root(a[0], a[1], a[2], rem)
        tB = _first_root(b[0], b[1], b[2], rem)
        if tB >= 0.0:
            tau = tB
            body = 1
        if tA >= 0.0 and tA < tau:
            tau = tA
            body = 0
    return (rem if body < 0 else tau), body


@njit(cache=True, nogil=True)
def _accel_1d(xA, xB, p):  # pragma: no cover - compiled
    """Accelerations (m/s^2) of A and B from the spring and gravity, with the masses, spring
    and gravity of the record ``p``."""
    f = p.k * (xA - xB - p.b)
    return (-f - p.mA * p.g) / p.mA, (f - p.mB * p.g) / p.mB


def start_1d(s, p):  # pragma: no cover - compiled
    aA, aB = _accel_1d(s[0], s[2], p)
    return (s[0], s[1], s[2], s[3], aA, aB)


def step_1d(s, p, rem):  # pragma: no cover - compiled
    """Velocity Verlet over ``rem`` s, or up to the first root in (0, rem] of either
    particle's height (returns the state, the time advanced and the body, -1 for none)."""
    xA, vA, xB, vB, aA, aB = s
    h, body = _first_impact((xA, vA, aA), (xB, vB, aB), rem, p.floor)
    xA = xA + h * (vA + 0.5 * aA * h)
    xB = xB + h * (vB + 0.5 * aB * h)
    aA_new, aB_new = _accel_1d(xA, xB, p)
    vA = vA + 0.5 * (aA + aA_new) * h
    vB = vB + 0.5 * (aB + aB_new) * h
    return (xA, vA, xB, vB, aA_new, aB_new), h, body


@njit(cache=True, nogil=True)
def _accel_2d(xA, yA, xB, yB, p):  # pragma: no cover - compiled
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


def start_2d(s, p):  # pragma: no cover - compiled
    axA, ayA, axB, ayB = _accel_2d(s[0], s[1], s[4], s[5], p)
    return (s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], axA, ayA, axB, ayB)


def step_2d(s, p, rem):  # pragma: no cover - compiled
    """:func:`step_1d` in 2D: the roots of the heights; the spring along the axis."""
    xA, yA, vxA, vyA, xB, yB, vxB, vyB, axA, ayA, axB, ayB = s
    h, body = _first_impact((yA, vyA, ayA), (yB, vyB, ayB), rem, p.floor)
    xA = xA + h * (vxA + 0.5 * axA * h)
    yA = yA + h * (vyA + 0.5 * ayA * h)
    xB = xB + h * (vxB + 0.5 * axB * h)
    yB = yB + h * (vyB + 0.5 * ayB * h)
    nxA, nyA, nxB, nyB = _accel_2d(xA, yA, xB, yB, p)
    vxA = vxA + 0.5 * (axA + nxA) * h
    vyA = vyA + 0.5 * (ayA + nyA) * h
    vxB = vxB + 0.5 * (axB + nxB) * h
    vyB = vyB + 0.5 * (ayB + nyB) * h
    return (xA, yA, vxA, vyA, xB, yB, vxB, vyB, nxA, nyA, nxB, nyB), h, body


#: The steps in 1D and 2D: each stops at the impacts it locates, the roots of its quadratic.
KERNELS = {1: Kernel(step_1d, floor="locate", start=start_1d),
           2: Kernel(step_2d, floor="locate", start=start_2d)}
