"""``euler-cromer``: the textbook's hand-written method, compiled with numba.

The loop performs the listing's floating-point operations in the listing's order
(``f = k*(xA - xB - b)``, ``fA = -f - mA*g``, ``aA = fA/mA``, ``vA = vA + aA*dt``,
``xA = xA + vA*dt``, then B), so with the textbook's values it reproduces the listing's floats
bit for bit. The motion is chaotic: an algebraically equal reordering would differ by
centimetres within 10 s.

Collision rule of the textbook, which the kernels' driver applies: if a particle is below the
floor after a step and was not before, its velocity is reversed (scaled by the elasticity); it
is not moved. A particle below the floor that keeps moving down after that is reported as
``tunnelled``, or as ``failed`` when it is only resting on the floor, which the flip rule
cannot hold.

Only every ``every``-th step is kept, so memory follows the samples, not the steps.
"""

from __future__ import annotations

from .base import ExplicitSpring
from .kernels import Kernel
from .stepping import Stepper

#: No public names: the class is ``dumbbell.solvers.METHODS[name]``.
__all__: list[str] = []


class EulerCromer(ExplicitSpring, Stepper):
    """The textbook's Euler-Cromer in 1D (see the module docstring)."""

    name = "euler-cromer"
    order = 1
    chunk = 4_000_000
    no_step = "euler-cromer is the 1D textbook method; use euler-cromer-2d or pymunk in 2D"

    @staticmethod
    def kernel(dimensions: int) -> Kernel | None:
        """The textbook's step (1D only)."""
        from .kernels.euler_cromer import KERNEL

        return KERNEL if dimensions == 1 else None
