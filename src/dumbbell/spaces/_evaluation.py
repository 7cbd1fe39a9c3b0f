"""The accounting's terms over many samples at once: the tracked bodies' state
(:class:`State`, read by :func:`read_state`) and every energy and momentum from it
(:func:`evaluate`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.energy import (
    angular_momentum,
    gravity_potential,
    rotational_ke,
    spring_potential,
    translational_ke,
)
from ._what_counts import Inventory


@dataclass(frozen=True)
class State:
    """States of the tracked bodies, each array (samples, bodies): centre of gravity x, y (m),
    its velocity vx, vy (m/s), angle (rad) and angular velocity omega (rad/s)."""

    x: np.ndarray
    y: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    angle: np.ndarray
    omega: np.ndarray


def read_state(inv: Inventory) -> State:
    """The present state of the tracked bodies, as one sample: read from pymunk's body
    structs in one pass (the centre of gravity as pymunk holds it), or through pymunk's
    getters on a pymunk build whose structs :mod:`._memory` cannot read."""
    from . import _layout as layout
    from . import _memory as mem

    if inv.bodies and layout.readable():
        at = mem.addresses(inv.bodies, "_body")
        a = mem.Span.over(at, mem.size("body")).f(
            at, np.array([mem.offset("body", *f.split(".")) for f in
                          ("p.x", "p.y", "v.x", "v.y", "a", "w")], dtype=np.uint64)[:, None])
        return State(*a[:, None, :])
    rows = []
    for b in inv.bodies:
        cg = b.local_to_world(b.center_of_gravity)
        v = b.velocity
        rows.append((cg[0], cg[1], v[0], v[1], b.angle, b.angular_velocity))
    a = np.array(rows, dtype=float).reshape(len(inv.bodies), 6).T[:, None, :]
    return State(*a)


def _ordered(values: np.ndarray) -> np.ndarray:
    """Sum over the last axis in order, left to right: ((v0 + v1) + v2) + ..."""
    return np.cumsum(values, axis=-1)[..., -1]


def _rotate(angle: np.ndarray, p: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    if p == (0.0, 0.0):
        return 0.0 * angle, 0.0 * angle
    c, s = np.cos(angle), np.sin(angle)
    return c * p[0] - s * p[1], s * p[0] + c * p[1]


def evaluate(inv: Inventory, st: State, about: tuple[float, float] = (0.0, 0.0)
             ) -> dict[str, np.ndarray]:
    """All terms over all samples: the system's K_trans, K_rot, K_cm, K_int, U_g, U_spring,
    E (J), px, py (kg m/s), L_cm, L_about (kg m^2/s), X, Y (centre of mass, m), and per body
    (arrays (samples, dynamic bodies)) body_K_trans, body_K_rot, body_U_g, body_L_about;
    per spring (samples, springs) spring_U.

    K_int is summed as each body's motion relative to the centre of mass plus its spin
    (Koenig's theorem), which equals K_trans + K_rot - K_cm without the cancellation."""
    n = inv.dynamic
    m, moment = inv.mass, inv.moment
    gx, gy = inv.gravity
    ox, oy = about
    samples = st.x.shape[0]
    zero = np.zeros(samples)
    if n == 0:
        empty = np.zeros((samples, 0))
        out = {k: zero.copy() for k in ("K_trans", "K_rot", "K_cm", "K_int", "U_g", "E", "px",
                                         "py", "L_cm", "L_about", "X", "Y")}
        out.update(body_K_trans=empty, body_K_rot=empty, body_U_g=empty, body_L_about=empty)
    else:
        # Sums over bodies in their order, left to right (cumsum: no pairwise regrouping),
        # so that two bodies add as they always have.
        M = _ordered(m[:n])
        px, py = _ordered(m[:n] * st.vx[:, :n]), _ordered(m[:n] * st.vy[:, :n])
        mx, my = _ordered(m[:n] * st.x[:, :n]), _ordered(m[:n] * st.y[:, :n])
        X, Y, Vx, Vy = mx / M, my / M, px / M, py / M
        spin = np.isfinite(moment[:n])
        kt = translational_ke(m[:n], st.vx[:, :n], st.vy[:, :n])
        kr = np.where(spin, rotational_ke(np.where(spin, moment[:n], 0.0), st.omega[:, :n]), 0.0)
        own = np.where(spin, np.where(spin, moment[:n], 0.0) * st.omega[:, :n], 0.0)
        lo = angular_momentum(m[:n], st.x[:, :n], st.y[:, :n], st.vx[:, :n], st.vy[:, :n],
                              ox, oy) + own
        rel = translational_ke(m[:n], st.vx[:, :n] - Vx[:, None], st.vy[:, :n] - Vy[:, None])
        K_int = _ordered(np.concatenate([rel, kr[:, spin]], axis=1))
        arm = angular_momentum(m[:n], st.x[:, :n], st.y[:, :n], st.vx[:, :n], st.vy[:, :n],
                               X[:, None], Y[:, None])
        L_cm = _ordered(np.concatenate([arm, own[:, spin]], axis=1))
        K_cm = translational_ke(M, Vx, Vy)
        out = {
            "K_trans": kt.sum(axis=1), "K_rot": kr.sum(axis=1), "K_cm": K_cm, "K_int": K_int,
            "U_g": gravity_potential(M, gx, gy, X, Y), "px": px, "py": py, "L_cm": L_cm,
            "L_about": lo.sum(axis=1), "X": X, "Y": Y, "body_K_trans": kt, "body_K_rot": kr,
            "body_U_g": gravity_potential(m[:n], gx, gy, st.x[:, :n], st.y[:, :n]),
            "body_L_about": lo,
        }
    spring_u = np.zeros((samples, len(inv.springs)))
    U_spring = zero.copy()
    for j, s in enumerate(inv.springs):
        if s.kind == "DampedRotarySpring":
            extent = st.angle[:, s.a] - st.angle[:, s.b]
        else:
            ax, ay = _rotate(st.angle[:, s.a], s.anchor_a)
            bx, by = _rotate(st.angle[:, s.b], s.anchor_b)
            extent = np.hypot((st.x[:, s.b] + bx) - (st.x[:, s.a] + ax),
                              (st.y[:, s.b] + by) - (st.y[:, s.a] + ay))
        spring_u[:, j] = spring_potential(s.stiffness, extent, s.rest)
        U_spring = spring_u[:, j] if j == 0 else U_spring + spring_u[:, j]
    out["U_spring"] = U_spring
    out["spring_U"] = spring_u
    out["E"] = out["K_cm"] + out["K_int"] + out["U_g"] + U_spring
    return out
