"""The closed-form flight of the rigid 2D dumbbell: the ``exact`` solver's 2D half.

Between impacts the centre of mass R = (X, Y) follows a parabola and the axis angle theta
(of d = rA - rB from the x axis) grows linearly, so each end's height is

    y(tau) = Y0 + VY tau - g tau^2 / 2 + a sin(theta0 + omega tau)

with the signed arm ``a = (mB/M) L`` for A and ``-(mA/M) L`` for B. Impacts are the first roots
of these heights, found by a search that cannot miss one, grazing touches included:

- ``|y''| <= C = g + |a| omega^2``, so on an interval of width h the height lies at most
  ``C h^2 / 8`` below its chord: an interval whose ends clear that margin holds no root;
- an interval whose height is provably decreasing (``y' <= min(y'_lo, y'_hi) + C h < 0``) and
  changes sign holds exactly one root, refined by ``brentq`` to about 1e-14 s;
- an interval on which ``y'`` is provably increasing (``|y'''| <= |a| omega^3``) and changes
  sign holds one minimum, found as the root of ``y'``: the end touches the floor there iff
  that minimum is <= 0 (a graze at 1e-7 m/s is found; a miss by 1e-9 m is not);
- anything else is split in two, down to 1e-13 s.

The search and the sampling run compiled with numba (:mod:`.kernels.exact`), with the floats
of the same arithmetic in Python and numpy, and of scipy's ``brentq``, bit for bit.

Heights are computed relative to the segment's start, ``a (sin(theta) - sin(theta0)) =
2 a cos(theta0 + omega tau / 2) sin(omega tau / 2)``, and the end that just hit the floor starts
its segment at height 0 exactly, so that a slow rebound is not lost to rounding. Impacts follow
the impulse law of a frictionless floor with restitution e: at the contact point, with r_x its
horizontal offset from the centre of mass and I the moment of inertia,
``J = -(1 + e) v_y / (1/M + r_x^2 / I)``, ``VY += J / M``, ``omega += r_x J / I``. Ends that hit
together get impulses in turn until neither approaches the floor.

The chaotic map amplifies rounding about tenfold per impact, so the 1e-14 s of each root is
the precision of one impact, not of the hundredth.

>>> traj = simulate(load_scene("scenes/rigid-2d.toml"), "exact", every=100)  # doctest: +SKIP
>>> before, after = first_impact_state(tilt=30.0, elasticity=0.5)             # doctest: +SKIP
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..errors import UsageError
from ..model.energy import (
    gravity_potential,
    impact_heat,
    rigid_moment,
    rotational_ke,
    spins,
    state_columns,
    translational_ke,
)
from ..model.scene import Scene, scene_from_dict
from ..model.trajectory import Impact, Verdict
from . import base
from ._closed_form import MIN_SPLIT, REST_SPEED, ROOT_XTOL, at_rest, search_failed
from .base import SearchBudget, impact_budget_reason

#: The public API: the first impact in closed form; the rest serves the exact solver.
__all__ = ["first_impact_state"]

#: Rounds of impulses for ends that hit together.
MAX_ROUNDS = 100


@dataclass(frozen=True)
class RigidState:
    """The rigid dumbbell at time ``t`` (s): centre of mass X, Y (m) and VX, VY (m/s), axis
    angle ``theta`` (rad, of rA - rB from the x axis, counter-clockwise) and ``omega`` (rad/s);
    ``hA``, ``hB``: the ends' heights (m), 0 for an end just off the floor."""

    t: float
    X: float
    Y: float
    VX: float
    VY: float
    theta: float
    omega: float
    hA: float
    hB: float


