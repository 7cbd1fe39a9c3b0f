"""``exact``: the piecewise-analytic 1D solution (and, in :mod:`.exact_rigid`, the rigid 2D
dumbbell's closed-form flight).

Between impacts the centre of mass falls freely, ``X(t) = X0 + V0 t - g t^2/2``, and the
stretch ``s = xA - xB - b`` is a harmonic oscillator with ``w = sqrt(k/mu)``. Impacts are the
first roots of a particle's height, found by a search that cannot miss one: on an interval of
length h the height dips at most ``C h^2/8`` below its chord, with
``C = g + (m_other/M) w^2 S`` bounding its curvature (S the oscillation's amplitude), so an
interval is either cleared, split, or known to hold one crossing that ``brentq`` refines to
about 1e-14 s. That is the precision of one impact: the chaotic map amplifies rounding about
tenfold per impact, so late impacts are known less well. Grazing impacts are found by the splitting. Positions and velocities are then
evaluated in closed form at the sample times.

A particle that comes to rest on an inelastic floor would bounce infinitely often in finite
time; the run stops there with the verdict ``failed`` and says so.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..model.scene import Scene
from ..model.trajectory import Impact, Trajectory, Verdict
from . import base
from .base import RunOptions, SearchBudget, Solver, check_impacts, impact_budget_reason
from .verdicts import RawRun, conclude

#: The public API: the solver class (its supports and solve); the rest serves it.
__all__ = ["Exact"]

NAME = "exact"

#: Root tolerance for impact times (s).
ROOT_XTOL = 1e-14
#: Intervals shorter than this (s) are not split further: a dip below the floor inside one
#: would be shallower than C * MIN_SPLIT^2 / 8, about 1e-25 m.
MIN_SPLIT = 1e-13
#: A point of a particle's height curve, as the root searches pass it: time (s), height (m)
#: and vertical velocity (m/s).
HeightPoint = tuple[float, float, float]
#: An impact slower than this (m/s) means the particle has come to rest on the floor.
REST_SPEED = 1e-9


@dataclass(frozen=True)
class Segment:
    """Free motion from time ``t0`` (s): centre of mass X0 (m), V0 (m/s); stretch s0 (m) and
    its rate sd0 (m/s)."""

    t0: float
    X0: float
    V0: float
    s0: float
    sd0: float


class _Motion:
    """Closed-form motion of one segment; ``tau`` is the time since the segment began (s)."""

    def __init__(self, scene: Scene):
        self.g = scene.system.g
        self.M = scene.system.M
        self.cA = scene.system.B.mass / scene.system.M  # xA = X + cA (b + s)
        self.cB = scene.system.A.mass / scene.system.M  # xB = X - cB (b + s)
        self.b = scene.system.b
        self.w = scene.system.omega

    def stretch(self, seg: Segment, tau):
        if self.w > 0:
            cos, sin = np.cos(self.w * tau), np.sin(self.w * tau)
            return (seg.s0 * cos + (seg.sd0 / self.w) * sin,
                    -seg.s0 * self.w * sin + seg.sd0 * cos)
        return seg.s0 + seg.sd0 * tau, seg.sd0 + 0.0 * tau

    def state(self, seg: Segment, tau):
        """xA, vA, xB, vB at ``tau`` (scalars or arrays)."""
        X = seg.X0 + seg.V0 * tau - 0.5 * self.g * tau * tau
        V = seg.V0 - self.g * tau
        s, sd = self.stretch(seg, tau)
        return (X + self.cA * (self.b + s), V + self.cA * sd,
                X - self.cB * (self.b + s), V - self.cB * sd)

    def height(self, seg: Segment, body: str, tau):
        """Height of ``body`` (m) and its rate (m/s) at ``tau`` (an array of times)."""
        xA, vA, xB, vB = self.state(seg, tau)
        return (xA, vA) if body == "A" else (xB, vB)

    def height_at(self, seg: Segment, body: str, tau: float) -> tuple[float, float]:
        """:meth:`height` at one time, in plain floats: the root search calls it hundreds of
        times per impact, where numpy's per-call overhead would dominate."""
        X = seg.X0 + seg.V0 * tau - 0.5 * self.g * tau * tau
        V = seg.V0 - self.g * tau
        if self.w > 0:
            cos, sin = math.cos(self.w * tau), math.sin(self.w * tau)
            s = seg.s0 * cos + (seg.sd0 / self.w) * sin
            sd = -seg.s0 * self.w * sin + seg.sd0 * cos
        else:
            s, sd = seg.s0 + seg.sd0 * tau, seg.sd0
        if body == "A":
            return X + self.cA * (self.b + s), V + self.cA * sd
        return X - self.cB * (self.b + s), V - self.cB * sd

    def amplitude(self, seg: Segment) -> float:
        """Largest |s| the segment reaches (m); inf without a spring."""
        return math.hypot(seg.s0, seg.sd0 / self.w) if self.w > 0 else math.inf

    def segment_at(self, t0: float, xA: float, vA: float, xB: float, vB: float) -> Segment:
        mA_M, mB_M = self.cB, self.cA
        return Segment(t0, mA_M * xA + mB_M * xB, mA_M * vA + mB_M * vB,
                       xA - xB - self.b, vA - vB)


