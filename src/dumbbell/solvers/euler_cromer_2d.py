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

from .base import ExplicitSpring
from .kernels import Kernel
from .stepping import Stepper

#: No public names: the class is ``dumbbell.solvers.METHODS[name]``.
__all__: list[str] = []


class EulerCromer2D(ExplicitSpring, Stepper):
    """A 2D Euler-Cromer in pymunk's step order (see the module docstring)."""

    # Declared as euler_cromer.EulerCromer is (`duplicates` pairs the two by shape): a solver
    # is one class with its own facts, and the steps are two algorithms (the listing's
    # operation order, bit for bit, against pymunk's), so no class branches on dimensions.

    name = "euler-cromer-2d"
    order = 1
    chunk = 4_000_000
    no_step = "euler-cromer-2d is the 2D method; use euler-cromer (the textbook's) in 1D"

    @staticmethod
    def kernel(dimensions: int) -> Kernel | None:
        """pymunk's step order (2D only)."""
        from .kernels.euler_cromer_2d import KERNEL

        return KERNEL if dimensions == 2 else None
