"""The reference's 2D spring dumbbell: only the relative vector is integrated, and no impact
can be missed.

Between impacts the centre of mass R follows its parabola in closed form (gravity is uniform and
the spring is internal). Only d = rA - rB has no closed form: ``mu d'' = -k (|d| - b) d/|d|``,
a central force, with gravity gone. It is integrated by the 8th-order Runge-Kutta formula of
Dormand and Prince (the 12 stages of DOP853, coefficients from scipy) at a fixed step, compiled
with numba. The step is ``STEP_ANGLE / rate``, where rate bounds how fast the state turns: the
spring's w = sqrt(k/mu) and the axis' fastest rotation |d x d'| / r_min^2 (r_min the shortest
length the segment's relative energy allows); every sample time is a step end, so samples need
no interpolation.

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

import functools
import math

import numpy as np
from scipy.optimize import brentq

from ..model.energy import spins
from ..model.scene import Scene
from ..model.trajectory import Impact, Verdict

#: The fixed step turns the state by at most this angle (rad): RK8's local error is then
#: about STEP_ANGLE^9, 5e-16 of the motion's scale.
STEP_ANGLE = 0.02
ROOT_XTOL = 1e-14
MIN_SPLIT = 1e-13
REST_SPEED = 1e-9
MAX_IMPACTS = 100_000


@functools.cache
def _kernels():
    """The compiled RK8 step and the stepping loop (compiled on first use)."""
    from numba import njit
    from scipy.integrate._ivp import dop853_coefficients as dop

    n = dop.N_STAGES
    A = np.ascontiguousarray(dop.A[:n, :n])
    B = np.ascontiguousarray(dop.B)

    @njit(cache=True, nogil=True)
    def rhs(s, w2, b, out):  # pragma: no cover
        dx, dy = s[0], s[1]
        r = math.sqrt(dx * dx + dy * dy)
        f = -w2 * (r - b) / r if r > 0 else -w2
        out[0] = s[2]
        out[1] = s[3]
        out[2] = f * dx
        out[3] = f * dy

    @njit(cache=True, nogil=True)
    def step(s, h, w2, b, out):  # pragma: no cover
        K = np.empty((n, 4))
        tmp = np.empty(4)
        for i in range(n):
            for c in range(4):
                acc = 0.0
                for j in range(i):
                    acc += A[i, j] * K[j, c]
                tmp[c] = s[c] + h * acc
            rhs(tmp, w2, b, K[i])
        for c in range(4):
            acc = 0.0
            for i in range(n):
                acc += B[i] * K[i, c]
            out[c] = s[c] + h * acc

    @njit(cache=True, nogil=True)
    def run(s, t, times, k, hmax, seg, g, cA, cB, CA, CB, quietA, quietB, w2, b, out, nxt):
        """Step from (t, s) through the sample times ``times[k:]``, writing samples into
        ``out``; stop before a step whose ends do not clear the curvature margin of a particle
        (returns 1, with the step's end state and time in ``nxt``) or after the last sample
        (returns 0); also the time reached, the next sample index and the steps taken."""
        t0, Y0, VY0 = seg[0], seg[1], seg[2]
        new = np.empty(4)
        count = 0
        while k < times.size:
            target = times[k]
            if target > t:
                m = math.ceil((target - t) / hmax)
                h = (target - t) / m
                for j in range(m):
                    t1 = target if j == m - 1 else t + h
                    step(s, t1 - t, w2, b, new)
                    count += 1
                    ta, tb = t - t0, t1 - t0
                    ya = Y0 + VY0 * ta - 0.5 * g * ta * ta
                    yb = Y0 + VY0 * tb - 0.5 * g * tb * tb
                    hh = t1 - t
                    suspect = False
                    margin = hh * hh / 8.0
                    if t1 > quietA and min(ya + cA * s[1], yb + cA * new[1]) <= CA * margin:
                        suspect = True
                    if t1 > quietB and min(ya - cB * s[1], yb - cB * new[1]) <= CB * margin:
                        suspect = True
                    if suspect:
                        for c in range(4):
                            nxt[c] = new[c]
                        nxt[4] = t1
                        return 1, t, k, count
                    for c in range(4):
                        s[c] = new[c]
                    t = t1
            for c in range(4):
                out[k, c] = s[c]
            k += 1
        return 0, t, k, count

    return step, run


def warm_up() -> None:
    """Compile the kernels (or load them from numba's cache)."""
    run = _kernels()[1]
    s = np.array([0.2, 0.0, 0.0, 0.0])
    out = np.empty((1, 4))
    run(s, 0.0, np.array([1e-3]), 0, 1e-3, np.array([0.0, 1.0, 0.0]), 9.8, 0.5, 0.5, 1.0, 1.0,
        -1.0, -1.0, 4000.0, 0.2, out, np.empty(5))


def integrate(scene: Scene, times: np.ndarray, t_end: float, step_angle: float = STEP_ANGLE,
              pb: object | None = None
              ) -> tuple[dict[str, np.ndarray], list[Impact], Verdict, int]:
    """The 2D spring dumbbell sampled at ``times`` (s, sorted): state columns of the samples
    reached, impacts, verdict, and the number of Runge-Kutta steps taken."""
    step, run = _kernels()
    A, B = scene.system.A, scene.system.B
    M, g = scene.system.M, scene.system.g
    cA, cB = B.mass / M, A.mass / M
    w2 = scene.system.omega**2
    b = scene.system.b
    e = scene.system.floor.elasticity if scene.system.floor is not None else 1.0
    floor = scene.system.floor is not None
    times = np.ascontiguousarray(times, dtype=np.float64)
    out = np.empty((len(times), 4))
    # Centre-of-mass segments: (t0, X0, Y0, VX, VY0); relative state s = (d, d').
    X0 = (A.mass * A.x + B.mass * B.x) / M
    Y0 = (A.mass * A.height + B.mass * B.height) / M
    VX = (A.mass * A.vx + B.mass * B.vx) / M
    VY0 = (A.mass * A.vy + B.mass * B.vy) / M
    s = np.array([A.x - B.x, A.height - B.height, A.vx - B.vx, A.vy - B.vy], dtype=np.float64)
    segs = [(0.0, X0, Y0, VX, VY0)]
    t, k = 0.0, 0
    quiet = {"A": -1.0, "B": -1.0}
    impacts: list[Impact] = []
    verdict = Verdict()
    steps = 0
    nxt = np.empty(5)

    def bounds(s: np.ndarray) -> tuple[float, float, float]:
        """Step length (s) and the curvature bounds C_A, C_B (m/s^2) of this segment."""
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
        return step_angle / rate, g + cA * w2 * S, g + cB * w2 * S

    hmax, CA, CB = bounds(s)
    while k < len(times):
        t0, Xs, Ys, VXs, VYs = segs[-1]
        seg = np.array([t0, Ys, VYs])
        qa, qb = (quiet["A"], quiet["B"]) if floor else (math.inf, math.inf)
        status, t, k2, count = run(s, t, times, k, hmax, seg, g, cA, cB, CA, CB, qa, qb, w2, b,
                                   out, nxt)
        steps += count
        if pb is not None:
            pb.update(t - (times[k - 1] if k else 0.0))  # type: ignore[attr-defined]
        k = k2
        if status == 0:
            break
        # A suspect step [t, t1]: search each particle's first contact in it.
        t1 = float(nxt[4])
        s0 = s.copy()

        def state(tau: float, s0: np.ndarray = s0, t=t) -> np.ndarray:
            if tau == t:
                return s0.copy()
            res = np.empty(4)
            step(s0, tau - t, w2, b, res)
            return res

        def height(body: str, tau: float, t0=t0, Ys=Ys, VYs=VYs) -> tuple[float, float]:
            x = state(tau)
            c = cA if body == "A" else -cB
            ta = tau - t0
            return (float(Ys + VYs * ta - 0.5 * g * ta * ta + c * x[1]),
                    float(VYs - g * ta + c * x[3]))

        roots = {}
        for body, C in (("A", CA), ("B", CB)):
            lo = max(t, quiet[body])
            if lo < t1:
                roots[body] = _first_root(lambda tau, body=body: height(body, tau), C, lo, t1)
        hit_t = min(roots.values(), default=math.inf)
        if not math.isfinite(hit_t):
            # Cleared on closer look: take the step.
            s[:] = nxt[:4]
            t = t1
            continue
        hit = [body for body, r in roots.items() if r - hit_t <= 10 * ROOT_XTOL]
        x = state(hit_t)
        ta = hit_t - t0
        R = (Xs + VXs * ta, Ys + VYs * ta - 0.5 * g * ta * ta)
        V = [VXs, VYs - g * ta]
        vA = [float(V[0] + cA * x[2]), float(V[1] + cA * x[3])]
        vB = [float(V[0] - cB * x[2]), float(V[1] - cB * x[3])]
        vel = {"A": vA, "B": vB}
        for body in hit:
            v_before = float(vel[body][1])
            if abs(v_before) < REST_SPEED:
                verdict = Verdict("failed", hit_t, f"{body} came to rest on the floor (impact "
                                  f"speed {abs(v_before):.1e} m/s): infinitely many impacts "
                                  "ahead")
                break
            vel[body][1] = -e * v_before
            impacts.append(Impact(hit_t, body, v_before, vel[body][1]))
        if not verdict.ok:
            t = hit_t
            break
        V = [(A.mass * vA[0] + B.mass * vB[0]) / M, (A.mass * vA[1] + B.mass * vB[1]) / M]
        s = np.array([x[0], x[1], vA[0] - vB[0], vA[1] - vB[1]], dtype=np.float64)
        segs.append((hit_t, R[0], R[1], V[0], V[1]))
        t = hit_t
        hmax, CA, CB = bounds(s)
        for body in hit:
            C = CA if body == "A" else CB
            quiet[body] = hit_t + (vel[body][1] / C if C > 0 else math.inf)
        if len(impacts) >= MAX_IMPACTS:
            verdict = Verdict("failed", t, f"more than {MAX_IMPACTS} impacts")
            break
    return _columns(scene, segs, times[:k], out[:k], cA, cB), impacts, verdict, steps


def _first_root(f, C: float, lo: float, hi: float) -> float:
    """First time in (lo, hi] where the height ``f(t) -> (y, y')`` reaches the floor moving
    down, given |y''| <= C (m/s^2); inf if none."""

    def y(tau: float) -> float:
        return f(tau)[0]

    def search(lo, flo, dlo, hi, fhi, dhi) -> float:
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
        fm, dm = f(mid)
        left = search(lo, flo, dlo, mid, fm, dm)
        return left if left < math.inf else search(mid, fm, dm, hi, fhi, dhi)

    return search(lo, *f(lo), hi, *f(hi))


def _columns(scene: Scene, segs: list[tuple[float, float, float, float, float]],
             t: np.ndarray, rel: np.ndarray, cA: float, cB: float) -> dict[str, np.ndarray]:
    """Particle positions (m) and velocities (m/s) at the samples from the centre-of-mass
    segments (closed form) and the relative state."""
    g = scene.system.g
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
