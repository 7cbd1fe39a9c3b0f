"""The numba kernels of ``reference`` for 2D spring dumbbells: the 8th-order Runge-Kutta step
of Dormand and Prince on the relative state, and the loop that steps between impacts.

Not a stepper kernel (no ``advance``): :mod:`dumbbell.solvers.reference_2d` drives them and
says why they are exact enough. The arithmetic and its order decide the reference's floats:
change them only on purpose. Imported only when the solver runs, so ``import dumbbell``
does not load numba.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from scipy.integrate._ivp import dop853_coefficients as _dop

from ..._install import njit

_N = _dop.N_STAGES
_A = np.ascontiguousarray(_dop.A[:_N, :_N])
_B = np.ascontiguousarray(_dop.B)


class Span(NamedTuple):
    """What stays fixed from one impact (or searched step) to the next, for :func:`run`."""

    t0: float  #: start of the centre-of-mass segment (s)
    Y0: float  #: centre-of-mass height at t0 (m)
    VY0: float  #: centre-of-mass vertical velocity at t0 (m/s)
    hmax: float  #: longest step (s)
    g: float  #: gravitational acceleration (m/s^2)
    cA: float  #: mB / M: A's share of the relative vector
    cB: float  #: mA / M: B's share of it
    CA: float  #: bound on |A's height''| (m/s^2)
    CB: float  #: bound on |B's height''| (m/s^2)
    quietA: float  #: A cannot reach the floor before this time (s)
    quietB: float  #: B cannot reach the floor before this time (s)
    w2: float  #: k / mu (1/s^2)
    b: float  #: rest length (m)


@njit(cache=True, nogil=True)
def rhs(s, w2, b, out):  # pragma: no cover
    """d' and d'' of the relative state ``s = (d, d')`` into ``out``."""
    dx, dy = s[0], s[1]
    r = math.sqrt(dx * dx + dy * dy)
    f = -w2 * (r - b) / r if r > 0 else -w2
    out[0] = s[2]
    out[1] = s[3]
    out[2] = f * dx
    out[3] = f * dy


@njit(cache=True, nogil=True)
def step(s, h, w2, b, out):  # pragma: no cover
    """One DOP853 step of length ``h`` (s) from ``s`` into ``out``."""
    K = np.empty((_N, 4))
    tmp = np.empty(4)
    for i in range(_N):
        for c in range(4):
            acc = 0.0
            for j in range(i):
                acc += _A[i, j] * K[j, c]
            tmp[c] = s[c] + h * acc
        rhs(tmp, w2, b, K[i])
    for c in range(4):
        acc = 0.0
        for i in range(_N):
            acc += _B[i] * K[i, c]
        out[c] = s[c] + h * acc


@njit(cache=True, nogil=True)
def run(s, t, times, k, span, out, nxt):  # pragma: no cover
    """Step from (t, s) through the sample times ``times[k:]``, writing samples into
    ``out``; stop before a step whose ends do not clear the curvature margin of a particle
    (returns 1, with the step's end state and time in ``nxt``) or after the last sample
    (returns 0); also the time reached, the next sample index and the steps taken."""
    t0, Y0, VY0, hmax, g, cA, cB, CA, CB, quietA, quietB, w2, b = span
    new = np.empty(4)
    count = 0
    while k < times.size:
        target = times[k]
        if target > t:
            m = math.ceil((target - t) / hmax)
            h = (target - t) / m
            for j in range(m):
                t1 = target if j == m - 1 else t + h
                step(s, t1 - t, w2, b, new)
                count += 1
                ta, tb = t - t0, t1 - t0
                ya = Y0 + VY0 * ta - 0.5 * g * ta * ta
                yb = Y0 + VY0 * tb - 0.5 * g * tb * tb
                hh = t1 - t
                suspect = False
                margin = hh * hh / 8.0
                if t1 > quietA and min(ya + cA * s[1], yb + cA * new[1]) <= CA * margin:
                    suspect = True
                if t1 > quietB and min(ya - cB * s[1], yb - cB * new[1]) <= CB * margin:
                    suspect = True
                if suspect:
                    for c in range(4):
                        nxt[c] = new[c]
                    nxt[4] = t1
                    return 1, t, k, count
                for c in range(4):
                    s[c] = new[c]
                t = t1
        for c in range(4):
            out[k, c] = s[c]
        k += 1
    return 0, t, k, count
