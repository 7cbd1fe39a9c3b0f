"""The physics of one pymunk step, as the ledger counts it: energies at a snapshot, the move
(where each body started, what the potentials did over it), and the work of each source's
impulses in the solver (constraints, springs, gravity, forces, damping, what nothing
explains).

Every change of velocity in the step is an impulse; kinetic energy is quadratic and the
velocity change linear in the impulses, so the change of kinetic energy over the step is
exactly the sum over sources of impulse . (u0 + u1) / 2, u the velocity the source acts on
before and after, however the solver ordered them. The functions here take the typed
records of :mod:`._records` and the :class:`._inventory.Build`, and add into the running
sums of :class:`._terms.Sums`."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _inventory as inventory
from ._constraints import Group
from ._inventory import Build, Table
from ._records import Before, Energy, Move, Potentials, Snapshot, Step
from ._terms import Sums


class FieldError(Exception):
    """A declared potential gave a value that is not a finite number."""


def _cross(rx: Any, ry: Any, px: Any, py: Any) -> Any:
    return rx * py - ry * px


def _scatter(rows: np.ndarray, values: np.ndarray, size: int) -> np.ndarray:
    return np.bincount(rows, weights=values, minlength=size)


def same(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Equal but for a few roundings (a compiler may fuse pymunk's multiply and add)."""
    return np.abs(x - y) <= 8.0 * np.finfo(float).eps * (np.abs(x) + np.abs(y)) + 1e-300


# -- energies -----------------------------------------------------------------------------


def spring_energy(b: Build, pos: np.ndarray) -> list[np.ndarray]:
    """Potential of each default spring, per group, at positions ``pos``."""
    out = []
    for g in b.springs:
        rest, k = g.settings[0], g.settings[1]
        ia, ib = g.a, g.b
        if g.kind == "spring":
            ca, sa = np.cos(pos[2, ia]), np.sin(pos[2, ia])
            cb, sb = np.cos(pos[2, ib]), np.sin(pos[2, ib])
            an = g.anchor
            dx = (pos[0, ib] + cb * an[:, 2] - sb * an[:, 3]) - (
                pos[0, ia] + ca * an[:, 0] - sa * an[:, 1])
            dy = (pos[1, ib] + sb * an[:, 2] + cb * an[:, 3]) - (
                pos[1, ia] + sa * an[:, 0] + ca * an[:, 1])
            extent = np.sqrt(dx * dx + dy * dy)
        else:
            extent = pos[2, ia] - pos[2, ib]
        out.append(np.where(g.default, 0.5 * k * (extent - rest) ** 2, 0.0))
    return out


def field_energy(b: Build, pos: np.ndarray) -> np.ndarray:
    """Declared potential of each dynamic row (0 where none is declared). Raises
    :class:`FieldError` naming the potential, the body and the value when one is not a
    finite number."""
    t = b.table
    out = np.zeros(t.n)
    for f in b.fields:
        x, y = pos[0, f.idx], pos[1, f.idx]
        raw = f.potential(x, y, t.m[f.idx])
        try:
            value = np.broadcast_to(np.asarray(raw, dtype=float), f.idx.shape)
        except (TypeError, ValueError):
            value = np.full(f.idx.shape, np.nan)
        bad = ~np.isfinite(value)
        if bad.any():
            j = int(np.argmax(bad))
            shown = raw if raw is None or np.ndim(raw) == 0 else value[j]
            raise FieldError(f"declared potential {f.label!r} returned {shown!r} for "
                             f"{t.labels[int(f.idx[j])]} at x = {float(x[j]):.6g}, y = "
                             f"{float(y[j]):.6g}: it must return finite energies")
        out[f.idx] += value
    return out


def snapshot(b: Build, pos: np.ndarray, vel: np.ndarray, bias: np.ndarray,
             sleeping: np.ndarray) -> Snapshot:
    """A snapshot at (pos, vel), with the potentials there."""
    return Snapshot(pos, vel, bias, sleeping, spring_energy(b, pos), field_energy(b, pos),
                    bool(sleeping.any()), bool(bias.any()))


