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
from typing import Any

import numpy as np

from ..errors import UsageError
from ..model import args
from ._bodies import Bodies, Joints, Link
from ._refusals import settings_problem
from ._scan import DYNAMIC, Scan, scan

__all__ = ["Reach", "reach"]

#: Longest step (s) the guard looks at and :func:`.stepping.step` takes: past it (11.6 days) a
#: pymunk space's state overflows (positions of -inf or NaN at 1e100 s and more), and so do
#: the guard's own estimates (a fall's speed at 1e154 s).
MAX_DT = 1e6


def step_dt(dt: Any) -> float:
    """``dt`` checked at the border: a finite number > 0 (s), at most :data:`MAX_DT`."""
    dt = args.real(dt, "dt", "s")
    if dt > MAX_DT:
        raise UsageError(f"dt = {args.show(dt)}: must be a finite number > 0 and <= "
                         f"{MAX_DT:g} (s): a step longer than that is not one a pymunk "
                         "space can take (its state overflows)", param="dt")
    return dt


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
    dt = step_dt(dt)
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

    bodies = Bodies.of(sc, unit)
    joints = Joints.empty(bodies)
    for j, c in enumerate(sc.space.constraints):
        joints.add(bodies, Link.of(sc, bodies, c, j), pymunk)
    fall, level, source_fall = bodies.falls(joints, pymunk)
    speed, speeds = bodies.speeds(joints, fall, dt)
    source, bound = bodies.sources(joints, speed, speeds, source_fall)
    idx, pivot = bodies.idx, joints.pivot
    points = np.where(pivot, speed, speed + np.abs(sc.w[idx]) * bodies.own_reach)
    return Estimates(idx=idx, speed=speed, now=bodies.now, point=pivot, fall=fall, level=level,
                     held=joints.held_by, source=source, bound=bound, points=points,
                     kin=speeds.kin, radius=bodies.own_reach, region=joints.region)
