"""The dynamic bodies and the space's constraints as the reach estimate (:mod:`.estimates`)
reads them: ``Bodies`` (each body's mass, reach, speed and energy now; its fall, speed and
what sets it) and ``Joints`` (what each constraint does to the bodies it joins: springs'
energy, joints that hold a body to a fixed one or drag it, motors)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from .._pymunk import spring_function
from ..model.energy import rotational_ke, spring_potential, translational_ke
from ._floors import Floors, columns
from ._scan import DYNAMIC, KINEMATIC, Scan
from ._sharing import kinematic_obstacles, pass_on, too_bouncy, touches_dynamic

#: Joints that hold a body to a fixed one (they bound where its centre of gravity can go).
HOLDERS = ("PivotJoint", "PinJoint", "SlideJoint", "GrooveJoint")


@dataclass
class Bodies:
    """The dynamic bodies ``idx`` of ``sc`` as the estimate reads them (arrays in that
    order): mass, moment, the reach of their shapes, the speed of their centre of gravity and
    of their fastest point now, their kinetic energy; ``down`` the unit vector along gravity
    and ``unit`` the length unit's name for the texts."""

    sc: Scan
    unit: str
    idx: np.ndarray
    m: np.ndarray
    inertia: np.ndarray
    own_reach: np.ndarray
    speed_cg: np.ndarray
    now: np.ndarray
    kinetic: np.ndarray
    down: np.ndarray
    places: dict[int, int]

    @classmethod
    def of(cls, sc: Scan, unit: str) -> Bodies:
        idx = sc.dynamic
        m = sc.mass[idx]
        inertia = sc.moment[idx]
        with np.errstate(over="ignore", invalid="ignore"):
            own_reach = _body_reach(sc, idx)
            speed_cg = np.hypot(sc.v[idx, 0], sc.v[idx, 1])
            now = speed_cg + np.abs(sc.w[idx]) * own_reach
            spin = np.where(np.isfinite(inertia), rotational_ke(
                np.where(np.isfinite(inertia), inertia, 0.0), sc.w[idx]), 0.0)
            kinetic = translational_ke(m, sc.v[idx, 0], sc.v[idx, 1]) + spin
        return cls(sc, unit, idx, m, inertia, own_reach, speed_cg, now, kinetic, sc.down(),
                   {int(i): k for k, i in enumerate(idx)})

    def falls(self, joints: Joints, pymunk: Any) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """How far each centre of gravity can fall along gravity (length units), the depth
        it reaches (nan without gravity) and the text saying so ('' for none)."""
        sc, idx, n, unit = self.sc, self.idx, len(self.idx), self.unit
        depth_cg = sc.cg @ self.down
        fall = np.zeros(n)
        level = np.full(n, np.nan)
        source_fall = [""] * n
        if not sc.g > 0:
            return fall, level, source_fall
        held_level = joints.held_level
        held = ~np.isnan(held_level)
        fall[held] = np.maximum(0.0, held_level[held] - depth_cg[idx[held]])
        level[held] = np.maximum(held_level[held], depth_cg[idx[held]])
        for k in np.flatnonzero(held):
            source_fall[k] = f"held by {joints.held_by[k]}: falls {fall[k]:.4g} {unit}"
        free = [k for k in range(n) if not held[k]]
        if not free:
            return fall, level, source_fall
        floors = Floors(sc, self.down, pymunk)
        lowest = floors.lowest_reachable(sc, idx, held_level, self.own_reach)
        bottoms, starts, radii, filters = columns(sc, idx, self.down)
        for k in free:
            if filters[k] is None:
                continue
            floor = floors.level(starts[k], float(radii[k]), filters[k])
            where = "the floor under it"
            if floor is None:
                floor, where = lowest, "the lowest point it could hit"
            if floor is None:
                continue
            fall[k] = max(0.0, floor - float(bottoms[k]))
            level[k] = depth_cg[int(idx[k])] + fall[k]
            source_fall[k] = f"falls {fall[k]:.4g} {unit} to {where}"
        return fall, level, source_fall

    def speeds(self, joints: Joints, fall: np.ndarray, dt: float) -> tuple[np.ndarray, _Speeds]:
        """Each body's speed estimate (length units/s; see the module docstring), before
        motors and its speed now are counted, and what it was made of."""
        sc, m, g = self.sc, self.m, self.sc.g
        kin, e_kin = kinematic_obstacles(sc, self.idx)
        pushed = joints.dragged + (1.0 + np.minimum(1.0, e_kin)) * kin
        springs, pivot = joints.springs, joints.pivot
        with np.errstate(over="ignore", invalid="ignore"):
            own = self.kinetic + springs + m * g * fall + translational_ke(m, pushed, 0.0)
            budget = pass_on(sc, self.idx, m, own, joints.edges)
            h = 0.5 * g * dt
            free_speed = h + np.sqrt(h * h + 2.0 * budget / m + 2.0 * h * self.speed_cg)
            pivot_speed = np.sqrt(2.0 * budget / np.where(joints.pivot_inertia > 0,
                                                            joints.pivot_inertia, np.inf)
                                  ) * joints.pivot_reach
            speed = np.where(pivot, pivot_speed, free_speed) + np.where(joints.loose, g * dt,
                                                                        0.0)
            # Speeds past 1e154 overflow as squares: then add them instead (larger, finite).
            linear = (self.now + pushed
                      + np.sqrt(2.0 * np.maximum(springs + m * g * fall, 0.0) / m))
            speed = np.where(np.isfinite(speed), speed, linear)
            speed = np.where(np.isnan(speed), np.inf, speed)
        return speed, _Speeds(kin, e_kin, own, budget)

    def sources(self, joints: Joints, speed: np.ndarray, speeds: _Speeds,
                source_fall: list[str]) -> tuple[list[str], np.ndarray]:
        """Each body's final speed (``speed`` is raised in place by motors and by its speed
        now), the text saying what sets it, and whether it is a bound."""
        sc, idx, n, unit = self.sc, self.idx, len(self.idx), self.unit
        pumped, motor = joints.pumped, joints.motor
        bound = np.ones(n, dtype=bool)
        others = touches_dynamic(sc, idx)
        bouncy = too_bouncy(sc, idx)
        joined = np.zeros(n, dtype=bool)
        for a, b in joints.edges:
            if a != b:
                joined[a] = joined[b] = True
        source = []
        for k in range(n):
            why = []
            i = int(idx[k])
            if sc.field[i]:
                pumped[k].append("a custom velocity_func moves it: its field's energy is "
                                 "unknown")
            if speeds.kin[k] > 0:
                pumped[k].append(f"a kinematic obstacle at {speeds.kin[k]:.4g} {unit}/s")
            if speeds.e_kin[k] > 1.0 or bouncy[k]:
                pumped[k].append("restitution above 1")
            if motor[k] > 0:
                speed[k] = max(speed[k], (abs(sc.w[i]) + motor[k]) * joints.pivot_reach[k]
                               + (0.0 if joints.pivot[k] else self.speed_cg[k]))
            if self.now[k] > speed[k]:
                speed[k] = self.now[k]
                why.append("its speed now")
            else:
                why.append(_what_sets(k, speeds, source_fall, joints.springs))
            if pumped[k]:
                why.append("; ".join(dict.fromkeys(pumped[k])))
            bound[k] = not (pumped[k] or others[k] or joined[k])
            source.append("; ".join(why))
        return source, bound


