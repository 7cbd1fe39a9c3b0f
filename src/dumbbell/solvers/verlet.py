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

from .base import ExplicitSpring
from .kernels import Kernel
from .stepping import Stepper

#: No public names: the class is ``dumbbell.solvers.METHODS[name]``.
__all__: list[str] = []


class Verlet(ExplicitSpring, Stepper):
    """Velocity Verlet with impacts located inside the step (see the module docstring)."""

    name = "verlet"
    order = 2

    @staticmethod
    def kernel(dimensions: int) -> Kernel | None:
        """Velocity Verlet with located impacts, in 1D or 2D."""
        from .kernels.verlet import KERNELS

        return KERNELS[dimensions] if dimensions in (1, 2) else None