def read_snapshot(b: Build) -> Snapshot:
    """The state of the table's bodies now, between steps."""
    t = b.table
    F = t.pre.floats()
    Q = t.post.floats()
    bias = Q[3:6].copy()
    bias[:, t.n:] = 0.0
    sleeping = t.post.pointers()[0, : t.n] != 0
    return snapshot(b, F[0:3].copy(), F[3:6].copy(), bias, sleeping)


def energy(b: Build, s: Snapshot) -> Energy:
    """E and its parts at the snapshot ``s``."""
    t = b.table
    n = t.n
    v, p = s.vel, s.pos
    gx, gy = b.gravity
    K = 0.5 * t.m * (v[0, :n] ** 2 + v[1, :n] ** 2) + 0.5 * t.I * v[2, :n] ** 2
    Ug = -t.m * (gx * p[0, :n] + gy * p[1, :n])
    Ud = s.ud
    Us = sum(float(np.sum(u)) for u in s.us)
    k, ug, ud = float(np.sum(K)), float(np.sum(Ug)), float(np.sum(Ud))
    return Energy(k + ug + ud + Us, k, ug, Us, ud, K + Ug + Ud, Ug, Ud)


def magnitude(E: float, K: float, Ug: float, Us: float, Ud: float) -> float:
    """The largest magnitude of E and its parts (as :func:`totals` gives them, and an
    :class:`._records.Energy` begins): what sets the energies' own rounding."""
    return max(abs(E), K, abs(Ug), abs(Us), abs(Ud))


def totals(b: Build, s: Snapshot) -> tuple[float, float, float, float, float]:
    """E and its parts at ``s`` (E, K, U_g, U_springs, U_fields), in totals only: what the
    ledger needs at each step's end (:func:`energy` gives each body's too)."""
    t = b.table
    v = s.vel
    K = 0.5 * float(np.vdot(t.mass3_rows, v * v))
    mp = s.pos[:2] @ t.m_rows
    Ug = -(b.gravity[0] * float(mp[0]) + b.gravity[1] * float(mp[1]))
    Us = sum(float(np.sum(u)) for u in s.us) if b.springs else 0.0
    Ud = float(np.sum(s.ud)) if b.fields else 0.0
    return K + Ug + Ud + Us, K, Ug, Us, Ud


def changes(b: Build, s: Snapshot, pos: np.ndarray, vel: np.ndarray
            ) -> tuple[np.ndarray, float]:
    """The energy of what changed from the snapshot to the state (pos, vel) at the same
    moment: per dynamic row (kinetic, gravity, fields), and the springs' part (their
    potential, which moved bodies stretch)."""
    t = b.table
    n = t.n
    gx, gy = b.gravity
    v0, v1 = s.vel, vel
    dK = 0.5 * t.m * (v1[0, :n] ** 2 + v1[1, :n] ** 2 - v0[0, :n] ** 2 - v0[1, :n] ** 2) \
        + 0.5 * t.I * (v1[2, :n] ** 2 - v0[2, :n] ** 2)
    dU = -t.m * (gx * (pos[0, :n] - s.pos[0, :n]) + gy * (pos[1, :n] - s.pos[1, :n]))
    springs = 0.0
    if np.any(pos != s.pos):
        if b.fields:
            dU = dU + field_energy(b, pos) - s.ud
        if b.springs:
            after = spring_energy(b, pos)
            springs = sum(float(np.sum(a) - np.sum(c)) for a, c in zip(after, s.us,
                                                                        strict=True))
    return dK + dU, springs


# -- the move -----------------------------------------------------------------------------


