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

import time

import numpy as np

from ..model.scene import Scene
from ..model.trajectory import Trajectory, Verdict
from .base import RunOptions, kernel_params, point_particle_limits
from .kernels import EVENT_BUFFER, Params
from .stepping import Stepper, finish, run_kernel

#: The public API: the solver class (its supports and solve); the rest serves it.
__all__ = ["EulerCromer2D"]

NAME = "euler-cromer-2d"

_CHUNK = 4_000_000
_COLUMNS = ("xA", "yA", "vxA", "vyA", "xB", "yB", "vxB", "vyB")


def supports(scene: Scene) -> str | None:
    """None if this solver can run ``scene``, else why not."""
    if scene.system.dimensions != 2:
        return "euler-cromer-2d is the 2D method; use euler-cromer (the textbook's) in 1D"
    return point_particle_limits(scene, NAME)


def warm_up() -> float:
    """Compile (or load from numba's cache) the loop; returns the seconds it took."""
    from .kernels.euler_cromer_2d import advance

    t0 = time.perf_counter()
    st = np.array([0.1, 1.17, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    advance(st, 0, 1, Params(1e-5, 0.1, 0.1, 200.0, 0.2, 9.8, 1.0, True, 0.02, 0.02), 1,
            np.empty((2, 8)), np.empty((EVENT_BUFFER, 4)))
    return time.perf_counter() - t0


def solve(scene: Scene, options: RunOptions) -> Trajectory:
    """Integrate ``scene`` in pymunk's step order at step ``options.dt`` (s)."""
    from .kernels.euler_cromer_2d import advance

    A, B = scene.system.A, scene.system.B
    dt, every = options.dt, options.every
    out = np.empty((options.n_samples, 8))
    st = np.array([A.x, A.height, A.vx, A.vy, B.x, B.height, B.vx, B.vy], dtype=np.float64)
    out[0] = st
    warm_up()  # compiling is not part of the run time
    run = run_kernel(advance, kernel_params(scene.system, dt), st, out, options,
                     f"{NAME} {scene.name}", _CHUNK, event_time_in_steps=True)
    i = run.steps

    kept = i // every + 1
    state = {name: out[:kept, c].copy() for c, name in enumerate(_COLUMNS)}

    def below_floor(body: str) -> Verdict:
        y = st[1] if body == "A" else st[5]
        return Verdict("tunnelled", i * dt,
                       f"{body} is {-y:.3g} m below the floor and still moving down: "
                       "the step is too long for the bounce to catch it")

    return finish(scene, NAME, run, options, state, below_floor)


class EulerCromer2D(Stepper):
    """A 2D Euler-Cromer in pymunk's step order (see the module docstring)."""

    name = NAME
    order = 1
    supports = staticmethod(supports)
    solve = staticmethod(solve)
    warm_up = staticmethod(warm_up)
