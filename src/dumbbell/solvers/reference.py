"""``reference``: a high-accuracy solution for frictionless scenes, 1D, 2D and rigid.

The 2D spring dumbbell (the truth for 2D springs) is integrated by :mod:`.reference_2d`: the
centre of mass in closed form, RK8 at a fixed step on d = rA - rB only, and a floor search
bounded by the heights' curvature, so that no impact can be missed. Its error estimate is a
second run at half the step angle. 1D scenes and the rigid dumbbell (whose truth is ``exact``)
use scipy's DOP853, as follows.

Between impacts the equations of motion are integrated by scipy's DOP853 (an 8th-order
Runge-Kutta method with error control) at ``rtol = atol = 1e-12``; an impact is a terminal
event (a particle's height crossing 0 downwards), located by the integrator's root finder to
about 1e-15 s. There the velocity is changed as the floor's impulse demands, and the
integration restarts. Samples come from the integrator's dense output at the sample times.

- particles joined by a spring (or free): state rA, vA, rB, vB; a frictionless floor only
  reverses the impacting particle's vertical velocity (times the elasticity);
- rigid dumbbell: state R, V, axis angle theta, angular velocity Omega (counter-clockwise);
  the floor's vertical impulse J at a particle changes both V and Omega:
  ``J = -(1 + e) v_y / (1/M + r_x^2 / I)`` with r the particle's offset from the centre of
  mass and ``I = mu L^2`` (plus the circles' own ``1/2 m r^2`` when ``[pymunk] spin = true``,
  as in the pymunk solver).

The reference states its own error: unless told not to, it runs a second time at a ten times
tighter tolerance (2D spring: half the step angle) and puts the largest position difference (over the first 2 s and over the
whole run), the impact-time difference and its energy error into ``info["estimated_error"]``.
Over a long run of a chaotic scene the position difference grows like any other; over the
window it is the honest error bar.

Friction is not handled (a sliding, sticking contact is not a single impulse).

DOP853's events fire only on a sign change between step ends, so a particle that swings
below the floor and back within one step is missed; on a rigid body, whose flight is a
polynomial, the steps grow to seconds and this happens (``scenes/rigid-2d.toml`` at 2.68 s).
The run then checks itself: a sample more than 1e-9 m below the floor ends it ``failed``.
The rigid dumbbell's truth is ``exact`` (its flight in closed form), not this solver.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model.energy import (
    _relative_energy_error,
    impact_heat,
    rigid_moment,
    spins,
    state_columns,
)
from ..model.scene import Scene
from ..model.trajectory import Impact, Trajectory, Verdict
from .base import RunOptions, Truth, impact_budget_reason
from .kernels import REST_SPEED
from .verdicts import RawRun, head, judge, rest_reason

#: No public names: the class is ``dumbbell.solvers.METHODS[name]``.
__all__: list[str] = []

NAME = "reference"

RTOL = 1e-12
ATOL = 1e-12
#: The window (s) over which the error estimate is stated separately (chaos: see docs/physics.md).
ERROR_WINDOW = 2.0
MAX_IMPACTS = 100_000


def supports(scene: Scene) -> str | None:
    """None if this solver can run ``scene``, else why not."""
    if scene.system.resting_contact():
        return scene.system.resting_contact()
    if scene.system.floor is not None and scene.system.floor.friction > 0:
        return ("the reference handles frictionless floors only (friction makes a contact "
                "slide and stick, not a single impulse); compare pymunk at smaller dt instead")
    return None


@dataclass
class _Model:
    """The ODE of one scene: initial state, right-hand side, impact event per body, the jump
    at an impact, and the conversion of states (n, dim) to the solver's columns."""

    y0: list[float]
    rhs: Callable[[float, np.ndarray], list[float]]
    height: dict[str, Callable[[np.ndarray], float]]
    vertical_velocity: Callable[[np.ndarray, str], float]
    jump: Callable[[np.ndarray, str, float], np.ndarray]
    columns: Callable[[np.ndarray], dict[str, np.ndarray]]
    #: Mass (kg) the floor's impulse meets at a body; None: the particle's own.
    effective_mass: Callable[[np.ndarray, str], float] | None = None


