"""A step-size guard for any pymunk space: which dt is too large, by how much, and the fix.

Checks (each a :class:`Finding` with the number, its limit and the fix):

- ``spring``: a ``DampedSpring``'s explicit step is stable only while w*dt < 2, with
  w = sqrt(k / m_eff); m_eff is the mass the spring moves along its axis, 1 / (1/m_a + 1/m_b +
  (r_a x n)^2 / I_a + (r_b x n)^2 / I_b): the reduced mass mu for anchors at the centres of
  gravity, the other body's mass when one end is static;
- ``rotary-spring``: the same for a ``DampedRotarySpring`` with w = sqrt(k (1/I_a + 1/I_b));
- ``spring-network``: a body held by two or more springs, against an upper bound of its
  fastest vibration (see :func:`_networks`);
- ``tunnelling``: pymunk finds a contact only once shapes overlap (no swept collisions), so a
  body moving farther in one step than half the thinnest shape it can hit plus half its own
  size can pass through it. The speed is the larger of the present closing speed (its centre
  of gravity plus spin times the reach of its shapes, plus the fastest obstacle's) and the
  speed from energy (plus a kinematic obstacle's, which keeps its speed): the body's kinetic
  energy plus ALL the potential energy (gravity down to the lowest static shape it can hit, or
  the lowest shape when there is none, and the springs) turned into its kinetic energy. An
  estimate, not a bound: another body's kinetic energy passed on is not counted;
- ``slop``: ``space.collision_slop`` is the overlap left alone; more than a tenth of the
  smallest shape lets shapes sink visibly (pymunk's 0.1 is a pixel-sized default: 10 cm in SI);
- ``bias``: with ``space.collision_bias`` < 1 pymunk pushes overlapping shapes apart with an
  extra velocity, which adds energy at elastic contacts (flagged where any contact is elastic).

:func:`suggest_dt` returns a step (dt divided into whole sub-steps) that clears every finding
a step can clear; slop and bias are settings, not steps. :class:`Driver` steps a space at a
fixed frame step in sub-steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..errors import UsageError
from ..model import args
from .accounting import body_label, constraint_label, energy

__all__ = ["Driver", "Finding", "check", "report", "shape_size", "spring_omega", "step",
           "substeps", "suggest_dt", "survey"]

#: w*dt limit of the explicit spring step.
SPRING_LIMIT = 2.0
#: Largest slop, as a fraction of the smallest shape's size.
SLOP_FRACTION = 0.1
#: Most sub-steps of one step, and most steps one call of :func:`step` or
#: :meth:`Driver.step` takes: past it a loop would run for hours, so it is refused at once.
MAX_STEPS = 10**9
#: Slop suggested, as a fraction of the smallest shape's size.
SLOP_SUGGESTED = 0.01


@dataclass(frozen=True)
class Finding:
    """One check that failed: ``kind`` (spring, rotary-spring, tunnelling, slop, bias), the
    ``subject`` it is about, the measured ``value`` and its ``limit`` (w*dt for springs, metres
    per step for tunnelling, metres for slop, the bias for bias), the ``fix`` in words and the
    largest step that clears it, ``dt_max`` (s; None when no step can)."""

    kind: str
    subject: str
    value: float
    limit: float
    fix: str
    dt_max: float | None = None

    def __str__(self) -> str:
        return f"{self.kind}: {self.subject}: {self.value:.4g} > {self.limit:.4g}; {self.fix}"


#: What ``speeds`` may be: the present speeds, the speeds from energy, or the larger.
SPEEDS = ("state", "energy", "both")


def _check(space: Any, dt: Any, speeds: Any = "both") -> tuple[Any, float, str]:
    """The guard's arguments checked at the border (UsageError naming the one that is not
    valid): a pymunk.Space, a step > 0 (s) and one of :data:`SPEEDS`."""
    return (args.space(space), args.real(dt, "dt", "s"), args.choice(speeds, "speeds", SPEEDS))


def _inverse_mass(body: Any) -> tuple[float, float]:
    """1/m (1/kg) and 1/I (1/(kg m^2)) of a body; 0 for static, kinematic, infinite."""
    import pymunk

    if body.body_type != pymunk.Body.DYNAMIC:
        return 0.0, 0.0
    inv_m = 0.0 if math.isinf(body.mass) else 1.0 / body.mass
    inv_i = 0.0 if math.isinf(body.moment) else 1.0 / body.moment
    return inv_m, inv_i


def spring_omega(spring: Any) -> float:
    """Angular frequency (rad/s) of a ``DampedSpring`` or ``DampedRotarySpring`` on its two
    bodies as they are now (0 if neither can move); see the module docstring."""
    import pymunk

    args.pymunk_object(spring, "spring", ("DampedSpring", "DampedRotarySpring"))
    a, b = spring.a, spring.b
    ma, ia = _inverse_mass(a)
    mb, ib = _inverse_mass(b)
    if isinstance(spring, pymunk.DampedRotarySpring):
        inv = ia + ib
    else:
        pa = a.local_to_world(spring.anchor_a)
        pb = b.local_to_world(spring.anchor_b)
        ra = pa - a.local_to_world(a.center_of_gravity)
        rb = pb - b.local_to_world(b.center_of_gravity)
        d = pb - pa
        length = d.length
        n = d / length if length > 0 else pymunk.Vec2d(1.0, 0.0)
        inv = ma + mb + ia * ra.cross(n) ** 2 + ib * rb.cross(n) ** 2
    return math.sqrt(spring.stiffness * inv)


def shape_size(shape: Any) -> float:
    """The thinnest extent of a shape (m): a circle's diameter, a segment's thickness
    (2 x radius), a polygon's least width across an edge plus 2 x radius."""
    import pymunk

    args.pymunk_object(shape, "shape", ("Shape",))
    if isinstance(shape, pymunk.Circle):
        return 2.0 * shape.radius
    if isinstance(shape, pymunk.Segment):
        return 2.0 * shape.radius
    if isinstance(shape, pymunk.Poly):
        verts = shape.get_vertices()
        width = math.inf
        for i, p in enumerate(verts):
            q = verts[(i + 1) % len(verts)]
            edge = q - p
            if edge.length == 0:
                continue
            n = edge.perpendicular_normal()
            dots = [v.dot(n) for v in verts]
            width = min(width, max(dots) - min(dots))
        return (0.0 if math.isinf(width) else width) + 2.0 * shape.radius
    return 0.0


