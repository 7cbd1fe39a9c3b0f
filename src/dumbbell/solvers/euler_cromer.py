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

from ..model.energy import partition_1d
from ..model.scene import Scene
from ..model.trajectory import Trajectory, Verdict
from .base import RunOptions, kernel_params
from .kernels import EVENT_BUFFER, Params
from .stepping import Stepper, finish, run_kernel
from .verdicts import below_floor_verdict

#: The public API: the solver class (its supports and solve); the rest serves it.
__all__ = ["EulerCromer"]

NAME = "euler-cromer"

#: Steps per kernel call: the progress bar moves between calls.
_CHUNK = 4_000_000


def supports(scene: Scene) -> str | None:
    """None if this solver can run ``scene``, else why not."""
    if scene.system.dimensions != 1:
        return "euler-cromer is the 1D textbook method; use euler-cromer-2d or pymunk in 2D"
    return None


def warm_up() -> float:
    """Compile (or load from numba's cache) the loop and the 1D energy partition; returns the
    seconds it took."""
    from .kernels.euler_cromer import advance

    t0 = time.perf_counter()
    st = np.array([1.2, 0.0, 1.0, 0.0])
    out = np.empty((4, 2))
    ev = np.empty((EVENT_BUFFER, 4))
    advance(st, 0, 1, Params(1e-5, 0.1, 0.1, 200.0, 0.2, 9.8, 1.0, True, 0.02, 0.02), 1, out, ev)
    partition_1d(0.1, 0.1, 200.0, 0.2, 9.8, *out)
    return time.perf_counter() - t0


def solve(scene: Scene, options: RunOptions) -> Trajectory:
    """Integrate ``scene`` with the textbook's Euler-Cromer method. See the module docstring."""
    from .kernels.euler_cromer import advance

    params = kernel_params(scene.system, options.dt)
    mA, mB, k, b, g = params.mA, params.mB, params.k, params.b, params.g
    dt, every = options.dt, options.every
    # One contiguous row per column, so the Trajectory's columns are views, not copies.
    out = np.empty((4, options.n_samples))
    A, B = scene.system.A, scene.system.B
    st = np.array([A.height, A.vy, B.height, B.vy], dtype=np.float64)
    out[:, 0] = st
    run = run_kernel(advance, params, st, out, options,
                     f"{NAME} {scene.name}", _CHUNK, event_time_in_steps=True)
    i = run.steps

    kept = i // every + 1
    state = {name: out[c, :kept] for c, name in enumerate(("xA", "vA", "xB", "vB"))}

    def below_floor(body: str) -> Verdict:
        c = 0 if body == "A" else 2
        f = k * (st[0] - st[2] - b)
        push = f / mA if body == "A" else -f / mB  # the spring's downward pull on the body
        E = partition_1d(mA, mB, k, b, g, *out[:, [0, kept - 1]])["E"]  # at the start and end
        return below_floor_verdict(scene, i * dt, body, st[c], st[c + 1], dt, push, E=E)

    return finish(scene, NAME, run, options, state, below_floor)


class EulerCromer(Stepper):
    """The textbook's Euler-Cromer in 1D (see the module docstring)."""

    name = NAME
    order = 1
    supports = staticmethod(supports)
    solve = staticmethod(solve)
    warm_up = staticmethod(warm_up)
