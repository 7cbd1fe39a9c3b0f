"""The truth's own error: the exact solution evaluated again in extended precision.

numpy's ``longdouble`` (80-bit on x86: 64-bit mantissa) re-evaluates the same closed form,
impact times refined by Newton's method there, at the exact solver's sample times; the
differences are the exact solver's rounding and root-finding error. ``bench`` reports them
as the truth's own point.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import UsageError
from ..model import args
from ..model.trajectory import Trajectory

#: No public names: the closed-form truth behind the tests of the solvers.
__all__: list[str] = []


def _checked(traj: Any, window: Any, rigid: bool) -> tuple[Trajectory, float]:
    """A trajectory of the closed form's kind (1D, or the rigid 2D dumbbell) and a window
    > 0 (s), else a UsageError naming the argument."""
    traj = args.trajectory(traj)
    system = traj.scene.system
    fits = (system.dimensions == 2 and system.rigid is not None) if rigid else (
        system.dimensions == 1)
    if not fits:
        kind = "the rigid 2D dumbbell" if rigid else "a 1D scene"
        raise UsageError(f"traj: {traj.scene.source} is not {kind}; the closed form here is "
                         f"that of {kind}", param="traj")
    return traj, args.real(window, "window", "s")


def extended_precision_exact(traj: Trajectory, window: float) -> tuple[float, float]:
    """Largest position error (m) and impact time error (s) over [0, window] of an ``exact``
    trajectory against the same
    closed form evaluated in numpy's extended precision (80-bit on x86: 64-bit mantissa),
    with each impact time refined by Newton's method in that precision. It checks the
    rounding of the double-precision solution, given its sequence of impacts."""
    return _exact_error(*_checked(traj, window, rigid=False))


def _long(system: Any) -> tuple[Any, Any, Any, Any, Any]:
    """mA, mB (kg), g (m/s^2), M (kg) and the floor's elasticity of ``system`` in extended
    precision."""
    L = np.longdouble
    mA, mB = L(system.A.mass), L(system.B.mass)
    e = L(system.floor.elasticity) if system.floor else L(1)
    return mA, mB, L(system.g), mA + mB, e


def _exact_error(traj: Trajectory, window: float) -> tuple[float, float]:
    L = np.longdouble
    scene = traj.scene
    mA, mB, g, M, e = _long(scene.system)
    k = L(scene.system.spring.stiffness) if scene.system.spring else L(0)
    b = L(scene.system.spring.rest_length) if scene.system.spring else L(0)
    w = np.sqrt(k * M / (mA * mB))

    def state(seg, tau):
        _t0, X0, V0, s0, sd0 = seg
        X = X0 + V0 * tau - g * tau * tau / 2
        V = V0 - g * tau
        if w > 0:
            c, s = np.cos(w * tau), np.sin(w * tau)
            st, sdt = s0 * c + sd0 / w * s, -s0 * w * s + sd0 * c
        else:
            st, sdt = s0 + sd0 * tau, sd0 + 0 * tau
        return (X + mB / M * (b + st), V + mB / M * sdt, X - mA / M * (b + st), V - mA / M * sdt)

    def segment(t0, xA, vA, xB, vB):
        return (t0, (mA * xA + mB * xB) / M, (mA * vA + mB * vB) / M, xA - xB - b, vA - vB)

    A, B = scene.system.A, scene.system.B
    seg = segment(L(0), L(A.height), L(A.vy), L(B.height), L(B.vy))
    n = int(np.searchsorted(traj.t, window * (1 + 1e-12), side="right"))
    t = traj.t[:n].astype(L)
    worst = worst_t = 0.0
    starts = [e_.t for e_ in traj.events if e_.t <= window] + [math.inf]
    events = [e_ for e_ in traj.events if e_.t <= window]
    lo = 0
    for j, stop in enumerate(starts):
        hi = int(np.searchsorted(traj.t[:n], stop, side="left"))
        if hi > lo:
            xA, _, xB, _ = state(seg, t[lo:hi] - seg[0])
            worst = max(worst, float(np.max(np.abs(xA - traj["xA"][lo:hi]))),
                        float(np.max(np.abs(xB - traj["xB"][lo:hi]))))
        lo = hi
        if j == len(events):
            break
        hit = events[j]
        tau = L(hit.t) - seg[0]
        idx = 0 if hit.body == "A" else 2
        for _ in range(8):
            s = state(seg, tau)
            tau = tau - s[idx] / s[idx + 1]
        worst_t = max(worst_t, abs(float(seg[0] + tau - L(hit.t))))
        xA, vA, xB, vB = state(seg, tau)
        if hit.body == "A":
            xA, vA = L(0), -e * vA
        else:
            xB, vB = L(0), -e * vB
        seg = segment(seg[0] + tau, xA, vA, xB, vB)
    return worst, (worst_t if events else math.nan)


def extended_precision_rigid(traj: Trajectory, window: float) -> tuple[float, float]:
    """:func:`extended_precision_exact` for the rigid 2D dumbbell: the parabola-and-rotation
    closed form and the impulse law in numpy's extended precision, each impact time refined
    by Newton's method there; largest position error (m) and impact time error (s)."""
    return _rigid_error(*_checked(traj, window, rigid=True))


