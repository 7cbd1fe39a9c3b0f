"""``euler-cromer``: the textbook's hand-written method, compiled with numba.

The loop performs the listing's floating-point operations in the listing's order
(``f = k*(xA - xB - b)``, ``fA = -f - mA*g``, ``aA = fA/mA``, ``vA = vA + aA*dt``,
``xA = xA + vA*dt``, then B), so with the textbook's values it reproduces the listing's floats
bit for bit. The motion is chaotic: an algebraically equal reordering would differ by
centimetres within 10 s.

Collision rule of the textbook: if a particle is below the floor after a step and was not
before, its velocity is reversed (scaled by the elasticity); it is not moved. A particle below
the floor that keeps moving down after that is reported as ``tunnelled``, or as ``failed`` when
it is only resting on the floor, which the flip rule cannot hold.

Only every ``every``-th step is kept, so memory follows the samples, not the steps.
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit

from ..model.scene import Scene
from ..model.trajectory import Trajectory
from . import RunOptions, kernel_params
from .stepping import BIG, BLOWUP, EVENT_BUFFER, OK, TUNNEL_A, TUNNEL_B, blowup_verdict, run_kernel
from .verdicts import below_floor_verdict, energy_verdict

NAME = "euler-cromer"

#: Steps per kernel call: the progress bar moves between calls.
_CHUNK = 4_000_000


@njit(cache=True, nogil=True)
def _advance(st, i, i_stop, dt, mA, mB, k, b, g, e, floor, every, out, ev):  # pragma: no cover
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


def supports(scene: Scene) -> str | None:
    """None if this solver can run ``scene``, else why not."""
    if scene.dimensions != 1:
        return "euler-cromer is the 1D textbook method; use euler-cromer-2d or pymunk in 2D"
    return None


def warm_up() -> float:
    """Compile (or load from numba's cache) the loop and the 1D energy partition; returns the
    seconds it took."""
    from ..model.energy import partition_1d

    t0 = time.perf_counter()
    st = np.array([1.2, 0.0, 1.0, 0.0])
    out = np.empty((4, 2))
    ev = np.empty((EVENT_BUFFER, 4))
    _advance(st, 0, 1, 1e-5, 0.1, 0.1, 200.0, 0.2, 9.8, 1.0, True, 1, out, ev)
    partition_1d(0.1, 0.1, 200.0, 0.2, 9.8, *out)
    return time.perf_counter() - t0


def solve(scene: Scene, options: RunOptions) -> Trajectory:
    """Integrate ``scene`` with the textbook's Euler-Cromer method. See the module docstring."""
    mA, mB, k, b, g, e, floor = kernel_params(scene)
    dt, every = options.dt, options.every
    # One contiguous row per column, so the Trajectory's columns are views, not copies.
    out = np.empty((4, options.n_samples))
    st = np.array([scene.A.height, scene.A.vy, scene.B.height, scene.B.vy], dtype=np.float64)
    out[:, 0] = st
    run = run_kernel(_advance, (mA, mB, k, b, g, e, floor), st, out, options,
                     f"{NAME} {scene.name}", _CHUNK, event_time_in_steps=True)
    i, status, events, wall = run.steps, run.status, run.events, run.wall

    kept = i // every + 1
    traj = Trajectory(
        scene=scene, solver=NAME, t=options.sample_times(kept),
        state={name: out[c, :kept] for c, name in enumerate(("xA", "vA", "xB", "vB"))},
        events=events, dt=dt, every=every, wall_time=wall, info={"steps": i},
    )
    if status == BLOWUP:
        traj.verdict = blowup_verdict(traj, i * dt, dt)
    elif status in (TUNNEL_A, TUNNEL_B):
        body = "A" if status == TUNNEL_A else "B"
        c = 0 if body == "A" else 2
        f = k * (st[0] - st[2] - b)
        push = f / mA if body == "A" else -f / mB  # the spring's downward pull on the body
        traj.verdict = below_floor_verdict(traj, i * dt, body, st[c], st[c + 1], dt, push)
    else:
        traj.verdict = energy_verdict(traj, dt)
    return traj