class _Speeds(NamedTuple):
    """What the speed estimates were made of (arrays over the bodies): the fastest kinematic
    obstacle each can hit (length units/s) and the restitution with it, its own energy and
    its budget (J)."""

    kin: np.ndarray
    e_kin: np.ndarray
    own: np.ndarray
    budget: np.ndarray


def _what_sets(k: int, speeds: _Speeds, source_fall: list[str], springs: np.ndarray) -> str:
    """What sets body ``k``'s energy budget, in words."""
    if speeds.budget[k] > speeds.own[k] * (1 + 1e-12):
        return "energy passed on by other bodies"
    if source_fall[k]:
        return source_fall[k]
    if springs[k] > 0:
        return "its springs' energy"
    return "its kinetic energy now"


@dataclass
class Joints:
    """What the space's constraints do to the dynamic bodies (arrays over them): the energy
    of their springs (``springs``, J), what pumps energy in (``pumped``: the reasons;
    ``motor``: a motor's rate, rad/s; ``dragged``: the speed of a kinematic body a joint ties
    them to), how joints hold them (``held_level``, ``held_by``, ``region``, ``loose``;
    ``pivot``: turning about a fixed pivot, with ``pivot_inertia`` and ``pivot_reach`` about
    it), and the joints between two of them (``edges``)."""

    springs: np.ndarray
    pumped: list[list[str]]
    held_level: np.ndarray
    held_by: list[str]
    region: np.ndarray
    loose: np.ndarray
    pivot: np.ndarray
    pivot_inertia: np.ndarray
    pivot_reach: np.ndarray
    edges: list[tuple[int, int]]
    motor: np.ndarray
    dragged: np.ndarray

    @classmethod
    def empty(cls, bodies: Bodies) -> Joints:
        n = len(bodies.idx)
        return cls(springs=np.zeros(n), pumped=[[] for _ in range(n)],
                   held_level=np.full(n, np.nan), held_by=[""] * n,
                   region=np.full((n, 4), np.nan), loose=np.zeros(n, dtype=bool),
                   pivot=np.zeros(n, dtype=bool),
                   pivot_inertia=np.array(bodies.inertia, dtype=float),
                   pivot_reach=np.array(bodies.own_reach, dtype=float), edges=[],
                   motor=np.zeros(n), dragged=np.zeros(n))

    def add(self, bodies: Bodies, link: Link, pymunk: Any) -> None:
        """What the constraint of ``link`` does to the bodies it joins."""
        sc, c = bodies.sc, link.c
        if isinstance(c, pymunk.DampedSpring | pymunk.DampedRotarySpring):
            self._spring(sc, link, pymunk)
        if link.ka is not None and link.kb is not None:
            self.edges.append((link.ka, link.kb))
        if isinstance(c, pymunk.SimpleMotor):
            for k in (link.ka, link.kb):
                if k is not None:
                    self.motor[k] = max(self.motor[k], abs(float(c.rate)))
                    self.pumped[k].append(f"{link.label} turns it (rate {abs(c.rate):.4g} "
                                          "rad/s)")
            return
        for k, fixed, mine in ((link.ka, link.ib, "a"), (link.kb, link.ia, "b")):
            if k is not None and sc.kind[fixed] != DYNAMIC:
                self._fixed_end(bodies, link, (k, fixed, mine), pymunk)

    def _spring(self, sc: Scan, link: Link, pymunk: Any) -> None:
        c = link.c
        u, custom = _spring_energy(c, pymunk)
        inert = sc.moment if isinstance(c, pymunk.DampedRotarySpring) else sc.mass
        for k, here, there in ((link.ka, link.ia, link.ib), (link.kb, link.ib, link.ia)):
            if k is not None:
                # Released from rest, a spring gives its end the share m_other / (m +
                # m_other) (momentum is shared equally); all of it against a fixed end.
                other = inert[there] if sc.kind[there] == DYNAMIC else math.inf
                share = 1.0 if math.isinf(other) else other / (inert[here] + other)
                self.springs[k] += u * share
                if custom:
                    self.pumped[k].append(f"{link.label} has a custom force: its energy is "
                                          "unknown")

    def _fixed_end(self, bodies: Bodies, link: Link, end: tuple[int, int, str],
                   pymunk: Any) -> None:
        """Body ``k`` on end ``mine`` of ``link``, the other end the static or kinematic
        body ``fixed``: dragged by a moving kinematic body, held by a holding joint."""
        sc, c = bodies.sc, link.c
        k, fixed, mine = end
        if sc.kind[fixed] == KINEMATIC:
            vk = _anchor_speed(sc, fixed, c, "b" if mine == "a" else "a")
            if vk > 0:
                self.dragged[k] = max(self.dragged[k], vk)
                self.pumped[k].append(f"{link.label} ties it to kinematic {sc.label(fixed)} "
                                      f"moving at {vk:.4g} {bodies.unit}/s")
        if type(c).__name__ not in HOLDERS or math.isfinite(c.max_force):
            return
        hold = _hold(sc, c, (int(bodies.idx[k]), fixed, mine), bodies.down,
                     float(bodies.own_reach[k]))
        if hold is None:
            return
        level, r_pivot, box = hold
        if r_pivot is not None and not isinstance(c, pymunk.PivotJoint):
            # A pin or slide of length 0 has no direction to pull along: gravity's kick
            # each step is undone only by its error correction, a step late.
            self.loose[k] = True
            self.pumped[k].append(f"{link.label} has length 0: pymunk cannot tell which way "
                                  "to pull (a PivotJoint can)")
        if math.isnan(self.held_level[k]) or level < self.held_level[k]:
            self.held_level[k] = level
            self.held_by[k] = link.label
        self.region[k] = box if np.isnan(self.region[k]).all() else np.concatenate(
            [np.maximum(self.region[k, :2], box[:2]), np.minimum(self.region[k, 2:], box[2:])])
        if r_pivot is not None:
            self.pivot[k] = True
            self.pivot_inertia[k] = bodies.inertia[k] + bodies.m[k] * r_pivot**2
            self.pivot_reach[k] = r_pivot + bodies.own_reach[k]