def move_of(b: Build, s: Snapshot, pos: np.ndarray, vel: np.ndarray, dt: float) -> Move:
    """pymunk's move, p += (v + v_bias) dt for awake dynamic and kinematic bodies, from
    the snapshot to ``pos``: where each body started (the program may have moved it, woken
    it or put it to sleep) and how long it moved."""
    t = b.table
    n = t.n
    moving = t.moves
    if s.asleep:
        moving = moving.copy()
        moving[:n] &= ~s.sleeping
        spans = np.where(moving, dt, 0.0)
    else:
        spans = inventory.spans(t, dt)
    start = s.pos
    # Where each body would be: (v + v_bias) dt on from where it was for those that move,
    # and as it was for the others (x + 0). Found the same bit for bit (as almost every
    # step), that is the move; else the exact comparison decides (-0 against +0, ...).
    ahead = start + (vel + s.bias if s.biased else vel) * spans
    if ahead.tobytes() != pos.tobytes() and not np.array_equal(
            pos, np.where(moving, start + (vel + s.bias) * dt, start)):
        moving, start = _moved_how(b, s, Move(pos, vel, start, dt), moving)
        return Move(pos, vel, start, np.where(moving, dt, 0.0))
    return Move(pos, vel, start, spans if s.asleep else dt)