def _particles_model(scene: Scene) -> _Model:
    A, B = scene.system.A, scene.system.B
    mA, mB, g = A.mass, B.mass, scene.system.g
    k, b = scene.system.k, scene.system.b

    if scene.system.dimensions == 1:
        # The 1D force law keeps its sign when A passes below B, as in the other 1D solvers.
        def rhs1(_t: float, y: np.ndarray) -> list[float]:
            f = k * (y[0] - y[2] - b)
            return [y[1], -f / mA - g, y[3], f / mB - g]

        def jump1(y: np.ndarray, body: str, e: float) -> np.ndarray:
            y = y.copy()
            y[1 if body == "A" else 3] *= -e
            return y

        def columns1(Y: np.ndarray) -> dict[str, np.ndarray]:
            return {"xA": Y[:, 0], "vA": Y[:, 1], "xB": Y[:, 2], "vB": Y[:, 3]}

        return _Model([A.height, A.vy, B.height, B.vy], rhs1,
                      {"A": lambda y: y[0], "B": lambda y: y[2]},
                      lambda y, body: y[1 if body == "A" else 3], jump1, columns1)

    def rhs2(_t: float, y: np.ndarray) -> list[float]:
        dx, dy = y[0] - y[4], y[1] - y[5]
        L = math.hypot(dx, dy)
        s = -k * (L - b) / L if L > 0 else 0.0  # force on A per unit of d
        return [y[2], y[3], s * dx / mA, s * dy / mA - g,
                y[6], y[7], -s * dx / mB, -s * dy / mB - g]

    def jump2(y: np.ndarray, body: str, e: float) -> np.ndarray:
        y = y.copy()
        y[3 if body == "A" else 7] *= -e
        return y

    spin = spins(scene)

    def columns2(Y: np.ndarray) -> dict[str, np.ndarray]:
        cols = {name: Y[:, c] for c, name in enumerate(state_columns(scene))}
        if spin:  # frictionless: the circles keep their initial spins
            cols["omegaA"] = np.full(len(Y), A.spin)
            cols["omegaB"] = np.full(len(Y), B.spin)
        return cols

    return _Model([A.x, A.height, A.vx, A.vy, B.x, B.height, B.vx, B.vy], rhs2,
                  {"A": lambda y: y[1], "B": lambda y: y[5]},
                  lambda y, body: y[3 if body == "A" else 7], jump2, columns2)


def _rigid_model(scene: Scene) -> _Model:
    A, B = scene.system.A, scene.system.B
    M, g, L = scene.system.M, scene.system.g, scene.system.rigid.length  # type: ignore[union-attr]
    I = rigid_moment(scene)
    cA, cB = B.mass / M, A.mass / M  # rA = R + cA L u, rB = R - cB L u
    d = (A.x - B.x, A.height - B.height)
    w = (A.vx - B.vx, A.vy - B.vy)
    y0 = [(A.mass * A.x + B.mass * B.x) / M, (A.mass * A.height + B.mass * B.height) / M,
          (A.mass * A.vx + B.mass * B.vx) / M, (A.mass * A.vy + B.mass * B.vy) / M,
          math.atan2(d[1], d[0]), (d[0] * w[1] - d[1] * w[0]) / (d[0] ** 2 + d[1] ** 2)]
    arm = {"A": cA * L, "B": -cB * L}

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        return [y[2], y[3], 0.0, -g, y[5], 0.0]

    def offset(y: np.ndarray, body: str) -> tuple[float, float]:
        return arm[body] * math.cos(y[4]), arm[body] * math.sin(y[4])

    def vertical_velocity(y: np.ndarray, body: str) -> float:
        return y[3] + y[5] * offset(y, body)[0]

    def effective_mass(y: np.ndarray, body: str) -> float:
        rx = offset(y, body)[0]
        return 1.0 / (1.0 / M + rx * rx / I)

    def jump(y: np.ndarray, body: str, e: float) -> np.ndarray:
        rx = offset(y, body)[0]
        J = -(1.0 + e) * vertical_velocity(y, body) * effective_mass(y, body)
        y = y.copy()
        y[3] += J / M
        y[5] += rx * J / I
        return y

    def columns(Y: np.ndarray) -> dict[str, np.ndarray]:
        X, Yc, VX, VY, th, Om = Y.T
        cos, sin = np.cos(th), np.sin(th)
        cols: dict[str, np.ndarray] = {}
        for body in "AB":
            ox, oy = arm[body] * cos, arm[body] * sin
            cols.update({f"x{body}": X + ox, f"y{body}": Yc + oy,
                         f"vx{body}": VX - Om * oy, f"vy{body}": VY + Om * ox})
        cols = {name: cols[name] for name in state_columns(scene)}
        cols["omega"] = Om
        if spins(scene):
            cols["omegaA"] = cols["omegaB"] = Om
        return cols

    return _Model(y0, rhs, {body: (lambda y, body=body: y[1] + offset(y, body)[1])
                            for body in "AB"},
                  vertical_velocity, jump, columns, effective_mass)