def _earliest_possible(motion: _Motion, seg: Segment, body: str) -> float:
    """No impact of ``body`` can happen before this time (s): its height stays within
    c*S of the centre-of-mass curve, so the centre of mass must first fall to that level."""
    S = motion.amplitude(seg)
    if not math.isfinite(S):
        return 0.0
    level = motion.cB * (motion.b + S) if body == "B" else motion.cA * (S - motion.b)
    gap = seg.X0 - level
    if gap <= 0:
        return 0.0
    g, V0 = motion.g, seg.V0
    if g > 0:
        return (V0 + math.sqrt(V0 * V0 + 2.0 * g * gap)) / g
    return gap / -V0 if V0 < 0 else math.inf


def _first_root(motion: _Motion, seg: Segment, body: str, start: float, stop: float,
                budget: SearchBudget | None = None) -> float:
    """First time in (start, stop] at which ``body`` crosses the floor going down, or inf;
    each block scanned and
    interval split counts against ``budget``."""
    from scipy.optimize import brentq  # scipy loads only when the exact solver runs

    S = motion.amplitude(seg)
    c = motion.cB if body == "B" else motion.cA
    C = motion.g + (c * motion.w**2 * S if motion.w > 0 else 0.0)
    period = 2 * math.pi / motion.w if motion.w > 0 else math.inf
    h = min(period / 16.0, 0.05)
    a = max(start, _earliest_possible(motion, seg, body))
    block = 64

    def f(tau: float) -> tuple[float, float]:
        return motion.height_at(seg, body, tau)

    def search(low: HeightPoint, high: HeightPoint) -> float:
        # Curvature bound: below the chord by at most C h^2 / 8; the slope changes by <= C h.
        (lo, flo, dlo), (hi, fhi, dhi) = low, high
        width = hi - lo
        if flo > 0 and fhi > 0 and min(flo, fhi) - C * width * width / 8.0 > 0:
            return math.inf
        if flo > 0 and fhi <= 0 and min(dlo, dhi) + C * width < 0:
            # Strictly decreasing on the interval: exactly one crossing.
            return brentq(lambda x: f(x)[0], lo, hi, xtol=ROOT_XTOL, rtol=4 * np.finfo(float).eps)
        if width < MIN_SPLIT:
            return hi if fhi <= 0 else math.inf
        if budget is not None:
            budget.spend()
        mid = 0.5 * (lo + hi)
        middle = (mid, *f(mid))
        left = search(low, middle)
        if left < math.inf:
            return left
        return search(middle, high)

    while a < stop:
        if budget is not None:
            budget.spend(base.BLOCK_WORK)
        taus = np.minimum(a + h * np.arange(block + 1), stop)
        fs, ds = motion.height(seg, body, taus)
        width = np.diff(taus)
        lower = np.minimum(fs[:-1], fs[1:]) - C * width * width / 8.0
        suspect = np.flatnonzero((lower <= 0) & (width > 0))
        for j in suspect:
            root = search((float(taus[j]), float(fs[j]), float(ds[j])),
                          (float(taus[j + 1]), float(fs[j + 1]), float(ds[j + 1])))
            if root < math.inf:
                return root
        a = taus[-1]
    return math.inf


