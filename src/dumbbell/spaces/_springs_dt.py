"""The springs' step for the guard (:mod:`.guard`): a spring's angular frequency, the energy
swing of pymunk's explicit step at w*dt, and the guard's rows for springs (``spring``,
``rotary-spring``) and bodies held by several (``spring-network``)."""

from __future__ import annotations

import math
from typing import Any, NamedTuple

from ..model import args
from ._finding import Finding
from ._scan import Scan
from .estimates import percent

#: No public names here: ``energy_swing`` and ``spring_omega`` are :mod:`dumbbell.spaces.guard`'s.
__all__: list[str] = []

#: w*dt limit of the explicit spring step (stability).
SPRING_LIMIT = 2.0


def energy_swing(w_dt: float) -> float:
    """The energy swing of pymunk's step of an undamped spring at ``w_dt`` = w*dt: the largest
    relative change of its energy from the start, over every start, 2 w dt / (2 - w dt)
    (a fraction; inf from w dt = 2, where the step is unstable).

    Why: positions first, then velocities from the new positions (symplectic Euler) keeps
    H = v^2/2 + w^2 x^2/2 - (w^2 dt/2) x v exactly for x'' = -w^2 x; the energy
    E = v^2/2 + w^2 x^2/2 then runs between H / (1 + w dt / 2) and H / (1 - w dt / 2).

    Parameters
    ----------
    w_dt : float
        w*dt, w the spring's angular frequency.

    Returns
    -------
    float
        The swing, a fraction (inf from w dt = 2).

    Raises
    ------
    UsageError
        A w*dt that is not a number >= 0.

    Examples
    --------
    >>> from dumbbell import spaces
    >>> spaces.energy_swing(1.0), spaces.energy_swing(0.01), spaces.energy_swing(2.0)
    (2.0, 0.010050251256281407, inf)
    """
    z = args.real(w_dt, "w_dt", "-", lo=0.0)
    return math.inf if z >= SPRING_LIMIT else 2.0 * z / (2.0 - z)


def _swing_limit(tolerance: float) -> float:
    """The w*dt whose energy swing is ``tolerance`` (2 for an infinite tolerance)."""
    return SPRING_LIMIT if math.isinf(tolerance) else 2.0 * tolerance / (2.0 + tolerance)



def _inverse_mass(body: Any) -> tuple[float, float]:
    """1/m and 1/I of a body; 0 for static, kinematic, infinite."""
    import pymunk

    if body.body_type != pymunk.Body.DYNAMIC:
        return 0.0, 0.0
    inv_m = 0.0 if math.isinf(body.mass) or body.mass <= 0 else 1.0 / body.mass
    inv_i = 0.0 if math.isinf(body.moment) or body.moment <= 0 else 1.0 / body.moment
    return inv_m, inv_i


def spring_omega(spring: Any) -> float:
    """Angular frequency (rad/s) of a ``DampedSpring`` or ``DampedRotarySpring`` on its two
    bodies as they are now (0 if neither can move); see :mod:`dumbbell.spaces.guard`.

    Parameters
    ----------
    spring : pymunk.DampedSpring or pymunk.DampedRotarySpring
        The spring.

    Returns
    -------
    float
        w (rad per the space's time unit).

    Raises
    ------
    UsageError
        Anything but such a spring.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell.spaces import spring_omega
    >>> space = pymunk.Space()                     # no gravity, no shapes: the spring alone
    >>> ball = pymunk.Body(0.1, 1e-4)                 # 0.1 kg, hung 1 m below the anchor
    >>> spring = pymunk.DampedSpring(space.static_body, ball, (0, 1), (0, 0), 1, 200, 0)
    >>> round(spring_omega(spring), 4)   # sqrt(k / m): the line runs through the centre
    44.7214
    """
    import pymunk

    args.pymunk_object(spring, "spring", ("DampedSpring", "DampedRotarySpring"))
    a, b = spring.a, spring.b
    ma, ia = _inverse_mass(a)
    mb, ib = _inverse_mass(b)
    if isinstance(spring, pymunk.DampedRotarySpring):
        inv = ia + ib
    else:
        pa = a.local_to_world(spring.anchor_a)
        pb = b.local_to_world(spring.anchor_b)
        ra = pa - a.local_to_world(a.center_of_gravity)
        rb = pb - b.local_to_world(b.center_of_gravity)
        d = pb - pa
        length = d.length
        n = d / length if length > 0 else pymunk.Vec2d(1.0, 0.0)
        inv = ma + mb + ia * ra.cross(n) ** 2 + ib * rb.cross(n) ** 2
    w = math.sqrt(abs(spring.stiffness) * inv)
    return w if math.isfinite(w) else math.inf