def _reach(body: Any, shape: Any) -> float:
    """Farthest distance (m) of a shape's points from its body's centre of gravity."""
    import pymunk

    cg = body.center_of_gravity
    if isinstance(shape, pymunk.Circle):
        return (shape.offset - cg).length + shape.radius
    if isinstance(shape, pymunk.Segment):
        return max((shape.a - cg).length, (shape.b - cg).length) + shape.radius
    if isinstance(shape, pymunk.Poly):
        return max((v - cg).length for v in shape.get_vertices()) + shape.radius
    return 0.0


def _apart(space: Any) -> set[tuple[int, int]]:
    """Pairs of bodies (by id) that a constraint with ``collide_bodies = False`` keeps from
    colliding."""
    pairs = set()
    for c in space.constraints:
        if not c.collide_bodies:
            pairs.add((id(c.a), id(c.b)))
            pairs.add((id(c.b), id(c.a)))
    return pairs


def _speed(shape: Any) -> float:
    """Fastest a shape's points move now (m/s): its body's speed plus spin times reach; 0 for
    static bodies."""
    import pymunk

    body = shape.body
    if body.body_type == pymunk.Body.STATIC:
        return 0.0
    return body.velocity.length + abs(body.angular_velocity) * _reach(body, shape)


def _can_hit(s: Any, o: Any, apart: set[tuple[int, int]] = frozenset()) -> bool:
    return (o.body is not s.body and not o.sensor and not s.sensor
            and (id(s.body), id(o.body)) not in apart
            and not s.filter.rejects_collision(o.filter))


