"""How fast each body of a space can be moving when it meets an obstacle: per-body reach
estimates for the step-size guard's tunnelling check.

pymunk finds a contact only once shapes overlap, so what decides pass-through is the speed at
which a body can arrive at something it can hit. Each dynamic body gets an energy budget and
a speed from it:

- **its own energy**: its kinetic energy now, the energy of the springs fixed to it (each
  spring's whole energy, to either end), and its fall along gravity:

  - a body *held* by a joint to a static or kinematic body (``PivotJoint``, ``PinJoint``,
    ``SlideJoint``, ``GrooveJoint`` of unlimited ``max_force``) can lower its centre of
    gravity only as far as the joint lets it: a pivot to the pivot's level plus the centre of
    gravity's distance from it, a pin or slide to the anchor's level plus the joint's length
    and that distance, a groove to its lower end's level plus that distance;
  - a free body falls to the *floor under it*: the first static or kinematic shape straight
    below it (a circle as wide as the body swept down, through pymunk's own spatial index),
    and down that floor to its lowest point on top (a slope is slid down), and on to the next
    floor under that point if there is one;
  - a free body with nothing under it falls to the lowest point of anything it could hit
    (static and kinematic shapes, and held bodies swung to their lowest);

- **energy passed on**: a collision between bodies i and j gives i at most the fraction
  ``4 m_i m_j / (m_i + m_j)^2 ((1 + e) / 2)^2`` of the kinetic energy j brings (head on, j
  into i at rest; ``e`` the restitution, at most 1), a joint between them the same with
  e = 1. Each body's budget is the largest of its own and of what any other body's budget
  passes on that way (the fraction is at most 1, so this settles). Contacts are counted
  between any two dynamic bodies whatever their distance;

- **the speed**: for a free body, the speed of its centre of gravity with the whole budget as
  kinetic energy in pymunk's step (the step's lag adds ``g dt / 2`` and a little more, so
  ``v = h + sqrt(h^2 + 2 B / m + 2 h |v0|)`` with ``h = g dt / 2``); for a body turning about
  a fixed pivot, the speed of its farthest point, ``sqrt(2 B / I_pivot)`` times that point's
  distance from the pivot; never less than its speed now;

- **what pumps energy in**, added and named: a kinematic obstacle it can hit bounces it off at
  up to ``(1 + e)`` times the obstacle's speed; a joint to a moving kinematic body drags it at
  that body's speed; a ``SimpleMotor`` spins it at up to its rate (plus its spin now); a pin
  or slide of length 0 holding it (pymunk cannot tell which way to pull, so gravity's kick of
  each step, ``g dt``, is undone only a step late) adds ``g dt``.

``bound`` says whether the estimate is an upper bound: True for a body that no other dynamic
body can touch (filters, sensors and ``collide_bodies = False`` counted), joined to no other
dynamic body, with nothing pumping energy in (no motor, no moving kinematic body it can meet,
no restitution above 1, no custom ``velocity_func`` or spring force, no pin of length 0);
then energy
conservation bounds its speed before it meets an obstacle. Otherwise it is an estimate: a
chain of collisions can pass on more than one collision does (a light ball dropped on a heavy
one bounces up at three times its speed). Not counted anywhere: the push pymunk gives shapes
that overlap (by more than ``collision_slop``) to separate them, and impulses a program
applies in its own callbacks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from .._pymunk import spring_function
from ..errors import UsageError
from ..model import args
from ..model.energy import rotational_ke, spring_potential, translational_ke
from ._refusals import settings_problem
from ._scan import DYNAMIC, KINEMATIC, Scan, scan, world_outline

__all__ = ["Reach", "reach"]

#: Joints that hold a body to a fixed one (they bound where its centre of gravity can go).
HOLDERS = ("PivotJoint", "PinJoint", "SlideJoint", "GrooveJoint")
#: Most floors followed down slopes from one body.
MAX_FLOORS = 16


@dataclass(frozen=True)
class Reach:
    """One dynamic body's reach estimate (see the module docstring).

    ``speed``: the estimate (length units/s): of its centre of gravity, or of its farthest
    point when ``point`` is True (a body turning about a fixed pivot); ``now``: the speed of
    its fastest point now (centre of gravity plus spin times the reach of its shapes);
    ``fall``: how far its centre of gravity can drop along gravity before it meets an
    obstacle (length units; 0 without gravity); ``level``: the depth along gravity
    (``position . g / |g|``) its centre of gravity reaches after that fall (None without
    gravity): below it the estimate says nothing; ``held``: the joint holding it ('' if
    free); ``source``: what sets the estimate, in words; ``bound``: whether the estimate is an
    upper bound (see the module docstring).

    Parameters
    ----------
    subject : str
        The body's label.
    speed : float
        The estimate (length units per time unit).
    now : float
        The speed of its fastest point now.
    point : bool
        The estimate is of its farthest point, not its centre of gravity.
    fall : float
        How far its centre of gravity can drop along gravity (length units).
    level : float or None
        The depth along gravity it reaches after that fall.
    held : str
        The joint holding it ('' if free).
    source : str
        What sets the estimate, in words.
    bound : bool
        Whether the estimate is a bound (True) or a guess.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a ball thrown at 5 m/s, nothing under it
    >>> space.gravity = (0.0, -9.8)
    >>> ball = pymunk.Body(1.0, 1.0)
    >>> ball.velocity = (3.0, 4.0)                  # m/s: thrown, nothing to fall onto
    >>> space.add(ball, pymunk.Circle(ball, 0.1))
    >>> (r,) = spaces.reach(space, 1 / 60)
    >>> r.now, round(r.speed, 4), r.source, r.bound  # 5 m/s, and what gravity adds in a step
    (5.0, 5.1633, 'its kinetic energy now', True)
    """

    subject: str
    speed: float
    now: float
    point: bool
    fall: float
    level: float | None
    held: str
    source: str
    bound: bool


def reach(space: Any, dt: float, units: str | None = None) -> tuple[Reach, ...]:
    """Each dynamic body's reach estimate (a :class:`Reach`, in the order of
    ``space.bodies``) for steps of ``dt`` (s); ``units`` names the space's length unit in
    the ``source`` texts (e.g. 'm' or 'px'; None: 'units').

    Parameters
    ----------
    space : pymunk.Space
        Any space.
    dt : float
        The step (the space's time unit).
    units : str or None, default None
        The space's length unit, for the texts.

    Returns
    -------
    tuple of Reach
        One per dynamic body.

    Raises
    ------
    UsageError
        ``space`` not a pymunk Space, ``dt`` not a number > 0 or ``units`` not a unit; or a
        space in a state no estimate holds for (a NaN, a body without a mass), naming it.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a ball 2 m above a floor
    >>> space.gravity = (0.0, -9.8)
    >>> ball = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.1))
    >>> ball.position = (0.0, 2.0)
    >>> space.add(ball, pymunk.Circle(ball, 0.1), pymunk.Segment(space.static_body, (-1, 0),
    ...                                                          (1, 0), 0.0))
    >>> (estimate,) = spaces.reach(space, 1 / 60, units="m")
    >>> estimate.subject, round(estimate.speed, 3), estimate.source   # m/s
    ('body 0', 6.185, 'falls 1.9 m to the floor under it')
    """
    space = args.space(space)
    dt = args.real(dt, "dt", "s")
    unit = length_unit(units)
    sc = scan(space)
    problem = settings_problem(space) or state_problem(sc, unit)
    if problem is not None:
        raise UsageError(f"space: {problem[0]}: {problem[1]}", param="space")
    est = estimate(sc, dt, unit)
    return tuple(est.rows(sc))


def length_unit(units: Any) -> str:
    """The name of the space's length unit for messages: ``units`` checked as
    :func:`.units.check_units` checks it ('units' when None)."""
    from .units import check_units

    return check_units(units)[0]


def percent(fraction: float) -> str:
    """A fraction in words for messages: '1.5 %', or 'without bound' when infinite."""
    return "without bound" if math.isinf(fraction) else f"{100 * fraction:.3g} %"


def energy_units(unit: str) -> tuple[str, str]:
    """The units of energy and power of a space whose length unit is ``unit`` (mass in kg,
    time in s, as pymunk programs take them; 'units', the unnamed length, gives 'energy
    units'): ('J', 'W') in metres."""
    from .units import SI, UNNAMED, energy_unit, power_unit

    u = UNNAMED if unit == UNNAMED[0] else (unit, SI[1], SI[2])
    return energy_unit(u), power_unit(u)


# --- what cannot be stepped ------------------------------------------------------------------


def state_problem(sc: Scan, unit: str = "units") -> tuple[str, str, float] | None:
    """The first body whose state no step can fix: (subject, what is wrong, the value), or
    None. A position, angle, velocity or spin that is not finite (pymunk carries a NaN on
    forever), or a dynamic body whose mass or moment is not a number > 0 and < inf (pymunk
    refuses to step it); then the first shape whose geometry (radius, offset, ends,
    vertices) is not finite. Values are given in ``unit`` (the length unit), kg, rad, s."""
    motion = np.column_stack([sc.pos, sc.angle, sc.v, sc.w])
    bad = ~np.isfinite(motion).all(axis=1)
    dyn = sc.kind == DYNAMIC
    bad_mass = dyn & ~((sc.mass > 0) & np.isfinite(sc.mass))
    bad_moment = dyn & ~((sc.moment > 0) & ~np.isnan(sc.moment))
    for i in np.flatnonzero(bad | bad_mass | bad_moment):
        i = int(i)
        who = sc.label(i)
        if bad[i]:
            for name, value, of in (("position", tuple(sc.pos[i]), unit),
                                    ("angle", sc.angle[i], "rad"),
                                    ("velocity", tuple(sc.v[i]), f"{unit}/s"),
                                    ("angular_velocity", sc.w[i], "rad/s")):
                vals = value if isinstance(value, tuple) else (value,)
                if not all(math.isfinite(x) for x in vals):
                    shown = (f"({vals[0]:g}, {vals[1]:g}) {of}" if len(vals) == 2
                             else f"{vals[0]:g} {of}")
                    what = (f"{name} = {shown} is not a finite number: no step fixes it "
                            "(pymunk carries it into every later step); set the body's state "
                            "again or rebuild the space")
                    return who, what, float(next(x for x in vals if not math.isfinite(x)))
        what = "mass" if bad_mass[i] else "moment"
        value = float(sc.mass[i] if bad_mass[i] else sc.moment[i])
        of = "kg" if bad_mass[i] else f"kg {unit}²"
        text = (f"{what} = {value:g} {of}: pymunk steps a dynamic body only with a mass > 0 and "
                "< inf and a moment > 0 (give its shapes a mass or density, or set "
                f"body.{what})")
        return who, text, value
    for j in np.flatnonzero(np.isnan(sc.reach)):
        shape = sc.shapes[int(j)]
        name, vals = _bad_geometry(shape)
        shown = (f"({vals[0]:g}, {vals[1]:g}) {unit}" if len(vals) == 2
                 else f"{vals[0]:g}")              # a radius that is not a number has no unit
        who = f"shape {int(j)} ({type(shape).__name__} on {sc.label(int(sc.owner[j]))})"
        what = (f"{name} = {shown} is not a finite number: no step fixes it (its contacts and "
                "sizes would be NaN); give the shape finite geometry")
        return who, what, float(next(x for x in vals if not math.isfinite(x)))
    return None


def _bad_geometry(shape: Any) -> tuple[str, tuple[float, ...]]:
    """The first number of ``shape``'s geometry that is not finite: (its name, its value as a
    tuple of one or two numbers)."""
    fields = [("radius", (float(shape.radius),))]
    for name in ("offset", "a", "b"):
        if hasattr(shape, name):
            fields.append((name, tuple(getattr(shape, name))))
    if hasattr(shape, "get_vertices"):
        fields += [(f"vertex {k}", tuple(v)) for k, v in enumerate(shape.get_vertices())]
    return next(((n, v) for n, v in fields if not all(math.isfinite(x) for x in v)),
                ("geometry", (math.nan,)))


# --- the estimate ----------------------------------------------------------------------------


@dataclass
class Estimates:
    """The estimates over the dynamic bodies ``idx`` (arrays in that order), and what the
    guard reads besides: ``points`` (the estimate as a speed of the fastest point), ``kin``
    (the fastest kinematic obstacle each can hit), ``radius`` (the reach of its shapes from
    its centre of gravity) and ``region`` (left, bottom, right, top: the box a held body's
    shapes cannot leave; nan for a free body)."""

    idx: np.ndarray
    speed: np.ndarray
    now: np.ndarray
    point: np.ndarray
    fall: np.ndarray
    level: np.ndarray
    held: list[str]
    source: list[str]
    bound: np.ndarray
    points: np.ndarray
    kin: np.ndarray
    radius: np.ndarray
    region: np.ndarray

    def rows(self, sc: Scan) -> list[Reach]:
        return [Reach(sc.label(int(i)), float(self.speed[k]), float(self.now[k]),
                      bool(self.point[k]), float(self.fall[k]),
                      None if math.isnan(self.level[k]) else float(self.level[k]),
                      self.held[k], self.source[k], bool(self.bound[k]))
                for k, i in enumerate(self.idx)]


def estimate(sc: Scan, dt: float, unit: str = "units") -> Estimates:
    """The reach estimates of every dynamic body of ``sc`` at steps of ``dt`` (s)."""
    import pymunk

    bodies = _Bodies.of(sc, unit)
    joints = _Joints.empty(bodies)
    for j, c in enumerate(sc.space.constraints):
        joints.add(bodies, _Link.of(sc, bodies, c, j), pymunk)
    fall, level, source_fall = bodies.falls(joints, pymunk)
    speed, speeds = bodies.speeds(joints, fall, dt)
    source, bound = bodies.sources(joints, speed, speeds, source_fall)
    idx, pivot = bodies.idx, joints.pivot
    points = np.where(pivot, speed, speed + np.abs(sc.w[idx]) * bodies.own_reach)
    return Estimates(idx=idx, speed=speed, now=bodies.now, point=pivot, fall=fall, level=level,
                     held=joints.held_by, source=source, bound=bound, points=points,
                     kin=speeds.kin, radius=bodies.own_reach, region=joints.region)


@dataclass
class _Bodies:
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
    def of(cls, sc: Scan, unit: str) -> _Bodies:
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

    def falls(self, joints: _Joints, pymunk: Any) -> tuple[np.ndarray, np.ndarray, list[str]]:
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
        floors = _Floors(sc, self.down, pymunk)
        lowest = floors.lowest_reachable(sc, idx, held_level, self.own_reach)
        bottoms, starts, radii, filters = _columns(sc, idx, self.down)
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

    def speeds(self, joints: _Joints, fall: np.ndarray, dt: float) -> tuple[np.ndarray, _Speeds]:
        """Each body's speed estimate (length units/s; see the module docstring), before
        motors and its speed now are counted, and what it was made of."""
        sc, m, g = self.sc, self.m, self.sc.g
        kin, e_kin = _kinematic_obstacles(sc, self.idx)
        pushed = joints.dragged + (1.0 + np.minimum(1.0, e_kin)) * kin
        springs, pivot = joints.springs, joints.pivot
        with np.errstate(over="ignore", invalid="ignore"):
            own = self.kinetic + springs + m * g * fall + translational_ke(m, pushed, 0.0)
            budget = _pass_on(sc, self.idx, m, own, joints.edges)
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

    def sources(self, joints: _Joints, speed: np.ndarray, speeds: _Speeds,
                source_fall: list[str]) -> tuple[list[str], np.ndarray]:
        """Each body's final speed (``speed`` is raised in place by motors and by its speed
        now), the text saying what sets it, and whether it is a bound."""
        sc, idx, n, unit = self.sc, self.idx, len(self.idx), self.unit
        pumped, motor = joints.pumped, joints.motor
        bound = np.ones(n, dtype=bool)
        others = _touches_dynamic(sc, idx)
        bouncy = _bouncy(sc, idx)
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
class _Joints:
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
    def empty(cls, bodies: _Bodies) -> _Joints:
        n = len(bodies.idx)
        return cls(springs=np.zeros(n), pumped=[[] for _ in range(n)],
                   held_level=np.full(n, np.nan), held_by=[""] * n,
                   region=np.full((n, 4), np.nan), loose=np.zeros(n, dtype=bool),
                   pivot=np.zeros(n, dtype=bool),
                   pivot_inertia=np.array(bodies.inertia, dtype=float),
                   pivot_reach=np.array(bodies.own_reach, dtype=float), edges=[],
                   motor=np.zeros(n), dragged=np.zeros(n))

    def add(self, bodies: _Bodies, link: _Link, pymunk: Any) -> None:
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

    def _spring(self, sc: Scan, link: _Link, pymunk: Any) -> None:
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

    def _fixed_end(self, bodies: _Bodies, link: _Link, end: tuple[int, int, str],
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


class _Link(NamedTuple):
    """A constraint as the estimate reads it: its label, its bodies' numbers in the scan
    (``ia``, ``ib``) and their places among the dynamic bodies (None for others)."""

    c: Any
    label: str
    ia: int
    ib: int
    ka: int | None
    kb: int | None

    @classmethod
    def of(cls, sc: Scan, bodies: _Bodies, c: Any, j: int) -> _Link:
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


def _columns(sc: Scan, idx: np.ndarray, down: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[Any]]:
    """For the bodies ``idx``: the lowest depth of their solid shapes now, and the swept
    circle that finds the floor under each: start (the centre of their bounding box),
    radius (half their width across gravity) and the filter of their first solid shape
    (None for a body without a solid shape)."""
    solid = np.flatnonzero(~sc.sensor)
    nb = len(sc.bodies)
    lo = np.full((nb, 2), np.inf)
    hi = np.full((nb, 2), -np.inf)
    np.minimum.at(lo, sc.owner[solid], sc.bb[solid, :2])
    np.maximum.at(hi, sc.owner[solid], sc.bb[solid, 2:])
    first: dict[int, Any] = {}
    for j in solid[::-1]:
        first[int(sc.owner[j])] = sc.shapes[int(j)].filter
    # A body without a solid shape keeps infinite bounds here; it gets no filter below.
    lo, hi = np.where(np.isfinite(lo), lo, 0.0)[idx], np.where(np.isfinite(hi), hi, 0.0)[idx]
    across = np.array([-down[1], down[0]])
    corners = [np.column_stack([x[:, 0], y[:, 1]]) for x in (lo, hi) for y in (lo, hi)]
    depth = np.max([c @ down for c in corners], axis=0)
    width = np.max([c @ across for c in corners], axis=0) - np.min(
        [c @ across for c in corners], axis=0)
    centre = 0.5 * (lo + hi)
    return depth, centre, 0.5 * width, [first.get(int(i)) for i in idx]


class _Floors:
    """The static and kinematic shapes as floors: copies in a private pymunk space (so that
    pymunk's spatial index finds the one under a body), each with its lowest point on top."""

    def __init__(self, sc: Scan, down: np.ndarray, pymunk: Any) -> None:
        self.down = down
        self.space = pymunk.Space()
        self.low: dict[Any, tuple[float, np.ndarray]] = {}
        fixed = np.flatnonzero((sc.kind[sc.owner] != DYNAMIC) & ~sc.sensor)
        deepest = -math.inf
        static = self.space.static_body
        for j in fixed:
            shape = sc.shapes[int(j)]
            kind, pts, r = world_outline(shape, sc.bodies[int(sc.owner[j])], pymunk)
            if kind == "circle":
                copy = pymunk.Circle(static, r, tuple(pts[0]))
                low_point, low = pts[0], float(pts[0] @ down)
            elif kind == "segment":
                copy = pymunk.Segment(static, tuple(pts[0]), tuple(pts[1]), r)
                k = int(np.argmax(pts @ down))
                low_point, low = pts[k], float(pts[k] @ down) - r
            else:
                copy = pymunk.Poly(static, [tuple(p) for p in pts], radius=r)
                low_point, low = _poly_low(pts, down)
                low -= r
            copy.filter = shape.filter
            self.space.add(copy)
            self.low[copy] = (low, low_point)
            deepest = max(deepest, float((pts @ down).max()) + r)
        self.deepest = deepest
        self.fixed = fixed

    def level(self, start: Any, radius: float, filt: Any) -> float | None:
        """The depth a body's lowest point reaches on the floors under the swept circle from
        ``start`` (None when nothing is under it)."""
        if not self.low:
            return None
        down = self.down
        start = np.asarray(start, dtype=float)
        span = max(self.deepest - float(start @ down), 0.0) + 2.0 * radius + 1.0
        end = start + down * span
        hit = self.space.segment_query_first(tuple(start), tuple(end), radius, filt)
        if hit is None:
            return None
        seen = {hit.shape}
        low, point = self.low[hit.shape]
        level = low
        for _ in range(MAX_FLOORS):
            landed = float(np.array([hit.point.x, hit.point.y]) @ down)
            if not low > landed + 1e-9 * (1.0 + abs(landed)):
                break                         # a flat floor: nothing lower by sliding
            # Slid down to its lowest point: what is under that point?
            start = point - down * radius
            span = max(self.deepest - float(start @ down), 0.0) + 2.0 * radius + 1.0
            hits = [h for h in self.space.segment_query(tuple(start), tuple(start + down * span),
                                                         radius, filt) if h.shape not in seen]
            if not hits:
                break
            hit = min(hits, key=lambda h: h.alpha)
            seen.add(hit.shape)
            low, point = self.low[hit.shape]
            if not low > level:
                break                         # a wall at the end of the slope
            level = low
        return level

    def lowest_reachable(self, sc: Scan, idx: np.ndarray, held_level: np.ndarray,
                         own_reach: np.ndarray) -> float | None:
        """The deepest point anything solid can reach: the static and kinematic shapes'
        bottoms, and held bodies swung to their lowest (None if there is nothing)."""
        deepest = self.deepest if self.low else -math.inf
        held = ~np.isnan(held_level)
        if held.any():
            deepest = max(deepest, float((held_level[held] + own_reach[held]).max()))
        return None if math.isinf(deepest) else deepest


def _poly_low(pts: np.ndarray, down: np.ndarray) -> tuple[np.ndarray, float]:
    """The lowest point on a polygon's top (its vertices on edges that face up)."""
    edge = np.roll(pts, -1, axis=0) - pts
    normal = np.column_stack([edge[:, 1], -edge[:, 0]])     # outward for pymunk's CCW order
    up = normal @ down < 0
    top = np.unique(np.concatenate([np.flatnonzero(up), (np.flatnonzero(up) + 1) % len(pts)]))
    if len(top) == 0:
        top = np.arange(len(pts))
    depth = pts[top] @ down
    k = int(top[int(np.argmax(depth))])
    return pts[k], float(depth.max())


def _pass_on(sc: Scan, idx: np.ndarray, m: np.ndarray, own: np.ndarray,
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


def _kinematic_obstacles(sc: Scan, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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


def _touches_dynamic(sc: Scan, idx: np.ndarray) -> np.ndarray:
    """Whether each body can touch another dynamic body's solid shape."""
    from ._scan import best_other

    dynamic = sc.kind[sc.owner] == DYNAMIC
    found, _ = best_other(sc, np.ones(len(sc.shapes)), dynamic, idx, "max")
    return ~np.isnan(found)


def _bouncy(sc: Scan, idx: np.ndarray) -> np.ndarray:
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