class _Judged(NamedTuple):
    """The step a spring is judged at: ``dt`` (s) and the largest energy swing allowed
    (``tolerance``, a fraction; math.inf: stability only)."""

    dt: float
    tolerance: float


def _spring_row(kind: str, subject: str, w: float, at: _Judged, extra: str = "") -> Finding:
    """A spring's finding: w*dt against the w*dt whose swing is ``at.tolerance``."""
    dt, tolerance = at
    z = w * dt
    limit = _swing_limit(tolerance)
    dt_max = limit / w
    swing = energy_swing(z) if math.isfinite(z) else math.inf
    keeps = ("stays stable (w dt < 2)" if math.isinf(tolerance)
             else f"keeps the swing under {percent(tolerance)}")
    if z >= SPRING_LIMIT:
        now = "unstable: the energy grows without bound from w dt = 2"
    else:
        now = f"the energy swings by {percent(swing)} at this step (2 w dt / (2 - w dt))"
    fix = f"{extra}w = {w:.4g} rad/s: {now}; dt < {dt_max:.4g} s {keeps}"
    # The closed form of its drift: none (the step keeps a modified energy), a bounded swing.
    note = ("" if extra or z >= SPRING_LIMIT else
            f"no drift: its energy swings by at most {percent(swing)} and back")
    return Finding(kind, subject, z, limit, fix, dt_max, "<", note=note)


def _springs(space: Any, dt: float, tolerance: float) -> list[Finding]:
    """Each spring's w*dt (linear and rotary) against the step's swing and stability."""
    import pymunk

    rows: list[Finding] = []
    for j, c in enumerate(space.constraints):
        if not isinstance(c, pymunk.DampedSpring | pymunk.DampedRotarySpring):
            continue
        w = spring_omega(c)
        kind = "rotary-spring" if isinstance(c, pymunk.DampedRotarySpring) else "spring"
        if w == 0.0:
            rows.append(Finding(kind, f"{type(c).__name__} {j}", 0.0, _swing_limit(tolerance),
                                "it moves nothing (no stiffness, or no end that can move)",
                                None, "<", note="moves nothing"))
            continue
        rows.append(_spring_row(kind, f"{type(c).__name__} {j}", w, _Judged(dt, tolerance)))
    return rows


def _networks(space: Any, sc: Scan, dt: float, tolerance: float) -> list[Finding]:
    """``spring-network``: a body held by two or more linear springs vibrates faster than any
    one of them alone (a row of equal masses: up to 2 sqrt(k/m) against sqrt(2 k/m)). Bound
    (Gershgorin, translations only): w^2 <= sum over its springs of k / m + k / sqrt(m m_other),
    the other end's term dropped when it cannot move. An upper bound, so it can flag a step
    that would still be stable and accurate; checked only for bodies with two or more
    springs."""
    import pymunk

    bound: dict[int, list[Any]] = {}
    for c in space.constraints:
        if not isinstance(c, pymunk.DampedSpring) or c.stiffness <= 0:
            continue
        for here, there in ((c.a, c.b), (c.b, c.a)):
            inv_here, _ = _inverse_mass(here)
            if inv_here == 0.0:
                continue
            inv_there, _ = _inverse_mass(there)
            entry = bound.setdefault(id(here), [here, 0.0, 0])
            entry[1] += c.stiffness * (inv_here + math.sqrt(inv_here * inv_there))
            entry[2] += 1
    rows = []
    for body, w2, count in bound.values():
        if count >= 2:
            rows.append(_spring_row("spring-network", sc.label(sc.number(body)),
                                    math.sqrt(w2), _Judged(dt, tolerance),
                                    f"{count} springs on it, w <= bound; "))
    return rows
