"""Compiled (numba) time-step kernels, one module per stepping solver, and their contract
(plus :mod:`.reference_2d`, the reference's Runge-Kutta loop, with a contract of its own).

A kernel ``advance(st, i, i_stop, p, every, out, ev)`` advances the state ``st`` in place
from step ``i`` towards ``i_stop`` with the scalars of the record ``p`` (:class:`Params`),
writes every ``every``-th step into ``out``, records impacts as rows
``(time or step, body 0/1, v_before, v_after)`` of ``ev``, and returns
``(step reached, status, impacts recorded)`` with a status code below. A kernel unpacks ``p``
into local names once, before its loop. This package's ``__init__`` holds only plain
constants and the record, so importing it does not load numba.
"""

from __future__ import annotations

from typing import NamedTuple

#: A state component beyond this magnitude (m or m/s) counts as blown up.
BIG = 1e150
#: Impacts recorded per kernel call before it hands back to Python.
EVENT_BUFFER = 4096
#: Kernel status codes.
OK, BLOWUP, TUNNEL_A, TUNNEL_B, REST = 0, 1, 2, 3, 4


class Params(NamedTuple):
    """The scalars a kernel reads, in one record (numba passes it as a typed tuple).

    Every field is a float except ``floor``, so every kernel compiles (and caches) once."""

    dt: float  #: step (s)
    mA: float  #: mass of A (kg)
    mB: float  #: mass of B (kg)
    k: float  #: spring constant (N/m)
    b: float  #: spring rest length (m)
    g: float  #: gravitational acceleration (m/s^2)
    e: float  #: the floor's elasticity (1)
    floor: bool  #: whether there is a floor
    rA: float  #: radius of A (m): how far below the floor counts as tunnelled in 2D
    rB: float  #: radius of B (m)