class RigidBody:
    """Masses, arms and moment of one rigid scene, and its closed-form motion."""

    def __init__(self, scene: Scene):
        if scene.system.rigid is None:
            raise ValueError("RigidBody needs a scene with [rigid]")
        self.M = scene.system.M
        self.g = scene.system.g
        self.L = scene.system.rigid.length
        A, B = scene.system.A, scene.system.B
        self.arm = {"A": B.mass / self.M * self.L, "B": -A.mass / self.M * self.L}
        self.moment = rigid_moment(scene)

    # --- the state -------------------------------------------------------------------------
    def initial(self, scene: Scene) -> RigidState:
        """The state at t = 0 from the particles' positions and velocities; the velocity
        along the rod (which a rigid rod cannot have) is dropped."""
        A, B, M = scene.system.A, scene.system.B, self.M
        d = (A.x - B.x, A.height - B.height)
        w = (A.vx - B.vx, A.vy - B.vy)
        theta = math.atan2(d[1], d[0])
        omega = (d[0] * w[1] - d[1] * w[0]) / (d[0] ** 2 + d[1] ** 2)
        return RigidState(0.0, (A.mass * A.x + B.mass * B.x) / M,
                          (A.mass * A.height + B.mass * B.height) / M,
                          (A.mass * A.vx + B.mass * B.vx) / M, (A.mass * A.vy + B.mass * B.vy) / M,
                          theta, omega, A.height, B.height)

    def advance(self, s: RigidState, tau: float) -> RigidState:
        """The state ``tau`` seconds after ``s`` (no impact in between)."""
        th = s.theta + s.omega * tau
        return RigidState(s.t + tau, s.X + s.VX * tau, s.Y + s.VY * tau - 0.5 * self.g * tau * tau,
                          s.VX, s.VY - self.g * tau, th, s.omega,
                          *(self.height(s, body, tau)[0] for body in "AB"))

    def vertical_velocity(self, s: RigidState, body: str) -> float:
        """Vertical velocity of ``body`` (m/s) in state ``s``."""
        return s.VY + s.omega * self.arm[body] * math.cos(s.theta)

    def curvature(self, s: RigidState, body: str) -> float:
        """Bound on |y''| of ``body``'s height over any time (m/s^2)."""
        return self.g + abs(self.arm[body]) * s.omega * s.omega

    def height(self, s: RigidState, body: str, tau: float) -> tuple[float, float]:
        """Height (m) and vertical velocity (m/s) of ``body`` at ``tau`` after ``s``
        (:func:`~dumbbell.solvers.kernels.exact.end_height`)."""
        from .kernels.exact import end_height

        return end_height(self._end(s, body), float(tau))

    def _end(self, s: RigidState, body: str) -> Any:
        """What the compiled height search reads of ``body`` in segment ``s``."""
        from .kernels.exact import End

        return End(float(self.arm[body]), float(s.omega), float(s.theta), float(s.VY),
                   float(self.g), float(s.hA if body == "A" else s.hB))

    # --- impacts ---------------------------------------------------------------------------
    def effective_mass(self, s: RigidState, body: str) -> float:
        """Mass (kg) the floor's vertical impulse at ``body`` meets: 1 / (1/M + r_x^2 / I)."""
        rx = self.arm[body] * math.cos(s.theta)
        return 1.0 / (1.0 / self.M + rx * rx / self.moment)

    def impulse(self, s: RigidState, body: str, e: float) -> RigidState:
        """The state just after the floor's frictionless impulse on ``body`` (restitution
        ``e``), the end moving down at the contact."""
        rx = self.arm[body] * math.cos(s.theta)
        J = -(1.0 + e) * self.vertical_velocity(s, body) * self.effective_mass(s, body)
        return replace(s, VY=s.VY + J / self.M, omega=s.omega + rx * J / self.moment)

    def collide(self, s: RigidState, hit: list[str], e: float
                ) -> tuple[RigidState, list[Impact], Verdict]:
        """The state after the floor's impulses on the ends in ``hit`` (on the floor in ``s``),
        given in turn until neither moves down; the impacts; ``failed`` if one came to rest."""
        s = replace(s, **{f"h{b}": 0.0 for b in hit})
        events: list[Impact] = []
        for _ in range(MAX_ROUNDS):
            moved = False
            for b in hit:
                v = self.vertical_velocity(s, b)
                if v >= 0:
                    continue
                if abs(v) < REST_SPEED:
                    return s, events, at_rest(b, s.t, v)
                s = self.impulse(s, b, e)
                after = self.vertical_velocity(s, b)
                events.append(Impact(s.t, b, v, after,
                                     impact_heat(self.effective_mass(s, b), v, after)))
                moved = True
            if not moved:
                break
        return s, events, Verdict()

    def first_contact(self, s: RigidState, body: str, start: float, stop: float,
                      budget: SearchBudget | None = None) -> float:
        """First time in [start, stop] (s after ``s``) at which ``body`` reaches the floor
        moving down, or inf; each block scanned and interval split counts against
        ``budget``. See the module docstring for why no root can be missed; the search runs
        compiled (:func:`~dumbbell.solvers.kernels.exact.end_contact`)."""
        from .kernels import exact as kernels

        w = s.omega
        C = self.curvature(s, body)
        D = abs(self.arm[body]) * abs(w) ** 3  # bound on |y'''|
        lo = max(start, self._earliest(s, body))
        if lo > stop:
            return math.inf
        h = 0.05 if w == 0 else min(0.05, 2 * math.pi / abs(w) / 16.0)
        # Without a run's budget, one search still stops: at a run's whole budget.
        allowed = base.MAX_SEARCH_WORK if budget is None else budget.limit - budget.work
        work = np.array([0.0, float(allowed)])
        root, status = kernels.end_contact(self._end(s, body), (float(lo), float(stop), h),
                                           (C, D, ROOT_XTOL, MIN_SPLIT),
                                           (work, base.BLOCK_WORK))
        if budget is not None:
            budget.spend(int(work[0]))  # raises OverBudget where the search stopped for it
        if status == kernels.ROOT_FAILED or status == kernels.OVER_BUDGET:
            raise search_failed(s.t)
        return root

    def _earliest(self, s: RigidState, body: str) -> float:
        """No contact of ``body`` before this time (s after ``s``): the end is at most |a|
        below the centre of mass, which must first fall to that level."""
        gap = s.Y - abs(self.arm[body])
        if gap <= 0:
            return 0.0
        if self.g > 0:
            return (s.VY + math.sqrt(s.VY * s.VY + 2.0 * self.g * gap)) / self.g
        return gap / -s.VY if s.VY < 0 else math.inf