class Link(NamedTuple):
    """A constraint as the estimate reads it: its label, its bodies' numbers in the scan
    (``ia``, ``ib``) and their places among the dynamic bodies (None for others)."""

    c: Any
    label: str
    ia: int
    ib: int
    ka: int | None
    kb: int | None

    @classmethod
    def of(cls, sc: Scan, bodies: Bodies, c: Any, j: int) -> Link:
        """Constraint ``c``, the ``j``-th of the space."""
        ia, ib = sc.number(c.a), sc.number(c.b)
        return cls(c, f"{type(c).__name__} {j}", ia, ib, bodies.places.get(ia),
                   bodies.places.get(ib))


def _body_reach(sc: Scan, idx: np.ndarray) -> np.ndarray:
    """Each body's farthest shape point from its centre of gravity (0 without shapes)."""
    out = np.zeros(len(sc.bodies))
    np.maximum.at(out, sc.owner, sc.reach)
    return out[idx]


def _spring_energy(c: Any, pymunk: Any) -> tuple[float, bool]:
    """A spring's energy now and whether a custom force function makes it unknown."""
    rotary = isinstance(c, pymunk.DampedRotarySpring)
    unknown = spring_function(c) is not None
    if rotary:
        extent, rest = c.a.angle - c.b.angle, c.rest_angle
    else:
        extent = (c.b.local_to_world(c.anchor_b) - c.a.local_to_world(c.anchor_a)).length
        rest = c.rest_length
    with np.errstate(over="ignore", invalid="ignore"):
        u = float(spring_potential(float(c.stiffness), float(extent), float(rest)))
    return (u if math.isfinite(u) else math.inf), unknown