def _model(scene: Scene) -> _Model:
    return _rigid_model(scene) if scene.system.rigid is not None else _particles_model(scene)


def integrate(scene: Scene, times: np.ndarray, t_end: float, tight: bool = False,
              pb: object | None = None
              ) -> tuple[dict[str, np.ndarray], list[Impact], Verdict, int]:
    """Integrate ``scene`` to ``t_end`` (s) and sample it at ``times`` (s, sorted); ``tight``
    for the error estimate's run (10x tighter tolerance, or half the fixed step in 2D).

    Returns the columns at the samples reached, the impacts, a verdict, and the number of
    right-hand-side evaluations (2D spring: Runge-Kutta steps)."""
    if scene.system.dimensions == 2 and scene.system.rigid is None:
        from .reference_2d import STEP_ANGLE
        from .reference_2d import integrate as integrate_2d

        return integrate_2d(scene, times, t_end, STEP_ANGLE / 2 if tight else STEP_ANGLE, pb)
    return _integrate_dop853(scene, times, t_end, tight, pb)


def _integrate_dop853(scene: Scene, times: np.ndarray, t_end: float, tight: bool,
                      pb: object | None = None
                      ) -> tuple[dict[str, np.ndarray], list[Impact], Verdict, int]:
    """scipy's DOP853 with impacts as terminal events (1D, and the rigid dumbbell), at
    tolerances :data:`RTOL` and :data:`ATOL`, 10x tighter if ``tight``."""
    from scipy.integrate import solve_ivp

    rtol, atol = (RTOL / 10, ATOL / 10) if tight else (RTOL, ATOL)
    model = _model(scene)
    if len(times):
        t_end = max(t_end, float(times[-1]))  # j * every * dt can round past t_end
    bodies = list(model.height) if scene.system.floor is not None else []
    events = _floor_events(model, bodies)
    y = np.asarray(model.y0, dtype=float)
    t = 0.0
    out = np.empty((len(times), len(y)))
    k = 0
    impacts: list[Impact] = []
    verdict = Verdict()
    nfev = 0
    while True:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # tolerances near machine precision
            sol = solve_ivp(model.rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol,
                            events=events or None, dense_output=True)
        nfev += sol.nfev
        if sol.status < 0:
            verdict = Verdict("failed", float(sol.t[-1]), f"DOP853 failed: {sol.message}")
            break
        t_stop = float(sol.t[-1])
        hi = int(np.searchsorted(times, t_stop, side="right"))
        if hi > k:
            out[k:hi] = sol.sol(times[k:hi]).T
            k = hi
        if pb is not None:
            pb.update(t_stop - t)  # type: ignore[attr-defined]
        if sol.status != 1:
            break
        y, impact = _bounce(scene, model, sol, bodies)
        if isinstance(impact, Verdict):
            verdict = impact
            break
        impacts.append(impact)
        t = impact.t
        if len(impacts) >= MAX_IMPACTS:
            verdict = Verdict("failed", t, impact_budget_reason(MAX_IMPACTS))
            break
        if t >= t_end:
            break
    return model.columns(out[:k]), impacts, verdict, nfev


def _floor_events(model: _Model, bodies: list[str]) -> list[Callable[..., float]]:
    """solve_ivp's terminal events: each body's height reaching 0 going down."""
    events = []
    for body in bodies:
        def event(_t: float, y: np.ndarray, body: str = body) -> float:
            return model.height[body](y)
        event.terminal = True  # type: ignore[attr-defined]
        event.direction = -1  # type: ignore[attr-defined]
        events.append(event)
    return events


def _bounce(scene: Scene, model: _Model, sol: Any, bodies: list[str]
            ) -> tuple[np.ndarray, Impact | Verdict]:
    """The state just after the first impact that stopped ``sol`` and the impact, or a
    ``failed`` verdict when the body hit at rest (an inelastic floor's endless bounces)."""
    e = scene.system.floor.elasticity if scene.system.floor is not None else 1.0
    hits = [(float(te[0]), body) for te, body in zip(sol.t_events, bodies, strict=True)
            if len(te)]
    t_hit, body = min(hits)
    y = np.asarray(sol.y_events[bodies.index(body)][0], dtype=float)
    v_before = float(model.vertical_velocity(y, body))
    if abs(v_before) < REST_SPEED:
        return y, Verdict("failed", t_hit, rest_reason(body, v_before))
    mass = (model.effective_mass(y, body) if model.effective_mass is not None
            else (scene.system.A.mass if body == "A" else scene.system.B.mass))
    y = model.jump(y, body, e)
    v_after = float(model.vertical_velocity(y, body))
    return y, Impact(t_hit, body, v_before, v_after, impact_heat(mass, v_before, v_after))


