"""Compiled (numba) time steps, one module per stepping solver, the one driver that runs them
(:mod:`.driver`), and their contract (plus :mod:`.reference_2d`, the reference's Runge-Kutta
loop, with a contract of its own).

A stepping solver writes one thing: its step, a plain Python function in the subset of Python
that numba compiles, described by a :class:`Kernel`. The driver compiles it into
``advance(st, i, i_stop, p, every, out, j0, ev)``, which advances the state ``st`` in place
from step ``i`` towards ``i_stop`` with the scalars of the record ``p`` (:class:`Params`);
applies the floor's rule the kernel names; records impacts as rows ``(time, body 0/1,
v_before, v_after)`` of ``ev``; writes every ``every``-th step into the columns of ``out`` (its
column 0 is sample ``j0``); stops at the step where the state blows up, a particle is through
the floor or comes to rest on it; and returns ``(step reached, status, impacts recorded)`` with
a status code below. A step takes and returns plain values, never an array, so that the
compiled loop keeps the state in registers.

The state is a tuple of floats: 1D ``(xA, vA, xB, vB)``, 2D ``(xA, yA, vxA, vyA, xB, yB, vxB,
vyB)`` (heights and vertical velocities: 1D columns 0, 1 and 2, 3; 2D 1, 3 and 5, 7), which a
step may extend with values it carries from one step to the next (Verlet's accelerations; see
``start``). This package's ``__init__`` holds only plain constants and records, so importing it
does not load numba.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

#: A state component beyond this magnitude (m or m/s) counts as blown up.
BIG = 1e150
#: Impacts recorded per kernel call before it hands back to Python.
EVENT_BUFFER = 4096
#: Kernel status codes.
OK, BLOWUP, TUNNEL_A, TUNNEL_B, REST = 0, 1, 2, 3, 4
#: An impact slower than this (m/s), or more impacts than MAX_HITS within one step, means a
#: particle has come to rest on the floor (the exact and reference solvers use the same speed).
REST_SPEED = 1e-9
MAX_HITS = 64
#: The floor rules a kernel may name (:attr:`Kernel.floor`).
FLOOR_RULES = ("flip", "end", "locate")


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


class Kernel(NamedTuple):
    """A stepping solver's compiled part. Each function is plain Python that numba compiles
    (undecorated, or compiled by numba's njit; what it calls must be compiled by njit or
    registered by numba's ``extending.register_jitable``); the driver inlines it into its
    loop.

    ``floor`` names the rule at the floor, which the driver applies or records:

    - ``"flip"`` (the textbook's): ``step(s, p) -> s``, one step of length ``p.dt``; then a
      particle below the floor that was not before the step has its vertical velocity
      reversed, times the elasticity; it is not moved;
    - ``"end"`` (pymunk's order): ``step(s, p) -> (s, hits)``, the step with its contacts
      applied at its end, ``hits = (hitA, vA_before, vA_after, hitB, vB_before, vB_after)``
      (``hitX`` True when X met the floor in this step);
    - ``"locate"`` (impacts inside the step): ``step(s, p, rem) -> (s, h, body)`` advances
      by ``h`` <= ``rem`` s, stopping early (``body`` 0 for A, 1 for B; else -1) where a
      particle meets the floor; the driver places it there, reflects its vertical velocity
      (times the elasticity), counts the impact and steps on over the rest of the step.

    ``start(s, p) -> s`` extends the sampled state with what the step carries (None:
    nothing); it is called whenever the driver resumes and after a located impact, so what it
    computes must follow from the sampled state alone. ``through_at_radius``: a particle is
    through the floor once its centre is more than its radius below it and moving down (a
    circle that the floor catches while they overlap); otherwise at any depth.

    Parameters
    ----------
    step : callable
        The step, as the floor rule says.
    floor : {'flip', 'end', 'locate'}, default 'flip'
        The rule at the floor.
    start : callable or None, default None
        Extends the sampled state with what the step carries.
    through_at_radius : bool, default False
        When a particle counts as through the floor.

    Examples
    --------
    A classic Euler-Cromer step of the 1D state ``s = (xA, vA, xB, vB)`` with the scalars
    ``p`` (``p.dt``, ``p.mA``, ``p.mB``, ``p.k``, ``p.b``, ``p.g``):

    >>> from dumbbell.solvers import Kernel
    >>> def euler_cromer(s, p):
    ...     xA, vA, xB, vB = s
    ...     f = -p.k * (xA - xB - p.b)
    ...     vA = vA + (f / p.mA - p.g) * p.dt
    ...     vB = vB + (-f / p.mB - p.g) * p.dt
    ...     return (xA + vA * p.dt, vA, xB + vB * p.dt, vB)
    >>> Kernel(euler_cromer).floor
    'flip'
    """

    step: Callable[..., Any]
    floor: str = "flip"
    start: Callable[..., Any] | None = None
    through_at_radius: bool = False
