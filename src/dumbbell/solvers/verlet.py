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

import time

import numpy as np

from ..model.scene import Scene
from ..model.trajectory import Trajectory, Verdict
from .base import RunOptions, kernel_params, point_particle_limits
from .kernels import EVENT_BUFFER, Params
from .stepping import Stepper, finish, run_kernel
from .verdicts import tunnel_reason

#: The public API: the solver class (its supports and solve); the rest serves it.
__all__ = ["Verlet"]

NAME = "verlet"

#: Steps per kernel call: the progress bar moves between calls.
_CHUNK = 2_000_000


def supports(scene: Scene) -> str | None:
    """None if this solver can run ``scene``, else why not."""
    return point_particle_limits(scene, NAME) if scene.system.dimensions == 2 else None


def warm_up() -> float:
    """Compile (or load from numba's cache) the loop; returns the seconds it took."""
    from .kernels.verlet import advance, advance_2d

    t0 = time.perf_counter()
    st = np.array([1.2, 0.0, 1.0, 0.0])
    out = np.empty((2, 4))
    ev = np.empty((EVENT_BUFFER, 4))
    p = Params(1e-5, 0.1, 0.1, 200.0, 0.2, 9.8, 1.0, True, 0.02, 0.02)
    advance(st, 0, 1, p, 1, out, ev)
    st2 = np.array([0.1, 1.17, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    advance_2d(st2, 0, 1, p, 1, np.empty((2, 8)), ev)
    return time.perf_counter() - t0


def solve(scene: Scene, options: RunOptions) -> Trajectory:
    """Integrate ``scene`` with velocity Verlet and located impacts. See the module docstring.

    ``wall_time`` covers the kernel calls and the impact list, not the array set-up, the
    verdict or the energy."""
    from .kernels.verlet import advance, advance_2d

    dt, every = options.dt, options.every
    A, B = scene.system.A, scene.system.B
    if scene.system.dimensions == 1:
        kernel, columns = advance, ("xA", "vA", "xB", "vB")
        st = np.array([A.height, A.vy, B.height, B.vy], dtype=np.float64)
    else:
        kernel, columns = advance_2d, ("xA", "yA", "vxA", "vyA", "xB", "yB", "vxB", "vyB")
        st = np.array([A.x, A.height, A.vx, A.vy, B.x, B.height, B.vx, B.vy], dtype=np.float64)
    # Columns of each particle's height and vertical velocity.
    vertical = {"A": (0, 1), "B": (2, 3)} if scene.system.dimensions == 1 else {"A": (1, 3),
                                                                         "B": (5, 7)}
    out = np.empty((options.n_samples, len(columns)))
    out[0] = st
    run = run_kernel(kernel, kernel_params(scene.system, dt), st, out, options,
                     f"{NAME} {scene.name}", _CHUNK, event_time_in_steps=False)
    i, events = run.steps, run.events

    kept = i // every + 1
    state = {name: out[:kept, c] for c, name in enumerate(columns)}

    def below_floor(body: str) -> Verdict:
        y, vy = vertical[body]
        return Verdict("tunnelled", i * dt, tunnel_reason(scene, body, st[y], st[vy], dt))

    def at_rest() -> Verdict:
        last = events[-1] if events else None
        t_rest = last.t if last else i * dt
        return Verdict(
            "failed", t_rest,
            f"{last.body if last else 'a particle'} came to rest on the floor (impact speed "
            f"{abs(last.v_before) if last else 0.0:.1e} m/s): an inelastic floor has infinitely "
            "many impacts in finite time here",
        )

    return finish(scene, NAME, run, options, state, below_floor, at_rest)


class Verlet(Stepper):
    """Velocity Verlet with impacts located inside the step (see the module docstring)."""

    name = NAME
    order = 2
    supports = staticmethod(supports)
    solve = staticmethod(solve)
    warm_up = staticmethod(warm_up)
