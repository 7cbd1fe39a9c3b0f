"""The constraints as the probe's run (:mod:`._probe`) solves for their impulses: each
constraint's ends (:class:`_End`) and the parts solved together (:class:`_Part`), where a
groove holds its anchor, the springs' arrays for their energy, and the least-squares solve."""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

__all__: list[str] = []


class _End(NamedTuple):
    """One end of a constraint: its body's place in the batch rows (-1: a body the batch
    does not list, such as a static or kinematic body only joints use: read from ``body``),
    its row of equations (-1: not dynamic), whether it is kinematic, and the anchor and
    centre of gravity in body coordinates."""

    slot: int
    row: int
    kinematic: bool
    anchor: tuple[float, float]
    cog: tuple[float, float]
    body: Any = None


class _Part(NamedTuple):
    """Constraints tied together through the dynamic bodies they join (solved together):
    ``cons`` their places, ``first`` where each one's impulse components start (and the
    count at the end), ``rows`` the rows' bodies (numbers of the run's ``row_bodies``,
    :class:`._probe._Run`)."""

    cons: list[int]
    first: list[int]
    rows: list[int]


def _springs(cons: list[Any], slot: dict[int, int], pymunk: Any) -> Any:
    """The springs of ``cons`` for their energy from the batch rows: for ends a and b, the
    batch row of the body (-1: not listed, then its world anchor and angle, fixed), the
    anchor in body coordinates; stiffness, rest length (or angle), whether rotary. None
    without springs."""
    springs = [c for c in cons if isinstance(c, pymunk.DampedSpring | pymunk.DampedRotarySpring)]
    if not springs:
        return None
    rotary = np.array([isinstance(c, pymunk.DampedRotarySpring) for c in springs])
    ends = []
    for which in ("a", "b"):
        bodies = [getattr(c, which) for c in springs]
        anchors = [(0.0, 0.0) if r else tuple(getattr(c, f"anchor_{which}"))
                   for c, r in zip(springs, rotary, strict=True)]
        slots = np.array([slot.get(int(b.id), -1) for b in bodies])
        fixed = np.array([(*b.local_to_world(p), b.angle) for b, p in zip(bodies, anchors,
                                                                           strict=True)])
        ends.append((slots, np.array([p[0] for p in anchors]), np.array([p[1] for p in anchors]),
                     fixed))
    stiff = np.array([float(c.stiffness) for c in springs])
    rest = np.array([float(c.rest_angle if r else c.rest_length)
                     for c, r in zip(springs, rotary, strict=True)])
    return ends, stiff, rest, rotary


def _solved(a_mat: np.ndarray, values: np.ndarray) -> np.ndarray | None:
    """The least-squares solution of ``a_mat x = values`` by its normal equations, or None
    when ``a_mat`` is not clearly of full column rank (its Cholesky factor has a pivot under
    1e-6 of the largest: the caller then takes numpy's least squares)."""
    normal = a_mat.T @ a_mat
    try:
        factor = np.linalg.cholesky(normal)
    except np.linalg.LinAlgError:
        return None
    pivots = np.abs(np.diagonal(factor))
    if not len(pivots) or pivots.min() <= 1e-6 * pivots.max():
        return None
    return np.linalg.solve(normal, a_mat.T @ values)


def _replace_end(pair: tuple[_End, _End], e: int, row: int) -> tuple[_End, _End]:
    """``pair`` with end ``e``'s row set."""
    ends = list(pair)
    ends[e] = ends[e]._replace(row=row)
    return ends[0], ends[1]


def _on_groove(run: Any, c: Any, end_a: _End, anchor_b: tuple[float, float],
               pose: list[list[float]]
               ) -> tuple[tuple[float, float, float, float], tuple[float, float], bool]:
    """Where a groove (on body a) holds its anchor (on body b, at ``anchor_b`` in the world):
    the anchor's projection on the groove, clamped to its ends, as pymunk's groove joint
    takes it (world point and offset from a's centre of gravity); the groove's direction (a
    unit vector), and whether the anchor is inside its ends (then pymunk's impulse has no
    part along the groove). ``run`` is the probe's run (:class:`._probe._Run`), whose
    ``_world`` places a point of a body in the world."""
    ta = run._world(end_a, tuple(c.groove_a), pose)
    tb = run._world(end_a, tuple(c.groove_b), pose)
    ax, ay = tb[0] - ta[0], tb[1] - ta[1]
    length = math.hypot(ax, ay)
    tx, ty = (ax / length, ay / length) if length > 0 else (1.0, 0.0)
    s = (anchor_b[0] - ta[0]) * tx + (anchor_b[1] - ta[1]) * ty
    if s <= 0.0:
        return ta, (tx, ty), False
    if s >= length:
        return tb, (tx, ty), False
    return (ta[0] + tx * s, ta[1] + ty * s, ta[2] + tx * s, ta[3] + ty * s), (tx, ty), True