def _level(space: Any, down: tuple[float, float], apart: set[tuple[int, int]]) -> float | None:
    """The lowest point (largest coordinate along ``down``) of the static shapes a moving
    shape can hit, else of all shapes; None when the space has no shapes."""
    import pymunk

    shapes = list(space.shapes)
    moving = [s for s in shapes if s.body.body_type != pymunk.Body.STATIC]
    static = [s for s in shapes if s.body.body_type == pymunk.Body.STATIC
              and any(_can_hit(m, s, apart) for m in moving)]
    pool = static or shapes
    if not pool:
        return None
    low = -math.inf
    for s in pool:
        bb = s.cache_bb()
        for x in (bb.left, bb.right):
            for y in (bb.bottom, bb.top):
                low = max(low, x * down[0] + y * down[1])
    return low


def _networks(space: Any, dt: float) -> list[tuple[Finding, bool]]:
    """``spring-network``: a body held by two or more linear springs vibrates faster than any
    one of them alone (a row of equal masses: up to 2 sqrt(k/m) against sqrt(2 k/m)). Bound
    (Gershgorin, translations only): w^2 <= sum over its springs of k / m + k / sqrt(m m_other),
    the other end's term dropped when it cannot move. An upper bound, so it can flag a step
    that would still be stable; checked only for bodies with two or more springs."""
    import pymunk

    rows: list[tuple[Finding, bool]] = []
    bound: dict[int, list[Any]] = {}
    for c in space.constraints:
        if not isinstance(c, pymunk.DampedSpring) or c.stiffness <= 0:
            continue
        for here, there in ((c.a, c.b), (c.b, c.a)):
            inv_here, _ = _inverse_mass(here)
            if inv_here == 0.0:
                continue
            inv_there, _ = _inverse_mass(there)
            entry = bound.setdefault(id(here), [here, 0.0, 0])
            entry[1] += c.stiffness * (inv_here + math.sqrt(inv_here * inv_there))
            entry[2] += 1
    for body, w2, count in bound.values():
        if count < 2:
            continue
        w = math.sqrt(w2)
        dt_max = SPRING_LIMIT / w
        rows.append((Finding("spring-network", body_label(space, body), w * dt, SPRING_LIMIT,
                             f"{count} springs on it, w <= {w:.4g} rad/s: dt < {dt_max:.4g} s",
                             dt_max), w * dt < SPRING_LIMIT))
    return rows


def survey(space: Any, dt: float, speeds: str = "both") -> list[tuple[Finding, bool]]:
    """Every check at step ``dt`` (s) as (finding, ok) pairs, passed ones included.
    ``speeds``: 'state' (the present speeds), 'energy' or 'both' (the larger)."""
    space, dt, speeds = _check(space, dt, speeds)
    apart = _apart(space)
    return (_springs(space, dt) + _networks(space, dt) + _tunnelling(space, dt, speeds, apart)
            + _contact_settings(space, apart))


def _springs(space: Any, dt: float) -> list[tuple[Finding, bool]]:
    """Each spring's w*dt (linear and rotary) against the explicit step's limit."""
    import pymunk

    rows: list[tuple[Finding, bool]] = []
    for c in space.constraints:
        if not isinstance(c, pymunk.DampedSpring | pymunk.DampedRotarySpring):
            continue
        w = spring_omega(c)
        if w == 0.0:
            continue
        kind = "rotary-spring" if isinstance(c, pymunk.DampedRotarySpring) else "spring"
        dt_max = SPRING_LIMIT / w
        rows.append((Finding(kind, constraint_label(space, c), w * dt, SPRING_LIMIT,
                             f"w = {w:.4g} rad/s: dt < {dt_max:.4g} s", dt_max),
                     w * dt < SPRING_LIMIT))
    return rows


