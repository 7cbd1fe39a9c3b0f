"""Compiled (numba) time steps, one module per stepping solver, the one driver that runs them
(:mod:`.driver`), and their contract (plus :mod:`.reference_2d`, the reference's Runge-Kutta
loop, with a contract of its own).

A stepping solver writes one thing: its step, a plain Python function in the subset of Python
that numba compiles, described by a :class:`Kernel`. The driver compiles it into
``advance(st, i, i_stop, p, every, out, j0, ev)``, which advances the state ``st`` in place
from step ``i`` towards ``i_stop`` with the scalars of the record ``p`` (:class:`Params`);
applies the floor's flip where the step leaves it to the driver; records impacts as rows
``(time, body 0/1, v_before, v_after)`` of ``ev``; writes every ``every``-th step into the
columns of ``out`` (its column 0 is sample ``j0``); stops at the step where the state blows
up or a particle is through the floor; and returns ``(step reached, status, impacts
recorded)`` with a status code below.

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
    (undecorated, or ``numba.njit``); the driver inlines it into its loop.

    - ``step``: one step of length ``p.dt``. Unless ``finds_impacts``, ``step(s, p) -> s``:
      the state after the step, the floor left to the driver, which then applies the
      textbook's rule (a particle below the floor that was not before the step has its
      vertical velocity reversed, times the elasticity; it is not moved);
    - ``finds_impacts``: the step handles the floor itself: ``step(s, p, i, hits) -> (s,
      n_hits, status)`` for the step from step index ``i``, with its impacts in the first
      ``n_hits`` rows of ``hits`` (time in s, body 0/1, v_before, v_after; at most
      :data:`~.driver.HITS`) and ``status`` OK, or REST when a particle has come to rest
      (the step is then not counted);
    - ``start``: ``start(s, p) -> s`` extends the sampled state with what the step carries
      (None: nothing). It is called whenever the driver resumes, so what it computes must
      follow from the sampled state alone;
    - ``through_at_radius``: a particle is through the floor once its centre is more than its
      radius below it and moving down (a circle that the floor catches while they overlap);
      otherwise at any depth.
    """

    step: Callable[..., Any]
    finds_impacts: bool = False
    start: Callable[..., Any] | None = None
    through_at_radius: bool = False