def supports(scene: Scene) -> str | None:
    """None if the closed-form rigid flight can run ``scene``, else why not."""
    if scene.system.rigid is None:
        return "the closed-form 2D solution is for a rigid dumbbell ([rigid]); use reference"
    if scene.system.resting_contact():
        return scene.system.resting_contact()
    if scene.system.floor is not None and scene.system.floor.friction > 0:
        return ("the exact rigid solution has a frictionless floor only (a contact with "
                "friction can slide and stick, not a single impulse); compare pymunk at a "
                "smaller dt instead")
    return None


def vertical_energy(scene: Scene) -> float:
    """The rigid dumbbell's energy at t = 0 that can move its centre of mass vertically (J):
    vertical kinetic, rotational, and potential above the floor (the horizontal motion is
    constant on a frictionless floor)."""
    body = RigidBody(scene)
    s = body.initial(scene)
    return float(translational_ke(body.M, 0.0, s.VY) + rotational_ke(body.moment, s.omega)
                 + gravity_potential(body.M, 0.0, -body.g, 0.0, s.Y))


def flight(scene: Scene, t_end: float) -> tuple[list[RigidState], list[Impact], Verdict]:
    """The free-flight segments up to ``t_end`` (s; each starts just after an impact), the
    impacts between them, and a verdict: ``failed`` when an end comes to rest or the run
    reaches its work budget (:data:`~dumbbell.solvers.base.MAX_IMPACTS` impacts,
    :data:`~.base.MAX_SEARCH_WORK` units of impact search)."""
    return base.within_budget(lambda segs, events: _flight(scene, t_end, segs, events),
                              lambda seg: seg.t)


def _flight(scene: Scene, t_end: float, segs: list[RigidState], events: list[Impact]
            ) -> tuple[list[RigidState], list[Impact], Verdict]:
    """:func:`flight`, filling ``segs`` and ``events`` as it goes."""
    body = RigidBody(scene)
    budget = SearchBudget(base.MAX_SEARCH_WORK)
    seg = body.initial(scene)
    segs.append(seg)
    if scene.system.floor is None:
        return segs, events, Verdict()
    e = scene.system.floor.elasticity
    start = {"A": 0.0, "B": 0.0}
    limit = base.MAX_IMPACTS
    while len(events) < limit:
        horizon = t_end - seg.t
        roots = {b: body.first_contact(seg, b, start[b], horizon, budget) for b in "AB"}
        tau = min(roots.values())
        if not tau <= horizon:
            return segs, events, Verdict()
        new = body.advance(seg, tau)
        hit = [b for b in "AB" if roots[b] - tau <= ROOT_XTOL * 10]
        new, hits, verdict = body.collide(new, hit, e)
        events += hits
        if not verdict.ok:
            return segs, events, verdict
        segs.append(new)
        seg = new
        for b in "AB":
            # Just off the floor at v_up, y >= v_up tau - C tau^2/2 > 0 until 2 v_up / C.
            v_up = body.vertical_velocity(new, b)
            C = body.curvature(new, b)
            start[b] = (v_up / C if C > 0 else horizon) if b in hit and v_up > 0 else 0.0
    return segs, events, Verdict("failed", seg.t, impact_budget_reason(limit))


