"""Collisions in the reach estimate (:mod:`.estimates`): the energy bodies pass on to each
other by collisions and joints (the most a head-on collision passes, by mass class), and
what each body can hit (kinematic obstacles, other dynamic bodies, restitution above 1)."""

from __future__ import annotations

import numpy as np

from ._scan import DYNAMIC, KINEMATIC, Scan


def pass_on(sc: Scan, idx: np.ndarray, m: np.ndarray, own: np.ndarray,
             edges: list[tuple[int, int]]) -> np.ndarray:
    """Each body's energy budget: the largest of its own and of what the others' budgets
    pass on by a collision (any two dynamic bodies with solid shapes) or through a joint
    (``edges``)."""
    n = len(idx)
    budget = own.copy()
    if n < 2:
        return budget
    solid = np.zeros(len(sc.bodies), dtype=bool)
    solid[sc.owner[~sc.sensor]] = True
    collider = solid[idx]
    e_body = np.zeros(len(sc.bodies))
    np.maximum.at(e_body, sc.owner[~sc.sensor], sc.elasticity[~sc.sensor])
    e = e_body[idx]
    e_top = np.sort(np.where(collider, e, 0.0))[-2:]
    # Restitution of i with the bounciest other body (at most 1 for the fraction).
    e_other = np.where(e >= e_top[-1], e_top[0], e_top[-1])
    bounce = ((1.0 + np.minimum(1.0, e * e_other)) / 2.0) ** 2
    classes, which = _mass_classes(m)
    a = np.array([i for i, _ in edges], dtype=int)
    b = np.array([j for _, j in edges], dtype=int)
    with np.errstate(over="ignore", invalid="ignore"):
        joint_frac = np.where((a != b), _share(m[a], m[b]), 0.0) if len(edges) else None
        for _ in range(n + 1):
            before = budget.copy()
            # Collisions: the best budget in each mass class, not counting the body itself.
            best = np.full(len(classes), -np.inf)
            np.maximum.at(best, which[collider], budget[collider])
            second = np.full(len(classes), -np.inf)
            top_of = np.full(len(classes), -1)
            for c in range(len(classes)):
                members = np.flatnonzero(collider & (which == c))
                if len(members):
                    order = members[np.argsort(budget[members])[::-1]]
                    top_of[c] = order[0]
                    second[c] = budget[order[1]] if len(order) > 1 else -np.inf
            for c, (lo, hi) in enumerate(classes):
                value = np.where(top_of[c] == np.arange(n), second[c], best[c])
                frac = _share_range(m, lo, hi) * bounce
                budget = np.where(collider & np.isfinite(value),
                                  np.maximum(budget, frac * value), budget)
            if joint_frac is not None:
                np.maximum.at(budget, a, joint_frac * budget[b])
                np.maximum.at(budget, b, joint_frac * budget[a])
            if np.array_equal(before, budget):
                break
    return budget


def _share(mi: np.ndarray, mj: np.ndarray) -> np.ndarray:
    """The most kinetic energy a head-on elastic collision passes from j to i at rest:
    4 m_i m_j / (m_i + m_j)^2."""
    return 4.0 * mi * mj / (mi + mj) ** 2


def _share_range(mi: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """:func:`_share` at its largest over m_j from ``lo`` to ``hi`` (1 where m_i is in it)."""
    nearest = np.clip(mi, lo, hi)
    return _share(mi, nearest)


def _mass_classes(m: np.ndarray) -> tuple[list[tuple[float, float]], np.ndarray]:
    """The bodies' masses in classes (lo, hi): each distinct mass when there are at most 64,
    else bins a factor 1.25 wide."""
    unique = np.unique(m)
    if len(unique) <= 64:
        return [(float(u), float(u)) for u in unique], np.searchsorted(unique, m)
    edges = np.exp(np.arange(np.log(unique[0]), np.log(unique[-1]) + 0.224, 0.223))
    which = np.clip(np.searchsorted(edges, m, side="right") - 1, 0, len(edges) - 1)
    classes = [(float(edges[c]), float(edges[c] * 1.25)) for c in range(len(edges))]
    return classes, which


def kinematic_obstacles(sc: Scan, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each body, the fastest kinematic shape it can hit (speed of its fastest point)
    and the restitution with it."""
    from ._scan import best_other

    kinematic = (sc.kind[sc.owner] == KINEMATIC)
    speed = (np.hypot(sc.v[sc.owner, 0], sc.v[sc.owner, 1])
             + np.abs(sc.w[sc.owner]) * sc.reach)
    value = np.where(kinematic, speed, np.nan)
    fastest, shape = best_other(sc, value, kinematic, idx, "max")
    if len(sc.shapes) == 0:
        return np.zeros(len(idx)), np.zeros(len(idx))
    e_body = np.zeros(len(sc.bodies))
    np.maximum.at(e_body, sc.owner, sc.elasticity)
    e = np.where(shape >= 0, e_body[idx] * sc.elasticity[np.maximum(shape, 0)], 0.0)
    return np.nan_to_num(fastest, nan=0.0), e


def touches_dynamic(sc: Scan, idx: np.ndarray) -> np.ndarray:
    """Whether each body can touch another dynamic body's solid shape."""
    from ._scan import best_other

    dynamic = sc.kind[sc.owner] == DYNAMIC
    found, _ = best_other(sc, np.ones(len(sc.shapes)), dynamic, idx, "max")
    return ~np.isnan(found)


def too_bouncy(sc: Scan, idx: np.ndarray) -> np.ndarray:
    """Whether each body has a shape whose restitution with the bounciest shape of another
    body is above 1."""
    e_body = np.zeros(len(sc.bodies))
    np.maximum.at(e_body, sc.owner, sc.elasticity)
    if len(e_body) < 2:
        return np.zeros(len(idx), dtype=bool)
    order = np.argsort(e_body)
    top, second = e_body[order[-1]], e_body[order[-2]]
    other = np.where(np.arange(len(e_body)) == order[-1], second, top)
    return (e_body * other > 1.0)[idx]