def supports(scene: Scene) -> str | None:
    """None if this solver can run ``scene``, else why not."""
    if scene.system.dimensions != 1:
        if scene.system.rigid is not None:
            from .exact_rigid import supports as rigid_supports

            return rigid_supports(scene)
        return ("the exact solution covers 1D scenes and the rigid 2D dumbbell; use the "
                "reference solver for a 2D spring")
    return scene.system.resting_contact()


def segments(scene: Scene, t_end: float) -> tuple[list[Segment], list[Impact], Verdict]:
    """The free-flight segments up to ``t_end`` (s), the impacts between them, and a verdict:
    ``failed`` when a particle comes to rest or the run reaches its work budget
    (:data:`~dumbbell.solvers.base.MAX_IMPACTS` impacts, :data:`~.base.MAX_SEARCH_WORK`
    units of impact search)."""
    return base.within_budget(lambda segs, events: _segments(scene, t_end, segs, events),
                              lambda seg: seg.t0)


def _segments(scene: Scene, t_end: float, segs: list[Segment], events: list[Impact]
              ) -> tuple[list[Segment], list[Impact], Verdict]:
    """:func:`segments`, filling ``segs`` and ``events`` as it goes."""
    motion = _Motion(scene)
    budget = SearchBudget(base.MAX_SEARCH_WORK)
    A, B = scene.system.A, scene.system.B
    seg = motion.segment_at(0.0, A.height, A.vy, B.height, B.vy)
    segs.append(seg)
    if scene.system.floor is None:
        return segs, events, Verdict()
    e = scene.system.floor.elasticity
    # After an impact the particle is on the floor moving up: no new root before this time.
    start = {"A": 0.0, "B": 0.0}
    limit = base.MAX_IMPACTS
    while len(events) < limit:
        horizon = t_end - seg.t0
        roots = {body: _first_root(motion, seg, body, start[body], horizon, budget)
                 for body in "AB"}
        tau = min(roots.values())
        if not tau <= horizon:
            return segs, events, Verdict()
        xA, vA, xB, vB = (float(v) for v in motion.state(seg, tau))
        t_hit = seg.t0 + tau
        velocities = {"A": vA, "B": vB}
        hit = [body for body in "AB" if roots[body] - tau <= ROOT_XTOL * 10]
        for body in hit:
            v = velocities[body]
            if abs(v) < REST_SPEED:
                return segs, events, Verdict(
                    "failed", t_hit,
                    f"{body} came to rest on the floor (impact speed {abs(v):.1e} m/s): an "
                    "inelastic floor has infinitely many impacts in finite time here",
                )
            velocities[body] = -e * v
            events.append(Impact(t_hit, body, v, velocities[body]))
        seg = motion.segment_at(t_hit, xA, velocities["A"], xB, velocities["B"])
        segs.append(seg)
        C = motion.g + max(motion.cA, motion.cB) * motion.w**2 * motion.amplitude(seg)
        for body in "AB":
            v_up = velocities[body]
            start[body] = (v_up / C if body in hit and C > 0 else 0.0)
            if body in hit and C == 0:
                start[body] = horizon  # straight line up, never to return
    return segs, events, Verdict("failed", seg.t0, impact_budget_reason(limit))