def sample(scene: Scene, segs: list[RigidState], t: np.ndarray) -> dict[str, np.ndarray]:
    """The state columns at the sorted times ``t`` (s), each from the segment it falls in,
    all in one compiled pass (:func:`~dumbbell.solvers.kernels.exact.rigid_sample`)."""
    from .kernels.exact import rigid_sample

    body = RigidBody(scene)
    rows = np.array([[s.t, s.X, s.Y, s.VX, s.VY, s.theta, s.omega] for s in segs], dtype=float)
    out = rigid_sample(rows, t, float(body.arm["A"]), float(body.arm["B"]), float(body.g))
    cols = dict(zip([*state_columns(scene), "omega"], out, strict=True))
    if spins(scene):
        cols["omegaA"] = cols["omega"].copy()
        cols["omegaB"] = cols["omega"].copy()
    return cols


def first_impact_state(
    tilt: float, elasticity: float, mA: float = 0.1, mB: float = 0.1, length: float = 0.2,
    height: float = 1.0, g: float = 9.8,
) -> tuple[RigidState, RigidState]:
    """The rigid dumbbell dropped from rest onto a frictionless floor: its state just before
    and just after the first impact, found by the same search and impulse law as the
    ``exact`` solver.

    Parameters
    ----------
    tilt : float
        Its axis from vertical (degrees), A above B.
    elasticity : float
        The floor's restitution, 0..1.
    mA, mB : float, default 0.1
        The masses (kg).
    length : float, default 0.2
        The rod (m).
    height : float, default 1.0
        B's height at the release (m).
    g : float, default 9.8
        Gravity (m/s²).

    Returns
    -------
    before, after : RigidState
        The state (t, centre of mass X, Y, VX, VY, theta, omega, heights hA, hB) just before
        and just after the impact.

    Raises
    ------
    UsageError
        A tilt, height or other argument that is not allowed, named in the message.

    Examples
    --------
    >>> from dumbbell.solvers.exact_rigid import first_impact_state
    >>> before, after = first_impact_state(30.0, 1.0)
    >>> round(after.omega, 4), round(-after.VY / before.VY, 12)    # rad/s, e_eff
    (-35.4175, 0.6)
    """
    from ..model import args

    tilt = args.real(tilt, "tilt", "degrees from vertical", lo=-180.0, hi=180.0)
    elasticity = args.real(elasticity, "elasticity", "restitution", lo=0.0, hi=1.0)
    mA, mB = args.real(mA, "mA", "kg"), args.real(mB, "mB", "kg")
    length = args.real(length, "length", "m")
    height = args.real(height, "height", "m", lo=0.0)
    g = args.real(g, "g", "m/s^2")
    scene = scene_from_dict({
        "dimensions": 2, "tilt": float(tilt),
        "bodies": {"A": {"mass": float(mA)}, "B": {"mass": float(mB), "height": float(height)}},
        "rigid": {"length": float(length)}, "floor": {"elasticity": float(elasticity)},
        "gravity": {"g": float(g)}, "run": {"t_end": 1.0, "dt": 1e-3, "solver": "exact"},
    }, source="first_impact_state")
    body = RigidBody(scene)
    s = body.initial(scene)
    horizon = 1e3 * (1.0 + height)
    roots = {b: body.first_contact(s, b, 0.0, horizon) for b in "AB"}
    tau = min(roots.values())
    if not math.isfinite(tau):
        raise UsageError(f"g = {g:g}, height = {height:g}: the dumbbell never reaches the floor",
                         param="g")
    before = body.advance(s, tau)
    hit = [b for b in "AB" if roots[b] - tau <= ROOT_XTOL * 10]
    after, _, _ = body.collide(before, hit, float(elasticity))
    return before, after
