"""``verlet``: velocity Verlet with impacts located inside the step (1D and 2D), with numba.

One step of size h from positions x, velocities v and accelerations a(x):
``x += v h + a h^2/2``, then ``v += (a + a_new) h/2``. Between impacts this is second order,
symplectic, and keeps the energy error bounded (O(dt^2), no drift) while ``w*dt < 2``.

Impacts: within a step the new height of each particle is exactly the quadratic
``p(tau) = x + v tau + a tau^2/2`` of the time ``tau`` into the step, so the step itself says
where it meets the floor. The first root of ``p`` in (0, h] over both particles (a dip below
the floor and back inside one step counts too) is taken; the step is split there: Verlet up to
the root, the particle placed on the floor and its velocity reflected (scaled by the
elasticity), then Verlet over the rest of the step, which may hold further impacts. The
impact times so found are correct to O(dt^3) per impact, so the method stays second order
through the impacts, where flipping the velocity at the first step below the floor (the
textbook's rule) makes any method first order.

In 2D (two particles, a spring along their axis, a frictionless floor, no spin) the same
holds for each particle's height; an impact reverses only the vertical velocity.

A particle that comes to rest on an inelastic floor would bounce infinitely often in finite
time; the run stops there with the verdict ``failed``. Only every ``every``-th step is kept.
"""

from __future__ import annotations

import math
import time

import numpy as np
from numba import njit

from ..model.scene import Scene
from ..model.trajectory import Trajectory, Verdict
from . import RunOptions, kernel_params, point_particle_limits
from .stepping import (
    BIG,
    BLOWUP,
    EVENT_BUFFER,
    OK,
    REST,
    TUNNEL_A,
    TUNNEL_B,
    blowup_verdict,
    run_kernel,
)
from .verdicts import energy_verdict, tunnel_reason

NAME = "verlet"

#: Steps per kernel call: the progress bar moves between calls.
_CHUNK = 2_000_000
#: An impact slower than this (m/s), or more impacts than _MAX_HITS in one step, means a
#: particle has come to rest on the floor (the exact solver uses the same speed).
REST_SPEED = 1e-9
_MAX_HITS = 64


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
def _advance(st, i, i_stop, dt, mA, mB, k, b, g, e, floor, every, out, ev):  # pragma: no cover
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
            if abs(v_in) < REST_SPEED or hits > _MAX_HITS:
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
        # One step records at most _MAX_HITS + 1 impacts: hand back while they still fit.
        if status != OK or n_ev >= ev.shape[0] - 2 * _MAX_HITS:
            break
    st[0] = xA
    st[1] = vA
    st[2] = xB
    st[3] = vB
    return i, status, n_ev


@njit(cache=True, nogil=True)
def _accel_2d(xA, yA, xB, yB, mA, mB, k, b, g):  # pragma: no cover
    """Accelerations (m/s^2) of A and B from the spring along their axis and gravity."""
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
def _advance_2d(st, i, i_stop, dt, mA, mB, k, b, g, e, floor, every, out, ev
                ):  # pragma: no cover
    xA, yA, vxA, vyA, xB, yB, vxB, vyB = st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7]
    axA, ayA, axB, ayB = _accel_2d(xA, yA, xB, yB, mA, mB, k, b, g)
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
            nxA, nyA, nxB, nyB = _accel_2d(xA, yA, xB, yB, mA, mB, k, b, g)
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
            axA, ayA, axB, ayB = _accel_2d(xA, yA, xB, yB, mA, mB, k, b, g)
            if abs(v_in) < REST_SPEED or hits > _MAX_HITS:
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
        if status != OK or n_ev >= ev.shape[0] - 2 * _MAX_HITS:
            break
    st[0], st[1], st[2], st[3] = xA, yA, vxA, vyA
    st[4], st[5], st[6], st[7] = xB, yB, vxB, vyB
    return i, status, n_ev


def supports(scene: Scene) -> str | None:
    """None if this solver can run ``scene``, else why not."""
    return point_particle_limits(scene, NAME) if scene.dimensions == 2 else None


def warm_up() -> float:
    """Compile (or load from numba's cache) the loop; returns the seconds it took."""
    t0 = time.perf_counter()
    st = np.array([1.2, 0.0, 1.0, 0.0])
    out = np.empty((2, 4))
    ev = np.empty((EVENT_BUFFER, 4))
    _advance(st, 0, 1, 1e-5, 0.1, 0.1, 200.0, 0.2, 9.8, 1.0, True, 1, out, ev)
    st2 = np.array([0.1, 1.17, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    _advance_2d(st2, 0, 1, 1e-5, 0.1, 0.1, 200.0, 0.2, 9.8, 1.0, True, 1, np.empty((2, 8)), ev)
    return time.perf_counter() - t0


def solve(scene: Scene, options: RunOptions) -> Trajectory:
    """Integrate ``scene`` with velocity Verlet and located impacts. See the module docstring.

    ``wall_time`` covers the kernel calls and the impact list, not the array set-up, the
    verdict or the energy."""
    mA, mB, k, b, g, e, floor = kernel_params(scene)
    dt, every = options.dt, options.every
    A, B = scene.A, scene.B
    if scene.dimensions == 1:
        kernel, columns = _advance, ("xA", "vA", "xB", "vB")
        st = np.array([A.height, A.vy, B.height, B.vy], dtype=np.float64)
    else:
        kernel, columns = _advance_2d, ("xA", "yA", "vxA", "vyA", "xB", "yB", "vxB", "vyB")
        st = np.array([A.x, A.height, A.vx, A.vy, B.x, B.height, B.vx, B.vy], dtype=np.float64)
    # Columns of each particle's height and vertical velocity.
    vertical = {"A": (0, 1), "B": (2, 3)} if scene.dimensions == 1 else {"A": (1, 3),
                                                                         "B": (5, 7)}
    out = np.empty((options.n_samples, len(columns)))
    out[0] = st
    run = run_kernel(kernel, (mA, mB, k, b, g, e, floor), st, out, options,
                     f"{NAME} {scene.name}", _CHUNK, event_time_in_steps=False)
    i, status, events, wall = run.steps, run.status, run.events, run.wall

    kept = i // every + 1
    traj = Trajectory(
        scene=scene, solver=NAME, t=options.sample_times(kept),
        state={name: out[:kept, c] for c, name in enumerate(columns)},
        events=events, dt=dt, every=every, wall_time=wall, info={"steps": i},
    )
    if status == BLOWUP:
        traj.verdict = blowup_verdict(traj, i * dt, dt)
    elif status in (TUNNEL_A, TUNNEL_B):
        body = "A" if status == TUNNEL_A else "B"
        y, vy = vertical[body]
        traj.verdict = Verdict("tunnelled", i * dt,
                               tunnel_reason(scene, body, st[y], st[vy], dt))
    elif status == REST:
        last = events[-1] if events else None
        t_rest = last.t if last else i * dt
        traj.verdict = Verdict(
            "failed", t_rest,
            f"{last.body if last else 'a particle'} came to rest on the floor (impact speed "
            f"{abs(last.v_before) if last else 0.0:.1e} m/s): an inelastic floor has infinitely "
            "many impacts in finite time here",
        )
    else:
        traj.verdict = energy_verdict(traj, dt)
    return traj