def vertical_energy(scene: Scene) -> float:
    """The scene's energy at t = 0 that can move the centre of mass vertically (J): every
    term but the horizontal motion (none in 1D; constant on a frictionless floor in 2D)."""
    from ..model.energy import gravity_potential, spring_potential, translational_ke

    system = scene.system
    if system.rigid is not None:
        from .exact_rigid import vertical_energy as rigid_energy

        return rigid_energy(scene)
    A, B, g = system.A, system.B, system.g
    return float(translational_ke(A.mass, 0.0, A.vy) + translational_ke(B.mass, 0.0, B.vy)
                 + gravity_potential(A.mass, 0.0, -g, 0.0, A.height)
                 + gravity_potential(B.mass, 0.0, -g, 0.0, B.height)
                 + spring_potential(system.k, A.height - B.height, system.b))


def check_work(scene: Scene, options: RunOptions) -> None:
    """UsageError before any work when the run must locate more impacts than
    :data:`~dumbbell.solvers.base.MAX_IMPACTS` (:func:`~.base.check_impacts`)."""
    check_impacts(scene, options, vertical_energy(scene), base.MAX_IMPACTS)


def solve(scene: Scene, options: RunOptions) -> Trajectory:
    """Evaluate the exact solution at the sample times ``i * every * dt`` (s)."""
    check_work(scene, options)
    if scene.system.rigid is not None:
        return _solve_rigid(scene, options)
    t0 = time.perf_counter()
    segs, events, verdict = segments(scene, options.t_end)
    motion = _Motion(scene)
    t = options.sample_times()
    if not verdict.ok:
        t = t[t <= verdict.t]
    # Sample times are sorted, so each segment owns one contiguous slice of them.
    bounds = np.searchsorted(t, [s.t0 for s in segs[1:]], side="left")
    cols = {name: np.empty_like(t) for name in ("xA", "vA", "xB", "vB")}
    for seg, lo, hi in zip(segs, [0, *bounds], [*bounds, len(t)], strict=True):
        if hi > lo:
            for name, value in zip(cols, motion.state(seg, t[lo:hi] - seg.t0), strict=True):
                cols[name][lo:hi] = value
    wall = time.perf_counter() - t0
    return conclude(Exact, scene, options, RawRun(t, cols, events, verdict, wall,
                                                  {"segments": len(segs), "root_xtol": ROOT_XTOL}))


def _solve_rigid(scene: Scene, options: RunOptions) -> Trajectory:
    """The rigid 2D dumbbell in closed form (:mod:`.exact_rigid`) at the sample times (s)."""
    from ..model.energy import rigid_moment
    from .exact_rigid import ROOT_XTOL as RIGID_XTOL
    from .exact_rigid import flight, sample

    t0 = time.perf_counter()
    segs, events, verdict = flight(scene, options.t_end)
    t = options.sample_times()
    if not verdict.ok:
        t = t[t <= verdict.t]
    cols = sample(scene, segs, t)
    wall = time.perf_counter() - t0
    return conclude(Exact, scene, options, RawRun(t, cols, events, verdict, wall,
                                                  {"segments": len(segs), "root_xtol": RIGID_XTOL,
                                                   "moment": rigid_moment(scene)}))


class Exact(Solver):
    """The closed-form 1D solution with impacts found by root search (see the module
    docstring)."""

    name = NAME
    order = None
    has_step = False
    step_limit = None
    flip_floor = True
    relative_cost = 0.01
    is_truth = True
    estimates_error = False
    supports = staticmethod(supports)
    solve = staticmethod(solve)
    check_work = staticmethod(check_work)

    @staticmethod
    def truth_for(scene: Scene) -> bool:
        """The truth for 1D scenes and the rigid 2D dumbbell."""
        return scene.system.dimensions == 1 or scene.system.rigid is not None
