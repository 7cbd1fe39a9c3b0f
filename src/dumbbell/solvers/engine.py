"""``pymunk``: the scene in the pymunk physics engine (Munk2D, a Chipmunk2D fork).

What gets built is only what the scene declares:

- one dynamic body per particle, carrying a ``Circle`` of the particle's radius; a rigid
  dumbbell (``[rigid]``) is instead ONE body carrying both circles, its centre of gravity at the
  centre of mass and its moment ``mu L^2`` (plus the circles' own ``1/2 m r^2`` when spin is on);
- ``[spring]``: a ``DampedSpring`` between the centres, damping 0, ``collide_bodies = False``;
- ``[floor]``: a static box whose top is at ``y = -r``, so that a circle of radius r touches it
  exactly when its centre is at height 0, where the point particle of the other solvers meets
  the floor (circles of different radii get one box each, filtered to their own circle). A box,
  not a ``Segment``: a circle-segment contact normal is computed from the closest point on the
  segment, which a long segment (needed: the dumbbell may travel far) rounds to about
  ``length * 1e-16``, so every bounce gave a spurious sideways kick (measured: 6e-13 m/s with a
  2e6 m segment). The box's top edge gives the normal (0, 1) exactly;
- ``[gravity]``: ``space.gravity = (0, -g)``.

1D scenes run on the vertical line x = 0 and return the 1D columns (xA, vA, xB, vB: vertical).

Settings (each overridable in a scene's ``[pymunk]`` table), chosen for SI units:

- ``collision_bias = 1.0``: no position correction. pymunk's default (0.0018, tuned for pixel
  units) pushes an overlapping circle out with an extra velocity, which adds energy each impact;
  with the correction off an elastic impact only reverses the normal velocity, as the
  textbook's flip does, and the circle leaves the floor on its own.
- ``collision_slop = 1e-4`` m: the overlap tolerated before the correction acts (only matters
  when ``collision_bias`` < 1). pymunk's default 0.1 is 10 cm, five radii of a particle.
- ``iterations = 10`` (pymunk's default): contact impulses converge in one pass for one contact
  per body; the spring is an explicit impulse that iterations do not touch.
- ``spin = false``: the circles get an infinite moment, so they are the point particles of the
  textbook (no K_spin). With ``spin = true`` each circle (or the rigid body) gets its disc
  moment and friction can make it spin; the state then holds ``omegaA``/``omegaB`` (rad/s).

Elasticity 1.0 is set on the circles and the scene's elasticity on the floor (pymunk multiplies
them); friction 1.0 on the circles and the scene's friction on the floor (also multiplied).

Only every ``every``-th step is read back from the engine (reading costs about as much as a
step); impacts come from collision callbacks, so the inner loop is a bare ``Space.step`` loop.
A circle that rests or rolls on the floor is not an impact: a touch that approaches slower than
``CONTACT_STEPS * g * dt`` resumes a contact, and touching that lasts is reported as a
:class:`~dumbbell.model.trajectory.Contact` (``Trajectory.contacts``; see :class:`_FloorLog`).
Verdicts: a non-finite or blown-up state is ``unstable``; a particle whose centre is more than
its radius below the floor and still moving down (pymunk finds contacts only once shapes
overlap, so a step that carries a circle deep into the floor box lets it through) is
``tunnelled``: the run stops there, keeping the samples up to it. Otherwise the energy verdict.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..model.energy import disc_inertia, partition_from_terms, spins, state_columns
from ..model.scene import Particle, Scene
from ..model.trajectory import Contact, Impact, Trajectory, Verdict
from .base import ExplicitSpring, RunOptions, Solver
from .verdicts import RawRun, Sinking, conclude, nonfinite_reason, tunnel_reason

#: No public names: the class is ``dumbbell.solvers.METHODS[name]``.
__all__: list[str] = []

NAME = "pymunk"

#: A position or velocity beyond this (m, m/s) counts as blown up.
_BIG = 1e12
#: Steps between progress-bar updates.
_CHUNK = 200_000
#: Half-width and thickness of the floor box (m): wider than anything a scene can reach.
_FLOOR_HALF_WIDTH = 1e6
FLOOR_THICKNESS = 1.0  # public: tests and the stability theory reason with it
_FLOOR_TYPE = 1
_PARTICLE_TYPE = {"A": 2, "B": 3}


def settings(scene: Scene) -> dict[str, Any]:
    """The engine settings used for ``scene``: the scene's ``[pymunk]`` values, else the
    defaults declared on :class:`~dumbbell.model.pymunk_settings.PymunkSettings`."""
    return scene.pymunk.resolved()


def supports(scene: Scene) -> str | None:
    """None: pymunk runs every scene (1D on the line x = 0, 2D, rigid, friction, spin)."""
    return None


@dataclass
class World:
    """A built pymunk space and handles to what the solver reads back.

    ``points`` maps particle name to (body, shape, offset of the circle from the body's centre
    of gravity in body coordinates, m)."""

    space: Any
    points: dict[str, tuple[Any, Any, tuple[float, float]]]
    spring: Any = None
    floors: list[Any] = field(default_factory=list)
    rigid_body: Any = None


def build(scene: Scene) -> World:
    """Build the pymunk space of ``scene`` (see the module docstring)."""
    from .._pymunk import require

    pymunk = require()
    cfg = settings(scene)
    space = pymunk.Space()
    space.gravity = (0.0, -scene.system.g)
    space.collision_slop = cfg["collision_slop"]
    space.collision_bias = cfg["collision_bias"]
    space.iterations = cfg["iterations"]
    world = World(space, {})
    if scene.system.rigid is not None:
        _add_rigid(scene, world)
    else:
        _add_particles(scene, world)
    if scene.system.floor is not None:
        _add_floors(scene, world)
    return world


def _circle(world: World, body: Any, p: Particle, offset: tuple[float, float]) -> Any:
    """The circle of particle ``p`` on ``body`` at ``offset`` (m), recorded in the world."""
    import pymunk

    shape = pymunk.Circle(body, p.radius, offset)
    shape.elasticity = 1.0
    shape.friction = 1.0
    shape.collision_type = _PARTICLE_TYPE[p.name]
    world.points[p.name] = (body, shape, offset)
    return shape


def _add_rigid(scene: Scene, world: World) -> None:
    """The rigid dumbbell: one body at the centre of mass carrying both circles."""
    import pymunk

    A, B = scene.system.A, scene.system.B
    M = scene.system.M
    R = ((A.mass * A.x + B.mass * B.x) / M, (A.mass * A.height + B.mass * B.height) / M)
    moment = scene.system.mu * scene.system.rigid.length**2
    if scene.system.discs:
        moment += disc_inertia(A.mass, A.radius) + disc_inertia(B.mass, B.radius)
    body = pymunk.Body(M, moment)
    body.position = R
    # One body: its velocity and spin follow from the particles' (consistent) velocities.
    V = ((A.mass * A.vx + B.mass * B.vx) / M, (A.mass * A.vy + B.mass * B.vy) / M)
    d = (A.x - B.x, A.height - B.height)
    w = (A.vx - B.vx, A.vy - B.vy)
    body.velocity = V
    body.angular_velocity = (d[0] * w[1] - d[1] * w[0]) / (d[0] ** 2 + d[1] ** 2)
    shapes = [_circle(world, body, p, (p.x - R[0], p.height - R[1])) for p in (A, B)]
    world.space.add(body, *shapes)
    world.rigid_body = body


def _add_particles(scene: Scene, world: World) -> None:
    """Two bodies, one circle each, joined by the spring if there is one."""
    import pymunk

    space = world.space
    for p in (scene.system.A, scene.system.B):
        moment = disc_inertia(p.mass, p.radius) if scene.system.discs else math.inf
        body = pymunk.Body(p.mass, moment)
        body.position = (p.x, p.height)
        body.velocity = (p.vx, p.vy)
        if scene.system.discs:
            body.angular_velocity = p.spin
        space.add(body, _circle(world, body, p, (0.0, 0.0)))
    if scene.system.spring is not None:
        bA, bB = world.points["A"][0], world.points["B"][0]
        rest, stiffness = scene.system.spring.rest_length, scene.system.spring.stiffness
        spring = pymunk.DampedSpring(bA, bB, (0.0, 0.0), (0.0, 0.0), rest, stiffness, 0.0)
        spring.collide_bodies = False
        space.add(spring)
        world.spring = spring


def _add_floors(scene: Scene, world: World) -> None:
    """One static floor box per distinct circle radius, its top where such a circle's
    centre is at height 0."""
    import pymunk

    A, B = scene.system.A, scene.system.B
    radii = sorted({A.radius, B.radius})
    for bit, r in enumerate(radii):
        W, T = _FLOOR_HALF_WIDTH, FLOOR_THICKNESS
        box = pymunk.Poly(world.space.static_body,
                          [(-W, -r - T), (W, -r - T), (W, -r), (-W, -r)])
        box.elasticity = scene.system.floor.elasticity
        box.friction = scene.system.floor.friction
        box.collision_type = _FLOOR_TYPE
        if len(radii) > 1:
            # Each particle meets only the box placed for its own radius.
            box.filter = pymunk.ShapeFilter(categories=1 << bit, mask=1 << bit)
            for p in (A, B):
                if p.radius == r:
                    shape = world.points[p.name][1]
                    shape.filter = pymunk.ShapeFilter(categories=1 << bit, mask=1 << bit)
        world.space.add(box)
        world.floors.append(box)


def _reader(scene: Scene, world: World) -> Any:
    """A function returning the state row (state_columns order, then spins) of the world."""
    (bA, _sA, _), (bB, _sB, _) = world.points["A"], world.points["B"]
    spin = spins(scene)
    if world.rigid_body is not None:
        body = world.rigid_body
        offA, offB = world.points["A"][2], world.points["B"][2]

        def read2() -> tuple[float, ...]:
            pA = body.local_to_world(offA)
            pB = body.local_to_world(offB)
            vA = body.velocity_at_world_point(pA)
            vB = body.velocity_at_world_point(pB)
            w = body.angular_velocity
            return (pA[0], pA[1], vA[0], vA[1], pB[0], pB[1], vB[0], vB[1], w)
        return read2
    if scene.system.dimensions == 1:
        def read1() -> tuple[float, ...]:
            return (bA.position[1], bA.velocity[1], bB.position[1], bB.velocity[1])
        return read1
    if spin:
        def read_spin() -> tuple[float, ...]:
            pA, vA, pB, vB = bA.position, bA.velocity, bB.position, bB.velocity
            return (pA[0], pA[1], vA[0], vA[1], pB[0], pB[1], vB[0], vB[1],
                    bA.angular_velocity, bB.angular_velocity)
        return read_spin

    def read() -> tuple[float, ...]:
        pA, vA, pB, vB = bA.position, bA.velocity, bB.position, bB.velocity
        return (pA[0], pA[1], vA[0], vA[1], pB[0], pB[1], vB[0], vB[1])
    return read


def _extra_columns(scene: Scene, world: World) -> list[str]:
    if world.rigid_body is not None:
        return ["omega"]
    return ["omegaA", "omegaB"] if spins(scene) else []


def _vertical_velocity(body: Any, shape: Any) -> float:
    return float(body.velocity_at_world_point(body.local_to_world(shape.offset))[1])


def _energy(
    scene: Scene, world: World, t: np.ndarray, state: dict[str, np.ndarray],
    events: list[Impact],
) -> dict[str, np.ndarray]:
    """The energy columns (J) from the general accounting of pymunk's own bodies, springs and
    gravity (:mod:`dumbbell.spaces.accounting`), evaluated over all samples at once."""
    from ..spaces._evaluation import State, evaluate
    from ..spaces._what_counts import inventory

    inv = inventory(world.space)
    n = len(t)
    zero = np.zeros(n)
    if world.rigid_body is not None:
        mA, mB, M = scene.system.A.mass, scene.system.B.mass, scene.system.M
        cols = [[(mA * state[f"{c}A"] + mB * state[f"{c}B"]) / M]
                for c in ("x", "y", "vx", "vy")]
        omega = [state["omega"]]
    else:
        if scene.system.dimensions == 1:
            cols = [[zero, zero], [state["xA"], state["xB"]], [zero, zero],
                    [state["vA"], state["vB"]]]
        else:
            cols = [[state[f"{c}A"], state[f"{c}B"]] for c in ("x", "y", "vx", "vy")]
        omega = ([state["omegaA"], state["omegaB"]] if spins(scene)
                 else [zero, zero])
    # Tracked bodies beyond the dynamic ones (a floor's static body) never move.
    extra = len(inv.bodies) - len(omega)
    pad = [zero] * extra
    st = State(*(np.column_stack(c + pad) for c in (*cols, [zero] * len(omega), omega)))
    return partition_from_terms(scene, t, state, events, evaluate(inv, st))


#: A touch of the floor that approaches slower than what gravity builds in this many steps
#: (``CONTACT_STEPS * g * dt``) is contact, not an impact; touching for this many steps or
#: more is a lasting contact. Why ten: docs/solvers.md, "Impacts and contacts".
CONTACT_STEPS = 10


class _FloorLog:
    """The circles' floor contacts as they happen, told apart into impacts and lasting contacts.

    Each time a circle begins to touch the floor (a new pymunk arbiter), its approach speed is
    its downward velocity then. Faster than ``v_th = CONTACT_STEPS * g * dt`` (m/s): an
    :class:`Impact` at the end of the step ``step()`` (index; step ``dt`` in s) in which it
    began, with the vertical velocity before and after the contact's impulses. Slower: a circle
    that rests or rolls on the floor and lost the contact for a step or two (the engine only
    keeps an arbiter while the shapes overlap), so the touch resumes the touching before it.
    A run of touching that lasts ``CONTACT_STEPS`` steps or more is a :class:`Contact`.
    :meth:`notes` counts the slow touches and gives the fastest, so that a run shows how far
    below the threshold its contacts stayed."""

    def __init__(self, world: World, dt: float, g: float, step: Callable[[], int]) -> None:
        self.dt, self.step = dt, step
        self.v_th = CONTACT_STEPS * g * dt
        self.events: list[Impact] = []
        self._pending: dict[str, list[float]] = {}
        self._since: dict[str, int] = {}              # body -> step its touching began
        self._left: dict[str, tuple[int, int]] = {}   # body -> (began, left) of its last
        self._runs: list[tuple[str, int, int]] = []   # finished runs: body, began, left
        self.slow, self.fastest_slow = 0, 0.0         # touches slower than v_th; the fastest
        for name in "AB":
            world.space.on_collision(_PARTICLE_TYPE[name], _FLOOR_TYPE, begin=self._begin,
                                     post_solve=self._post_solve, separate=self._separate)

    @staticmethod
    def _name(arbiter: Any) -> str:
        return "A" if arbiter.shapes[0].collision_type == _PARTICLE_TYPE["A"] else "B"

    def _begin(self, arbiter: Any, _space: Any, _data: Any) -> None:
        shape, name, i = arbiter.shapes[0], self._name(arbiter), self.step()
        v = _vertical_velocity(shape.body, shape)
        impact = -v > self.v_th
        if not impact:
            self.slow += 1
            self.fastest_slow = max(self.fastest_slow, -v)
        last = self._left.pop(name, None)
        if last is not None and not impact:
            self._since[name] = last[0]               # the same contact, resumed
            return
        if last is not None:
            self._runs.append((name, *last))
        self._since[name] = i
        if impact:
            self._pending[name] = [(i + 1) * self.dt, v]

    def _post_solve(self, arbiter: Any, _space: Any, _data: Any) -> None:
        name = self._name(arbiter)
        hit = self._pending.pop(name, None)
        if hit is not None:
            shape = arbiter.shapes[0]
            self.events.append(Impact(hit[0], name, hit[1], _vertical_velocity(shape.body, shape)))

    def _separate(self, arbiter: Any, _space: Any, _data: Any) -> None:
        name, i = self._name(arbiter), self.step()
        self._left[name] = (self._since.pop(name, i), i)

    def notes(self) -> dict[str, float]:
        """For the trajectory's ``info``: the threshold ``impact_threshold`` (m/s), how many
        touches were slower (``contact_touches``) and the fastest of them (m/s,
        ``contact_approach_max``; 0 without any)."""
        return {"impact_threshold": self.v_th, "contact_touches": self.slow,
                "contact_approach_max": self.fastest_slow}

    def contacts(self, t_end: float) -> tuple[Contact, ...]:
        """The lasting contacts up to ``t_end`` (s, the run's last sample): runs of touching of
        ``CONTACT_STEPS`` steps or more, one still touching at the end lasting until then."""
        end = t_end / self.dt
        runs = [*self._runs, *((n, *run) for n, run in self._left.items()),
                *((n, began, end) for n, began in self._since.items())]
        out = [Contact((a + 1) * self.dt, min(t_end, (b + 1) * self.dt), name)
               for name, a, b in runs if b - a >= CONTACT_STEPS and (a + 1) * self.dt <= t_end]
        return tuple(sorted(out, key=lambda c: (c.t_start, c.body)))


@dataclass(frozen=True)
class _Watch:
    """What ends a pymunk run at a sample: a state beyond :data:`_BIG` (``unstable``), or a
    circle more than its radius below the floor and moving down (``tunnelled``).
    ``columns`` maps each particle to its (height, vertical velocity) columns of a row."""

    scene: Scene
    floors: bool
    columns: dict[str, tuple[int, int]]
    radius: dict[str, float]

    @classmethod
    def of(cls, scene: Scene, world: World, names: list[str]) -> _Watch:
        """The watch of ``world``, whose rows have the columns ``names``."""
        one = scene.system.dimensions == 1
        columns = {name: (names.index(f"{'x' if one else 'y'}{name}"),
                          names.index(f"{'v' if one else 'vy'}{name}")) for name in "AB"}
        radius = {"A": scene.system.A.radius, "B": scene.system.B.radius}
        return cls(scene, bool(world.floors), columns, radius)

    def verdict(self, row: tuple[float, ...], t: float, dt: float) -> Verdict | None:
        """The verdict of the sample ``row`` at ``t`` (s) of a run at step ``dt`` (s), or
        None when the run goes on."""
        # abs(v) < _BIG for every v (False for a NaN), the loop in C: this runs per sample.
        if not all(map(_BIG.__gt__, map(abs, row))):
            return Verdict("unstable", t, nonfinite_reason(self.scene, dt, Pymunk.step_limit))
        if not self.floors:
            return None
        for name in "AB":
            y, vy = row[self.columns[name][0]], row[self.columns[name][1]]
            if y < -self.radius[name] and vy < 0:
                return Verdict("tunnelled", t, tunnel_reason(self.scene, Sinking(
                    name, y, vy, depth=self.radius[name] + FLOOR_THICKNESS / 2), dt))
        return None


def _state(scene: Scene, world: World, names: list[str], out: np.ndarray,
           heat: np.ndarray) -> dict[str, np.ndarray]:
    """The state columns of the samples kept (rows of ``out``, columns ``names``), the
    contacts' heat (J), and for a spinning rigid body each circle's spin (the body's)."""
    state = {name: out[:, c].copy() for c, name in enumerate(names[: out.shape[1]])}
    state["heat"] = heat
    if world.rigid_body is not None and spins(scene):
        state["omegaA"] = state["omegaB"] = state["omega"]
    return state


def solve(scene: Scene, options: RunOptions) -> Trajectory:
    """Run ``scene`` in pymunk at step ``options.dt`` (s). See the module docstring."""
    from ..progress import bar

    world = build(scene)
    space = world.space
    dt, every, n = options.dt, options.every, options.n_steps
    read = _reader(scene, world)
    names = state_columns(scene) + _extra_columns(scene, world)
    out = np.empty((options.n_samples, len(names)))
    out[0] = read()

    # Heat of the contacts, from their impulses step by step (friction included).
    from ..spaces.heat import HeatCounter

    i = 0  # step index; the floor log reads it (a closure cell), so the loop pays nothing
    log = _FloorLog(world, dt, scene.system.g, lambda: i) if world.floors else None
    counter = HeatCounter._on(space)  # after the log: every handler is made by now
    heat = np.zeros(options.n_samples)
    watch = _Watch.of(scene, world, names)
    step = space.step
    verdict: Verdict | None = None
    j = 0
    samples_per_chunk = max(1, _CHUNK // every)
    t0 = time.perf_counter()
    with bar(n, f"{NAME} {scene.name}", "step", quiet=options.quiet or n < 5 * _CHUNK) as pb:
        while j < options.n_samples - 1 and verdict is None:
            j_stop = min(options.n_samples - 1, j + samples_per_chunk)
            while j < j_stop:
                for i in range(j * every, (j + 1) * every):
                    step(dt)
                j += 1
                row = read()
                out[j] = row
                heat[j] = counter.total
                verdict = watch.verdict(row, j * every * dt, dt)
                if verdict is not None:
                    if verdict.status == "unstable":
                        j -= 1  # keep only finite samples
                    break
            pb.update(min(j * every, n) - pb.n)
        if verdict is None:
            for i in range(j * every, n):
                step(dt)
    wall = time.perf_counter() - t0

    kept = j + 1
    state = _state(scene, world, names, out[:kept], heat[:kept])
    cfg = settings(scene)
    info = {"steps": min(n, kept * every) if verdict else n, **cfg}
    if world.rigid_body is not None:
        info["moment"] = world.rigid_body.moment
    if log is not None:
        info.update(log.notes())
    t = options.sample_times(kept)
    events = [e for e in log.events if verdict is None or e.t <= verdict.t] if log else []
    traj = conclude(Pymunk, scene, options, RawRun(
        t, state, events, verdict or Verdict(), wall, info,
        energy=_energy(scene, world, t, state, events)))
    contacts = log.contacts(float(traj.t[-1])) if log and len(traj.t) else ()
    return dataclasses.replace(traj, contacts=contacts) if contacts else traj


class Pymunk(ExplicitSpring, Solver):
    """The pymunk (Chipmunk) engine (see the module docstring)."""

    name = NAME
    order = 1
    has_step = True
    flip_floor = False
    relative_cost = 30.0
    is_truth = False
    estimates_error = False
    _supports = staticmethod(supports)
    _solve = staticmethod(solve)

    @staticmethod
    def _catch_depth(scene: Scene) -> float:
        """How far (m) a circle may travel in one step and still be caught by the floor: the
        floor box's thickness plus the smaller circle's diameter."""
        return 2.0 * min(scene.system.A.radius, scene.system.B.radius) + FLOOR_THICKNESS