def warm_up() -> float:
    """Compile (or load from numba's cache) the 2D spring kernel; returns the seconds it took."""
    from .reference_2d import warm_up as warm_up_2d

    t0 = time.perf_counter()
    warm_up_2d()
    return time.perf_counter() - t0


def solve(scene: Scene, options: RunOptions, estimate_error: bool = True) -> Trajectory:
    """Integrate ``scene`` and sample at ``i * every * dt`` (s); ``dt`` sets only the sample
    times. With ``estimate_error`` a second run at 10x tighter tolerance measures the error."""
    from ..model import args
    from ..progress import bar

    if not isinstance(estimate_error, bool):
        estimate_error = args.flag(estimate_error, "estimate_error")
    times = options.sample_times()
    if scene.system.dimensions == 2 and scene.system.rigid is None:
        warm_up()  # numba compiles (or loads) the kernel outside the solver's clock
    t0 = time.perf_counter()
    with bar(options.t_end, f"{NAME} {scene.name}", "s", quiet=options.quiet) as pb:
        cols, impacts, verdict, nfev = integrate(scene, times, options.t_end, pb=pb)
    wall = time.perf_counter() - t0
    n = len(next(iter(cols.values())))
    t = times[:n]
    if scene.system.dimensions == 2 and scene.system.rigid is None:
        from .reference_2d import STEP_ANGLE

        info = {"method": "RK8 (DOP853 stages) on d = rA - rB, fixed step",
                "step_angle": STEP_ANGLE, "rk_steps": nfev}
    else:
        info = {"method": "DOP853", "rtol": RTOL, "atol": ATOL, "nfev": nfev}
    if scene.system.rigid is not None:
        info["moment"] = rigid_moment(scene)
    verdict, keep, energy = judge(Reference, scene, options, RawRun(t, cols, impacts, verdict))
    t, cols = t[:keep], head(cols, keep)
    if estimate_error and len(t):
        info["estimated_error"] = _estimate_error(scene, t, cols, impacts, energy)
    return Trajectory._made(scene=scene, solver=NAME, t=t, state=cols, events=impacts,
                      verdict=verdict, dt=options.dt, every=options.every, wall_time=wall,
                      info=info, energy=energy)


def _estimate_error(
    scene: Scene, t: np.ndarray, state: dict[str, np.ndarray], events: list[Impact],
    energy: dict[str, np.ndarray],
) -> dict[str, float]:
    """Differences from a run at 10x tighter tolerance over the samples ``t`` (s) of
    ``state`` with impacts ``events``, and the largest relative error of ``energy`` (J)."""
    cols, impacts, _, _ = integrate(scene, t, float(t[-1]), tight=True)
    n = min(len(t), len(next(iter(cols.values()))))
    pos = [c for c in state_columns(scene) if not c.startswith("v")]
    diff = np.max([np.abs(state[c][:n] - cols[c][:n]) for c in pos], axis=0)
    window = t[:n] <= ERROR_WINDOW + 1e-12
    est = {
        "position_m_window": float(diff[window].max()),
        "window_s": float(min(ERROR_WINDOW, t[n - 1])),
        "position_m_whole_run": float(diff.max()),
        "energy_relative": float(_relative_energy_error(energy, scene.system).max()),
    }
    early = [(a, b) for a, b in zip(impacts, events, strict=False)
             if max(a.t, b.t) <= ERROR_WINDOW and a.body == b.body]
    if early:
        est["impact_time_s_window"] = float(max(abs(a.t - b.t) for a, b in early))
    return est


class Reference(Truth):
    """RK8 on d = rA - rB with a curvature-bounded floor search (2D spring), or scipy's DOP853
    at tight tolerance with impacts as events (1D, rigid); see the module docstring."""

    name = NAME
    relative_cost = 100.0
    estimates_error = True      # a second run, 10x tighter (half the step in 2D), measures it
    _supports = staticmethod(supports)
    _solve = staticmethod(solve)
    warm_up = staticmethod(warm_up)

    @staticmethod
    def _truth_for(scene: Scene) -> bool:
        """The truth for the 2D spring dumbbell."""
        return scene.system.dimensions == 2 and scene.system.rigid is None