def _anchor_speed(sc: Scan, i: int, c: Any, which: str) -> float:
    """Speed of body ``i``'s anchor ``which`` of joint ``c`` (its velocity plus spin times
    the anchor's distance from its centre of gravity)."""
    anchor = getattr(c, f"anchor_{which}", None)
    r = 0.0 if anchor is None else math.hypot(anchor.x - sc.cog[i, 0], anchor.y - sc.cog[i, 1])
    return float(math.hypot(*sc.v[i]) + abs(sc.w[i]) * r)


def _hold(sc: Scan, c: Any, end: tuple[int, int, str], down: np.ndarray, own_reach: float
          ) -> tuple[float, float | None, np.ndarray] | None:
    """How joint ``c`` holds dynamic body ``i`` on its end ``mine`` (``end`` = (i, fixed,
    mine)) to the fixed body ``fixed``: the lowest depth its centre of gravity can reach, for
    a pivot (a joint of length 0) the distance from the pivot to the centre of gravity (else
    None), and the box (left, bottom, right, top) its shapes cannot leave."""
    import pymunk

    i, fixed, mine = end
    body, other = sc.bodies[i], sc.bodies[fixed]
    cog = body.center_of_gravity

    def world(b: Any, p: Any) -> np.ndarray:
        w = b.local_to_world(p)
        return np.array([w.x, w.y])

    def box(points: list[np.ndarray], r: float) -> np.ndarray:
        pts = np.array(points)
        return np.concatenate([pts.min(axis=0) - r, pts.max(axis=0) + r])

    if isinstance(c, pymunk.GrooveJoint):
        if mine == "b":   # the fixed body carries the groove; the body's anchor slides in it
            ends = [world(other, c.groove_a), world(other, c.groove_b)]
            r = (c.anchor_b - cog).length
            return max(e @ down for e in ends) + r, None, box(ends, r + own_reach)
        p = world(other, c.anchor_b)
        r = max((c.groove_a - cog).length, (c.groove_b - cog).length)
        return p @ down + r, None, box([p], r + own_reach)
    mine_anchor = c.anchor_a if mine == "a" else c.anchor_b
    fixed_anchor = c.anchor_b if mine == "a" else c.anchor_a
    r = (mine_anchor - cog).length
    p = world(other, fixed_anchor)
    if isinstance(c, pymunk.PivotJoint):
        length = 0.0
    elif isinstance(c, pymunk.PinJoint):
        length = float(c.distance)
    else:
        length = float(c.max)
    if not math.isfinite(length):
        return None
    return (p @ down + length + r, (r if length == 0.0 else None),
            box([p], length + r + own_reach))
