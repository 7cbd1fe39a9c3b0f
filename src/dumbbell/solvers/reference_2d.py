"""The reference's 2D spring dumbbell: only the relative vector is integrated, and no impact
can be missed.

Between impacts the centre of mass R follows its parabola in closed form (gravity is uniform and
the spring is internal). Only d = rA - rB has no closed form: ``mu d'' = -k (|d| - b) d/|d|``,
a central force, with gravity gone. It is integrated by the 8th-order Runge-Kutta formula of
Dormand and Prince (the 12 stages of DOP853, coefficients from scipy) at a fixed step, compiled
with numba (:mod:`.kernels.reference_2d`). The step is ``STEP_ANGLE / rate``, where rate
bounds how fast the state turns: the spring's w = sqrt(k/mu) and the axis' fastest rotation
|d x d'| / r_min^2 (r_min the shortest length the segment's relative energy allows); every
sample time is a step end, so samples need no interpolation.

The guarantee against a missed impact is a bound, not a heuristic: between impacts each
particle's height ``y = R_y + c d_y`` (c = mB/M for A, -mA/M for B) has
``|y''| <= C = g + |c| w^2 S``, with S the largest stretch the segment's relative energy
allows (``d'' = -w^2 (|d| - b) u``). On a step of length h the height lies at most
``C h^2 / 8`` below its chord, so a step whose ends clear that margin holds no contact; any
other step is searched as ``exact`` does (split, or ``brentq`` where the height provably falls
monotonically), its interior evaluated by a single Runge-Kutta step from the step's start. The
particle that just bounced at speed v cannot return before ``v / C`` (``y >= v t - C t^2/2``).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from ..model.energy import spins
from ..model.scene import Scene
from ..model.trajectory import Impact, Verdict
from ._closed_form import REST_SPEED, HeightPoint
from .base import impact_budget_reason
from .verdicts import rest_reason

#: Nothing public: the machinery the solver classes share.
__all__: list[str] = []

#: The fixed step turns the state by at most this angle (rad): RK8's local error is then
#: about STEP_ANGLE^9, 5e-16 of the motion's scale.
STEP_ANGLE = 0.02
ROOT_XTOL = 1e-14
MIN_SPLIT = 1e-13
MAX_IMPACTS = 100_000


def warm_up() -> None:
    """Compile the kernels (or load them from numba's cache)."""
    from .kernels.reference_2d import Span, run

    s = np.array([0.2, 0.0, 0.0, 0.0])
    out = np.empty((1, 4))
    span = Span(0.0, 1.0, 0.0, 1e-3, 9.8, 0.5, 0.5, 1.0, 1.0, -1.0, -1.0, 4000.0, 0.2)
    run(s, 0.0, np.array([1e-3]), 0, span, out, np.empty(5))


def integrate(scene: Scene, times: np.ndarray, t_end: float, step_angle: float = STEP_ANGLE,
              pb: object | None = None
              ) -> tuple[dict[str, np.ndarray], list[Impact], Verdict, int]:
    """The 2D spring dumbbell sampled at ``times`` (s, sorted): state columns of the samples
    reached, impacts, verdict, and the number of Runge-Kutta steps taken."""
    return _Integration(scene, times, step_angle).run(pb)


class _Integration:
    """One integration in progress: the centre-of-mass segments ``(t0, X0, Y0, VX, VY0)``,
    the relative state ``s = (d, d')`` at time ``t``, the samples reached (``k``), the
    current segment's step and curvature bounds, and when each particle is ``quiet`` (cannot
    reach the floor) after its last impact."""

    def __init__(self, scene: Scene, times: np.ndarray, step_angle: float) -> None:
        from .kernels import reference_2d as kernels

        self.kernels = kernels
        self.scene = scene
        self.step_angle = step_angle
        A, B = scene.system.A, scene.system.B
        self.M, self.g = scene.system.M, scene.system.g
        M = self.M
        self.cA, self.cB = B.mass / M, A.mass / M
        self.w2 = scene.system.omega**2
        self.b = scene.system.b
        self.e = scene.system.floor.elasticity if scene.system.floor is not None else 1.0
        self.floor = scene.system.floor is not None
        self.times = np.ascontiguousarray(times, dtype=np.float64)
        self.out = np.empty((len(self.times), 4))
        X0 = (A.mass * A.x + B.mass * B.x) / M
        Y0 = (A.mass * A.height + B.mass * B.height) / M
        VX = (A.mass * A.vx + B.mass * B.vx) / M
        VY0 = (A.mass * A.vy + B.mass * B.vy) / M
        self.s = np.array([A.x - B.x, A.height - B.height, A.vx - B.vx, A.vy - B.vy],
                          dtype=np.float64)
        self.segs = [(0.0, X0, Y0, VX, VY0)]
        self.t, self.k = 0.0, 0
        self.quiet = {"A": -1.0, "B": -1.0}
        self.impacts: list[Impact] = []
        self.verdict = Verdict()
        self.steps = 0
        self.nxt = np.empty(5)
        self.hmax, self.CA, self.CB = self.bounds(self.s)

    def run(self, pb: object | None) -> tuple[dict[str, np.ndarray], list[Impact], Verdict,
                                               int]:
        """Step to the last sample, stopping at every impact; the results of
        :func:`integrate`."""
        while self.k < len(self.times):
            if self.advance(pb) == 0:
                break
            # A suspect step [t, t1]: search each particle's first contact in it.
            t1 = float(self.nxt[4])
            s0 = self.s.copy()
            roots = self.contacts(s0, t1)
            hit_t = min(roots.values(), default=math.inf)
            if not math.isfinite(hit_t):
                # Cleared on closer look: take the step.
                self.s[:] = self.nxt[:4]
                self.t = t1
                continue
            hit = [body for body, r in roots.items() if r - hit_t <= 10 * ROOT_XTOL]
            if not self.bounce(s0, hit_t, hit):
                break
        k = self.k
        cols = _columns(self.scene, self.segs, self.times[:k], self.out[:k])
        return cols, self.impacts, self.verdict, self.steps

    def bounds(self, s: np.ndarray) -> tuple[float, float, float]:
        """Step length (s) and the curvature bounds C_A, C_B (m/s^2) of this segment."""
        w2, b = self.w2, self.b
        r = math.hypot(s[0], s[1])
        v2 = s[2] ** 2 + s[3] ** 2
        energy = 0.5 * v2 + 0.5 * w2 * (r - b) ** 2  # per unit reduced mass
        S = math.sqrt(2.0 * energy / w2) if w2 > 0 else 0.0
        spin = 0.0
        if w2 > 0 and b > 0:
            # Without a spring, or with rest length 0, d'' is linear in d: no turning rate
            # limits the step. Otherwise the axis turns fastest at its shortest; where it may
            # pass near zero length, the rate is capped there (accuracy, not the guarantee).
            r_min = max(b - S, 0.05 * max(b, r))
            spin = abs(s[0] * s[3] - s[1] * s[2]) / r_min**2
        rate = max(math.sqrt(w2), spin, 1e-300)
        return self.step_angle / rate, self.g + self.cA * w2 * S, self.g + self.cB * w2 * S

    def advance(self, pb: object | None) -> int:
        """Run the compiled loop from ``t`` until a suspect step (returns 1, its end in
        ``nxt``) or past the last sample (returns 0), moving the progress bar."""
        t0, _, Ys, _, VYs = self.segs[-1]
        qa, qb = (self.quiet["A"], self.quiet["B"]) if self.floor else (math.inf, math.inf)
        span = self.kernels.Span(t0, Ys, VYs, self.hmax, self.g, self.cA, self.cB, self.CA,
                                 self.CB, qa, qb, self.w2, self.b)
        k = self.k
        status, self.t, self.k, count = self.kernels.run(self.s, self.t, self.times, k, span,
                                                         self.out, self.nxt)
        self.steps += count
        if pb is not None:
            pb.update(self.t - (self.times[k - 1] if k else 0.0))  # type: ignore[attr-defined]
        return status

    def relative(self, s0: np.ndarray, tau: float) -> np.ndarray:
        """The relative state at ``tau`` (s) inside the step that starts at ``t`` from ``s0``:
        a single Runge-Kutta step."""
        if tau == self.t:
            return s0.copy()
        res = np.empty(4)
        self.kernels.step(s0, tau - self.t, self.w2, self.b, res)
        return res

    def height(self, s0: np.ndarray, body: str, tau: float) -> tuple[float, float]:
        """Height (m) and vertical velocity (m/s) of ``body`` at ``tau`` (s) in the step."""
        t0, _, Ys, _, VYs = self.segs[-1]
        x = self.relative(s0, tau)
        c = self.cA if body == "A" else -self.cB
        ta = tau - t0
        g = self.g
        return (float(Ys + VYs * ta - 0.5 * g * ta * ta + c * x[1]),
                float(VYs - g * ta + c * x[3]))

    def contacts(self, s0: np.ndarray, t1: float) -> dict[str, float]:
        """Each particle's first contact time (s, inf if none) in the step [t, t1]."""
        roots = {}
        for body, C in (("A", self.CA), ("B", self.CB)):
            lo = max(self.t, self.quiet[body])
            if lo < t1:
                roots[body] = _first_root(lambda tau, body=body: self.height(s0, body, tau),
                                          C, lo, t1)
        return roots

    def bounce(self, s0: np.ndarray, hit_t: float, hit: list[str]) -> bool:
        """Reflect the particles in ``hit`` at ``hit_t`` (s) and start a new segment there;
        False when the run ends (a particle at rest, too many impacts)."""
        A, B = self.scene.system.A, self.scene.system.B
        M, g, cA, cB = self.M, self.g, self.cA, self.cB
        t0, Xs, Ys, VXs, VYs = self.segs[-1]
        x = self.relative(s0, hit_t)
        ta = hit_t - t0
        R = (Xs + VXs * ta, Ys + VYs * ta - 0.5 * g * ta * ta)
        V = [VXs, VYs - g * ta]
        vA = [float(V[0] + cA * x[2]), float(V[1] + cA * x[3])]
        vB = [float(V[0] - cB * x[2]), float(V[1] - cB * x[3])]
        vel = {"A": vA, "B": vB}
        for body in hit:
            v_before = float(vel[body][1])
            if abs(v_before) < REST_SPEED:
                self.verdict = Verdict("failed", hit_t, rest_reason(body, v_before))
                self.t = hit_t
                return False
            vel[body][1] = -self.e * v_before
            self.impacts.append(Impact(hit_t, body, v_before, vel[body][1]))
        V = [(A.mass * vA[0] + B.mass * vB[0]) / M, (A.mass * vA[1] + B.mass * vB[1]) / M]
        self.s = np.array([x[0], x[1], vA[0] - vB[0], vA[1] - vB[1]], dtype=np.float64)
        self.segs.append((hit_t, R[0], R[1], V[0], V[1]))
        self.t = hit_t
        self.hmax, self.CA, self.CB = self.bounds(self.s)
        for body in hit:
            C = self.CA if body == "A" else self.CB
            self.quiet[body] = hit_t + (vel[body][1] / C if C > 0 else math.inf)
        if len(self.impacts) >= MAX_IMPACTS:
            self.verdict = Verdict("failed", self.t, impact_budget_reason(MAX_IMPACTS))
            return False
        return True


def _first_root(f, C: float, lo: float, hi: float) -> float:
    """First time in (lo, hi] where the height ``f(t) -> (y, y')`` reaches the floor moving
    down, given |y''| <= C (m/s^2); inf if none."""

    def y(tau: float) -> float:
        return f(tau)[0]

    def search(low: HeightPoint, high: HeightPoint) -> float:
        (lo, flo, dlo), (hi, fhi, dhi) = low, high
        width = hi - lo
        if flo <= 0 and dlo < 0:
            return lo  # on (or, by rounding, just below) the floor and moving down
        if flo > 0 and fhi > 0 and min(flo, fhi) - C * width * width / 8.0 > 0:
            return math.inf
        if flo > 0 and fhi <= 0 and min(dlo, dhi) + C * width < 0:
            return brentq(y, lo, hi, xtol=ROOT_XTOL, rtol=4 * np.finfo(float).eps)
        if width < MIN_SPLIT:
            return hi if flo > 0 and fhi <= 0 else math.inf
        mid = 0.5 * (lo + hi)
        middle = (mid, *f(mid))
        left = search(low, middle)
        return left if left < math.inf else search(middle, high)

    return search((lo, *f(lo)), (hi, *f(hi)))


def _columns(scene: Scene, segs: list[tuple[float, float, float, float, float]],
             t: np.ndarray, rel: np.ndarray) -> dict[str, np.ndarray]:
    """Particle positions (m) and velocities (m/s) at the samples from the centre-of-mass
    segments (closed form) and the relative state."""
    g, M = scene.system.g, scene.system.M
    cA, cB = scene.system.B.mass / M, scene.system.A.mass / M
    R = np.empty((len(t), 4))
    bounds = np.searchsorted(t, [s[0] for s in segs[1:]], side="left")
    for (t0, X0, Y0, VX, VY0), lo, hi in zip(segs, [0, *bounds], [*bounds, len(t)],
                                             strict=True):
        tau = t[lo:hi] - t0
        R[lo:hi, 0] = X0 + VX * tau
        R[lo:hi, 1] = Y0 + VY0 * tau - 0.5 * g * tau * tau
        R[lo:hi, 2] = VX
        R[lo:hi, 3] = VY0 - g * tau
    cols = {
        "xA": R[:, 0] + cA * rel[:, 0], "yA": R[:, 1] + cA * rel[:, 1],
        "vxA": R[:, 2] + cA * rel[:, 2], "vyA": R[:, 3] + cA * rel[:, 3],
        "xB": R[:, 0] - cB * rel[:, 0], "yB": R[:, 1] - cB * rel[:, 1],
        "vxB": R[:, 2] - cB * rel[:, 2], "vyB": R[:, 3] - cB * rel[:, 3],
    }
    if spins(scene):  # frictionless: the circles keep their initial spins
        cols["omegaA"] = np.full(len(t), scene.system.A.spin)
        cols["omegaB"] = np.full(len(t), scene.system.B.spin)
    return cols