def _potential(space: Any, apart: set[tuple[int, int]]) -> float:
    """The energy (J) a body could turn into speed: the springs' energy plus each dynamic
    body's fall to the lowest level it can reach."""
    import pymunk

    e = energy(space)
    g = math.hypot(*space.gravity)
    down = (space.gravity[0] / g, space.gravity[1] / g) if g > 0 else (0.0, -1.0)
    level = _level(space, down, apart) if g > 0 else None
    potential = e.U_spring
    if level is not None:
        for b in space.bodies:
            if b.body_type != pymunk.Body.DYNAMIC:
                continue
            r = b.local_to_world(b.center_of_gravity)
            potential += b.mass * g * max(0.0, level - (r[0] * down[0] + r[1] * down[1]))
    return potential


def _closing_speeds(body: Any, own: list[Any], targets: list[Any],
                    potential: float) -> tuple[float, float]:
    """How fast (m/s) ``body``'s shapes ``own`` may close on the shapes ``targets``: from the
    present motion, and from all the energy ``potential`` (J) turned into its speed. The
    obstacles may move too (their present speed; a kinematic one keeps its speed whatever
    the energy)."""
    import pymunk

    reach = max(_reach(body, s) for s in own)
    moving = [_speed(s) for s in targets]
    driven = [_speed(s) for s in targets if s.body.body_type == pymunk.Body.KINEMATIC]
    v_state = body.velocity.length + abs(body.angular_velocity) * reach + max(moving)
    v_energy = (math.sqrt(body.velocity.length**2 + 2.0 * potential / body.mass)
                + max(driven, default=0.0))
    return v_state, v_energy


def _tunnelling(space: Any, dt: float, speeds: str,
                apart: set[tuple[int, int]]) -> list[tuple[Finding, bool]]:
    """Each dynamic body that can hit something: how far it may move in one step against
    half the thinnest shape it can hit plus half its own smallest one."""
    import pymunk

    shapes = list(space.shapes)
    sizes = [shape_size(s) for s in shapes]
    potential = _potential(space, apart)
    rows: list[tuple[Finding, bool]] = []
    for b in space.bodies:
        if b.body_type != pymunk.Body.DYNAMIC:
            continue
        own = [i for i, s in enumerate(shapes) if s.body is b]
        targets = [j for j, o in enumerate(shapes)
                   if any(_can_hit(shapes[i], o, apart) for i in own)]
        if not targets:
            continue
        thinnest = min(sizes[j] for j in targets)
        limit = 0.5 * thinnest + 0.5 * min(sizes[i] for i in own)
        v_state, v_energy = _closing_speeds(b, [shapes[i] for i in own],
                                            [shapes[j] for j in targets], potential)
        v = {"state": v_state, "energy": v_energy, "both": max(v_state, v_energy)}[speeds]
        if v == 0.0 or limit == 0.0:
            continue
        dt_max = limit / v
        source = "from energy" if (speeds == "energy" or
                                   (speeds == "both" and v_energy > v_state)) else "now"
        rows.append((Finding("tunnelling", body_label(space, b), v * dt, limit,
                             f"{v:.4g} m/s ({source}) moves {v * dt:.3g} m per step; "
                             f"dt < {dt_max:.4g} s", dt_max), v * dt < limit))
    return rows


def _contact_settings(space: Any, apart: set[tuple[int, int]]) -> list[tuple[Finding, bool]]:
    """The collision slop against the smallest shape, and the collision bias where elastic
    shapes can touch. Slop and bias act only where shapes can touch."""
    shapes = list(space.shapes)
    contacts = any(_can_hit(a, b, apart) for i, a in enumerate(shapes) for b in shapes[i + 1:])
    if not (shapes and contacts):
        return []
    rows: list[tuple[Finding, bool]] = []
    smallest = min(shape_size(s) for s in shapes)
    if smallest > 0:
        slop_limit = SLOP_FRACTION * smallest
        rows.append((Finding("slop", "space.collision_slop", space.collision_slop,
                             slop_limit, f"smallest shape {smallest:.3g}: set "
                             f"space.collision_slop = {SLOP_SUGGESTED * smallest:.3g}"),
                     space.collision_slop <= slop_limit))
    elastic = any(s.elasticity > 0 and o.elasticity > 0 for s in shapes for o in shapes
                  if _can_hit(s, o, apart))
    if elastic:
        bias = space.collision_bias
        rows.append((Finding("bias", "space.collision_bias", bias, 1.0,
                             "elastic contacts: set space.collision_bias = 1.0 (no "
                             "position correction, which adds energy) if energy matters"),
                     bias >= 1.0))
    return rows