def _moved_how(b: Build, s: Snapshot, move: Move, moving: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """Which bodies pymunk moved over ``move`` (positions after it and velocities; its
    ``step`` the dt) (the program may have woken some or put them to sleep), and where each
    started: where it was, or where the program put it."""
    t = b.table
    pos, vel, dt = move.pos, move.vel, float(move.step)
    shift = (vel + s.bias) * dt
    ok = np.all(same(pos, np.where(moving, s.pos + shift, s.pos)), axis=0)
    flipped = ~moving & t.moves
    other = np.all(same(pos, np.where(flipped, s.pos + shift, s.pos)), axis=0)
    moving = np.where(~ok & other, flipped, moving)
    ok |= other
    # Moved with the velocity the last step left, set anew after the move: a collision's
    # begin, pre_solve or separate callback (the velocity alone changed, not the position).
    ok |= moving & np.all(same(pos, s.pos + (s.vel + s.bias) * dt), axis=0)
    step = np.where(moving, dt, 0.0)
    start = np.where(ok, s.pos, pos - (vel + s.bias) * step)
    return moving, start


def gravity_over(b: Build, s: Snapshot, move: Move) -> tuple[float, np.ndarray | None, float]:
    """Gravity's potential over the move: all of it, less the bias velocities' part
    (position correction), which leaves the velocities' part; the same per dynamic row
    when custom velocity functions need it (else None); and the correction's part."""
    t = b.table
    n, m = t.n, t.m
    gx, gy = b.gravity
    pos, start = move.pos, move.start
    d = (pos[:2] - start[:2]) @ t.m_rows
    dU = -(gx * float(d[0]) + gy * float(d[1]))
    corr = 0.0
    bias = None
    if s.biased:
        step = move.step
        moved = (s.bias[:2] * step if isinstance(step, np.ndarray) else s.bias[:2]) @ t.m_rows
        corr = -(gx * float(moved[0]) + gy * float(moved[1]))
        if not isinstance(step, np.ndarray):
            corr *= step
        if b.any_custom:
            bias = s.bias[:, :n] * (step[:n] if isinstance(step, np.ndarray) else step)
    g_rows = None
    if b.any_custom:
        g_rows = -m * (gx * (pos[0, :n] - start[0, :n]) + gy * (pos[1, :n] - start[1, :n]))
        if bias is not None:
            g_rows = g_rows + m * (gx * bias[0] + gy * bias[1])
    return float(dU - corr), g_rows, float(corr)


def potentials_over(b: Build, s: Snapshot, move: Move, corr: float
                    ) -> tuple[Potentials, float]:
    """The springs' and the declared fields' potentials over the move, less the bias
    velocities' part, which is added to the correction ``corr``."""
    if not (b.springs or b.fields):
        return Potentials([], [], None, s.ud), corr
    pos, start, step = move.pos, move.start, move.step
    unmoved = start is s.pos
    u_start = s.us if unmoved else spring_energy(b, start)
    u_end = spring_energy(b, pos)
    spring_int = [b2 - a2 for a2, b2 in zip(u_start, u_end, strict=True)]
    d_start = s.ud if unmoved else field_energy(b, start)
    d_end = field_energy(b, pos)
    d_int = d_end - d_start
    if s.biased:
        mid = start + move.vel * step
        end = mid + s.bias * step
        u1, u2 = spring_energy(b, mid), spring_energy(b, end)
        for j in range(len(spring_int)):
            spring_int[j] = spring_int[j] - (u2[j] - u1[j])
            corr += float(np.sum(u2[j] - u1[j]))
        if b.fields:
            f1, f2 = field_energy(b, mid), field_energy(b, end)
            d_int = d_int - (f2 - f1)
            corr += float(np.sum(f2 - f1))
    return Potentials(spring_int, u_end, d_int, d_end), corr


# -- the solver's impulses ----------------------------------------------------------------


def constraint_work(t: Table, g: Group, after: np.ndarray, initial: np.ndarray,
                    step: Step) -> float:
    """Work of the step's impulses of the constraints in ``g``. The impulse applied is
    the accumulator's end value less what it carried in and did not apply (pymunk applies
    the carried impulse scaled by dt / previous dt, and none when a stop resets it). A
    spring's impulse splits into its elastic part (its force at the step's positions,
    applied when the step prepares it) and its damping. Adds the work on each row to
    ``step.work`` and the springs' elastic kicks to ``step.kick`` (what ``space.damping``
    then scales)."""
    rows = t.rows
    ra, rb = g.a, g.b
    u = step.u
    La, Lb, Aa, Ab = impulses(g.kind, after, initial, step.coef)
    lin_a, ang_a = La[0] * u[0, ra] + La[1] * u[1, ra], Aa * u[2, ra]
    lin_b, ang_b = Lb[0] * u[0, rb] + Lb[1] * u[1, rb], Ab * u[2, rb]
    rel = lin_a + ang_a + lin_b + ang_b
    both = np.concatenate([ra, rb])
    step.work[0] += _scatter(both, np.concatenate([lin_a, lin_b]), rows)
    step.work[1] += _scatter(both, np.concatenate([ang_a, ang_b]), rows)
    drv_a = -np.where(t.lin_free[ra], 0.0, lin_a) - np.where(t.ang_free[ra], 0.0, ang_a)
    drv_b = -np.where(t.lin_free[rb], 0.0, lin_b) - np.where(t.ang_free[rb], 0.0, ang_b)
    g.kin_a += drv_a
    g.kin_b += drv_b
    total = float(np.sum(rel) + np.sum(drv_a) + np.sum(drv_b))
    if not g.spring:
        g.work += rel
        return total
    # The work is linear in the impulse along the spring: its elastic part, and the rest.
    elastic = spring_elastic(t, g, after, step)
    g.work += elastic
    g.extra += rel - elastic
    if step.spring_int:
        pot = step.spring_int[g.slot]
        g.pot += pot
        total += float(np.sum(pot))
    return total


def impulses(kind: str, after: np.ndarray, initial: np.ndarray, coef: float
             ) -> tuple[tuple[Any, Any], tuple[Any, Any], Any, Any]:
    """The impulses a constraint of ``kind`` applied in the step (its accumulators
    ``after`` the solver, ``initial`` what they carried in): linear on its body a and on b,
    angular on a and on b."""
    if kind in ("pin", "slide", "spring", "pivot", "groove"):
        if kind in ("pivot", "groove"):
            Px = after[0] - (1.0 - coef) * initial[0]
            Py = after[1] - (1.0 - coef) * initial[1]
            r1x, r1y, r2x, r2y = after[2:6]
        else:
            j, nx, ny, r1x, r1y, r2x, r2y = after
            J = j if kind == "spring" else j - (1.0 - coef) * initial[0]
            if kind == "slide":
                J = np.where((nx == 0.0) & (ny == 0.0), 0.0, J)
            Px, Py = nx * J, ny * J
        return (-Px, -Py), (Px, Py), -_cross(r1x, r1y, Px, Py), _cross(r2x, r2y, Px, Py)
    j = after[0]
    if kind == "rotary_spring":
        J = j
    elif kind in ("rotary_limit", "ratchet"):
        J = np.where(after[1] == 0.0, 0.0, j - (1.0 - coef) * initial[0])
    else:
        J = j - (1.0 - coef) * initial[0]
    zero = (0.0 * J, 0.0 * J)
    return zero, zero, -J * (after[1] if kind == "gear" else 1.0), J


def spring_elastic(t: Table, g: Group, after: np.ndarray, step: Step) -> np.ndarray:
    """The work of the elastic part of the impulses of the springs in ``g`` (their force at
    the step's positions, as the step prepares them); their kicks are added to
    ``step.kick``."""
    rows, kick, u, pos = t.rows, step.kick, step.u, step.pos
    ra, rb = g.a, g.b
    both = np.concatenate([ra, rb])
    rest, k, max_force = g.settings[0], g.settings[1], g.settings[3]
    if g.kind == "spring":
        _, nx, ny, r1x, r1y, r2x, r2y = after
        dx = (pos[0, rb] + r2x) - (pos[0, ra] + r1x)
        dy = (pos[1, rb] + r2y) - (pos[1, ra] + r1y)
        f = np.clip((rest - np.sqrt(dx * dx + dy * dy)) * k, -max_force, max_force)
        Jel = np.where(g.default, f * step.dt, 0.0)
        ex, ey = nx * Jel, ny * Jel
        if kick is not None:
            kick[0] += _scatter(both, np.concatenate([-ex, ex]), rows)
            kick[1] += _scatter(both, np.concatenate([-ey, ey]), rows)
            kick[2] += _scatter(both, np.concatenate([-_cross(r1x, r1y, ex, ey),
                                                      _cross(r2x, r2y, ex, ey)]), rows)
        unit = nx * (u[0, rb] - u[2, rb] * r2y - u[0, ra] + u[2, ra] * r1y) + ny * (
            u[1, rb] + u[2, rb] * r2x - u[1, ra] - u[2, ra] * r1x)
    else:
        f = np.clip(((pos[2, ra] - pos[2, rb]) - rest) * k, -max_force, max_force)
        Jel = np.where(g.default, f * step.dt, 0.0)
        if kick is not None:
            kick[2] += _scatter(both, np.concatenate([-Jel, Jel]), rows)
        unit = u[2, rb] - u[2, ra]
    return Jel * unit


def external(b: Build, step: Step, p: Before, damping: float, sums: Sums
             ) -> tuple[np.ndarray, Any, float, float]:
    """The work on each dynamic row of the impulses from outside the constraints and
    contacts: gravity, m g dt on every awake body (``p.awake``) the default velocity_func
    moves, applied forces and torques (``p.force``, read before pymunk cleared them), and
    ``space.damping``. Returns their linear and angular work per row, gravity's work in all,
    and the others' (added to ``sums``)."""
    t = b.table
    kicked, force = p.awake, p.force
    if b.any_custom:
        kicked = ~b.custom if kicked is None else kicked & ~b.custom
    n, dt = t.n, step.dt
    gx, gy = b.gravity
    un = step.u[:, :n]
    mk = inventory.mass_dt(t, dt)
    if kicked is not None:
        mk = np.where(kicked, mk, 0.0)
    lin = mk * (gx * un[0] + gy * un[1])
    w_g = float(lin.sum())
    ang: Any = 0.0  # an array once a force or damping acts
    total = 0.0
    if force is not None:
        f = force * dt
        if kicked is not None:
            f = np.where(kicked, f, 0.0)
        f[2] = np.where(t.finite, f[2], 0.0)
        fw = f * un
        w_f = fw.sum(axis=0)
        sums.force += w_f
        total += float(np.sum(w_f))
        lin, ang = lin + fw[0] + fw[1], ang + fw[2]
    if damping != 1.0:
        d = damping ** dt
        kick = step.kick
        before = step.vel0[:, :n] if kick is None else step.vel0[:, :n] + kick[:, :n] * t.inv3
        D = (d - 1.0) * t.mass3 * before
        if kicked is not None:
            D = np.where(kicked, D, 0.0)
        Dw = D * un
        w_d = float(Dw.sum())
        lin, ang = lin + Dw[0] + Dw[1], ang + Dw[2]
        sums.add("space.damping", "damping", w_d, f"space.damping = {damping:g}")
        total += w_d
    return lin, ang, w_g, total


def plain_step(b: Build, p: Before, vel0: np.ndarray, vel1: np.ndarray, u: np.ndarray,
               sums: Sums) -> float:
    """:func:`external` and :func:`unexplained` in one, for a plain build
    (:attr:`._inventory.Build.plain`) stepped with every body awake, no force and no
    damping: gravity kicks every dynamic body by g dt, and whatever else changed a velocity
    (the contacts, until their batch takes their work out; a callback) is unexplained. The
    same sums, in fewer numpy calls: each is paid for in caches the solver has just used."""
    t = b.table
    n = t.n
    un = u[:, :n]
    # The impulse no source explains, m (v1 - v0 - g dt), and its work on each row.
    rest = vel1[:, :n] - vel0[:, :n]
    rest -= inventory.gravity_dt(t, b.gravity, p.dt)
    rest *= t.mass3
    rest *= un
    w_r = np.add.reduce(rest, axis=0)
    sums.unattributed += w_r
    # Gravity's work, m g dt . u summed, and its step error against its potential's change.
    mu = un[:2] @ t.m
    step_err = p.dt * (b.gravity[0] * float(mu[0]) + b.gravity[1] * float(mu[1])) + p.g_int
    sums.add("gravity", "step error", step_err)
    return float(np.add.reduce(w_r)) + step_err


def unexplained(b: Build, step: Step, p: Before, outside: tuple[np.ndarray, Any, float],
                sums: Sums) -> float:
    """What no source explains (a custom velocity_func's kicks, an impulse from a callback)
    and gravity's step error (``outside``: the work per row :func:`external` gave, linear
    and angular, and gravity's in all; ``p.g_int`` gravity's potential change over the
    move): counted into ``sums``; returns their sum."""
    t = b.table
    lin, ang, w_g = outside
    g_int, g_rows, d_int = p.g_int, p.g_rows, p.potentials.d_int
    n = t.n
    # The work of what no source explains: of the impulse m (v1 - v0), less the sources'.
    K = t.mass3 * (step.vel1[:, :n] - step.vel0[:, :n]) * step.u[:, :n]
    w_r = K[0] + K[1] - lin - step.work[0, :n]
    # (without forces and damping ang is 0.0, and K - 0.0 is K bit for bit)
    spin = (K[2] - ang if isinstance(ang, np.ndarray) else K[2]) - step.work[1, :n]
    w_r += spin if t.all_finite else np.where(t.finite, spin, 0.0)  # infinite: imposed
    total = 0.0
    if b.any_custom:
        custom = b.custom
        vf = np.where(custom, w_r + g_rows + (0.0 if d_int is None else d_int), 0.0)
        step_err = w_g + g_int - float(np.sum(g_rows[custom]))
        sums.vf += np.where(b.declared, 0.0, vf)
        other = np.where(custom, 0.0, w_r)
        sums.unattributed += other
        total += float(np.sum(vf) + np.sum(other))
        for j, f in enumerate(b.fields):
            own = float(np.sum(np.where(custom[f.idx], 0.0, d_int[f.idx])))
            sums.field[j] += float(np.sum(vf[f.idx])) + own
            total += own
    else:
        step_err = w_g + g_int
        sums.unattributed += w_r
        total += float(w_r.sum())
        for j, f in enumerate(b.fields):
            own = float(np.sum(d_int[f.idx]))
            sums.field[j] += own
            total += own
    sums.add("gravity", "step error", step_err)
    return total + step_err