def _rigid_error(traj: Trajectory, window: float) -> tuple[float, float]:
    from ..model.energy import rigid_moment

    L = np.longdouble
    scene = traj.scene
    mA, mB, g, M, e = _long(scene.system)
    length = L(scene.system.rigid.length)  # type: ignore[union-attr]
    arm = {"A": mB / M * length, "B": -mA / M * length}
    moment = L(rigid_moment(scene))
    A, B = scene.system.A, scene.system.B
    d = (L(A.x) - L(B.x), L(A.height) - L(B.height))
    w = (L(A.vx) - L(B.vx), L(A.vy) - L(B.vy))
    seg = [L(0), (mA * L(A.x) + mB * L(B.x)) / M, (mA * L(A.height) + mB * L(B.height)) / M,
           (mA * L(A.vx) + mB * L(B.vx)) / M, (mA * L(A.vy) + mB * L(B.vy)) / M,
           np.arctan2(d[1], d[0]), (d[0] * w[1] - d[1] * w[0]) / (d[0] ** 2 + d[1] ** 2)]

    def at(seg, tau):
        t0, X, Y, VX, VY, th, om = seg
        return [t0 + tau, X + VX * tau, Y + VY * tau - g * tau * tau / 2, VX, VY - g * tau,
                th + om * tau, om]

    n = int(np.searchsorted(traj.t, window * (1 + 1e-12), side="right"))
    t = traj.t[:n].astype(L)
    events = [e_ for e_ in traj.events if e_.t <= window]
    worst = worst_t = 0.0
    lo = 0
    for j, stop in enumerate([e_.t for e_ in events] + [math.inf]):
        hi = int(np.searchsorted(traj.t[:n], stop, side="left"))
        if hi > lo:
            _, X, Y, _, _, th, _ = at(seg, t[lo:hi] - seg[0])
            for body in "AB":
                worst = max(worst,
                            float(np.max(np.abs(X + arm[body] * np.cos(th) - traj[f"x{body}"][lo:hi]))),
                            float(np.max(np.abs(Y + arm[body] * np.sin(th) - traj[f"y{body}"][lo:hi]))))
        lo = hi
        if j == len(events):
            break
        hit = events[j]
        a = arm[hit.body]
        tau = L(hit.t) - seg[0]
        if tau != 0:  # ends that hit together share the time: no new root to refine
            for _ in range(8):
                _, _, Y, _, VY, th, om = at(seg, tau)
                tau = tau - (Y + a * np.sin(th)) / (VY + a * om * np.cos(th))
        worst_t = max(worst_t, abs(float(seg[0] + tau - L(hit.t))))
        seg = at(seg, tau)
        rx = a * np.cos(seg[5])
        J = -(1 + e) * (seg[4] + seg[6] * rx) / (1 / M + rx * rx / moment)
        seg[4] += J / M
        seg[6] += rx * J / moment
    return worst, (worst_t if events else math.nan)