def check(space: Any, dt: float, speeds: str = "both") -> list[Finding]:
    """The checks that fail at step ``dt`` (s): each a :class:`Finding` with its fix."""
    return [f for f, ok in survey(space, dt, speeds) if not ok]


def substeps(space: Any, dt: float, speeds: str = "both") -> int:
    """The fewest whole sub-steps of ``dt`` (s) that clear every finding a step can clear."""
    space, dt, speeds = _check(space, dt, speeds)
    limits = [f.dt_max for f in check(space, dt, speeds) if f.dt_max is not None]
    if not limits:
        return 1
    ratio = dt / min(limits)
    if not ratio < MAX_STEPS:
        raise UsageError(f"dt = {dt:g}: clearing the guard's findings would take more than "
                         f"{MAX_STEPS:,} sub-steps of it; take a smaller dt", param="dt")
    return math.floor(ratio) + 1


def suggest_dt(space: Any, dt: float, speeds: str = "both") -> float:
    """A step (s) that clears every finding a step can clear: ``dt`` divided into the fewest
    whole sub-steps (so frames at ``dt`` stay whole); ``dt`` itself when nothing fails."""
    space, dt, speeds = _check(space, dt, speeds)
    return dt / substeps(space, dt, speeds)


def report(space: Any, dt: float, speeds: str = "both") -> str:
    """The guard's report as text: every check with ok or its fix, and the suggestion."""
    space, dt, speeds = _check(space, dt, speeds)
    rows = survey(space, dt, speeds)
    lines = [f"step-size guard at dt = {dt:g} s:"]
    for f, ok in rows:
        mark = "ok  " if ok else "FAIL"
        lines.append(f"  {mark} {f.kind:13s} {f.subject:22s} {f.value:10.4g} (limit "
                     f"{f.limit:.4g}){'' if ok else '; ' + f.fix}")
    n = substeps(space, dt, speeds)
    if n > 1:
        lines.append(f"  suggested: {n} sub-steps of dt, dt = {dt / n:.4g} s")
    elif any(not ok for _, ok in rows):
        lines.append("  the step is fine; the failures are settings")
    else:
        lines.append("  nothing to fix")
    return "\n".join(lines)


def step(space: Any, dt: float, substeps: int = 1) -> None:
    """Advance ``space`` by ``dt`` (s) in ``substeps`` equal steps."""
    args.space(space)
    substeps = args.whole(substeps, "substeps", "sub-steps", hi=MAX_STEPS)
    h = args.real(dt, "dt", "s") / substeps
    for _ in range(substeps):
        space.step(h)


class Driver:
    """Steps a space at a fixed frame step ``dt`` (s) in whole sub-steps: ``substeps`` given,
    or None for the guard's suggestion at the start. ``t`` (s) counts whole frames, so it does
    not drift with rounding."""

    def __init__(self, space: Any, dt: float, substeps: int | None = None,
                 speeds: str = "both") -> None:
        self.space, self.dt, speeds = _check(space, dt, speeds)
        if substeps is None:
            substeps = globals()["substeps"](space, self.dt, speeds)
        self.substeps = args.whole(substeps, "substeps", "sub-steps", hi=MAX_STEPS)
        self.h = self.dt / substeps
        self.frames = 0

    @property
    def t(self) -> float:
        """Time stepped so far (s)."""
        return self.frames * self.dt

    def step(self, frames: int = 1) -> None:
        """Advance ``frames`` frames."""
        frames = args.whole(frames, "frames", "frames", lo=0, hi=MAX_STEPS // self.substeps)
        step_ = self.space.step
        h = self.h
        for _ in range(frames * self.substeps):
            step_(h)
        self.frames += frames
