"""``euler-cromer-2d``: a hand-written 2D Euler-Cromer in pymunk's step order (numba).

pymunk (Chipmunk) steps in this order: positions first, ``p += v*dt``; then contacts are found
at the new positions; then the spring's impulse ``f*dt`` along the axis; then
``v += g*dt``; then the contact impulses. So in free flight it is symplectic Euler with the
velocity lagged one step behind the textbook's Euler-Cromer (which updates v first). This
solver does the same operations in the same order and with the same formulas as the engine
(``n = delta * (1/dist)``, ``f = (b - dist) * k``, impulses times the inverse mass), so in free
flight it agrees with the ``pymunk`` solver to rounding: the difference between pymunk and the
textbook method is the step order, nothing else.

Floor: a particle whose centre is below 0 after the position update while moving down gets
the vertical velocity ``-e * v_y`` it had before the step, which is what pymunk's contact
impulse produces for a frictionless circle of infinite moment (the bounce target is computed
from the velocity before the spring and gravity act). A particle still below the floor by
more than its radius and moving down is ``tunnelled``.

Frictionless 2D spring (or free) dumbbells without spin only.
"""

from __future__ import annotations

import math
import time

import numpy as np
from numba import njit

from ..model.scene import Scene
from ..model.trajectory import Trajectory, Verdict
from . import RunOptions, kernel_params, point_particle_limits
from .stepping import BIG, BLOWUP, EVENT_BUFFER, OK, TUNNEL_A, TUNNEL_B, blowup_verdict, run_kernel
from .verdicts import energy_verdict

NAME = "euler-cromer-2d"

_CHUNK = 4_000_000
_COLUMNS = ("xA", "yA", "vxA", "vyA", "xB", "yB", "vxB", "vyB")


@njit(cache=True, nogil=True)
def _advance(st, i, i_stop, dt, mA, mB, k, b, g, e, floor, rA, rB, every, out, ev
             ):  # pragma: no cover
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


def supports(scene: Scene) -> str | None:
    """None if this solver can run ``scene``, else why not."""
    if scene.dimensions != 2:
        return "euler-cromer-2d is the 2D method; use euler-cromer (the textbook's) in 1D"
    return point_particle_limits(scene, NAME)


def warm_up() -> float:
    """Compile (or load from numba's cache) the loop; returns the seconds it took."""
    t0 = time.perf_counter()
    st = np.array([0.1, 1.17, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    _advance(st, 0, 1, 1e-5, 0.1, 0.1, 200.0, 0.2, 9.8, 1.0, True, 0.02, 0.02, 1,
             np.empty((2, 8)), np.empty((EVENT_BUFFER, 4)))
    return time.perf_counter() - t0


def solve(scene: Scene, options: RunOptions) -> Trajectory:
    """Integrate ``scene`` in pymunk's step order at step ``options.dt`` (s)."""
    A, B = scene.A, scene.B
    mA, mB, k, b, g, e, floor = kernel_params(scene)
    dt, every = options.dt, options.every
    out = np.empty((options.n_samples, 8))
    st = np.array([A.x, A.height, A.vx, A.vy, B.x, B.height, B.vx, B.vy], dtype=np.float64)
    out[0] = st
    warm_up()  # compiling is not part of the run time
    run = run_kernel(_advance, (mA, mB, k, b, g, e, floor, A.radius, B.radius), st, out,
                     options, f"{NAME} {scene.name}", _CHUNK, event_time_in_steps=True)
    i, status, events, wall = run.steps, run.status, run.events, run.wall

    kept = i // every + 1
    traj = Trajectory(scene=scene, solver=NAME, t=options.sample_times(kept),
                      state={name: out[:kept, c].copy() for c, name in enumerate(_COLUMNS)},
                      events=events, dt=dt, every=every, wall_time=wall, info={"steps": i})
    if status == BLOWUP:
        traj.verdict = blowup_verdict(traj, i * dt, dt)
    elif status in (TUNNEL_A, TUNNEL_B):
        body = "A" if status == TUNNEL_A else "B"
        y = st[1] if body == "A" else st[5]
        traj.verdict = Verdict("tunnelled", i * dt,
                               f"{body} is {-y:.3g} m below the floor and still moving down: "
                               "the step is too long for the bounce to catch it")
    else:
        traj.verdict = energy_verdict(traj, dt)
    return traj
