"""The step guard's probe: how much energy each constraint of a space puts in or takes out per
second at a step, measured on a copy.

pymunk's rigid joints hold their bodies by impulses that also correct the drift of the joint
(``error_bias``, ``max_bias``), and that correction, with the step's own error, moves energy:
a pendulum on a ``PinJoint`` loses about 1 % of m g L a second at 1/60 s in pixel units, ten
times less at 1/600 s. No closed form covers a joint in an arbitrary space, so the guard
measures it:

- **the copy**: a new space built from pymunk's public attributes of the user's one (bodies,
  shapes, constraints and their settings, the space's settings, the forces set now), so that
  nothing in the user's space changes and no callback of the program runs (collision
  handlers and a constraint's ``pre_solve``/``post_solve`` are not copied; a custom
  ``velocity_func``, spring force or torque is, being part of the physics);
- **the run** (on a space of at most :data:`MAX_BODIES` bodies): :data:`PROBE_TIME` seconds
  of steps of ``dt`` (fewer when the space is big:
  at most :data:`MAX_STEPS` steps, and steps times the work of one step at most
  :data:`MAX_WORK`, a step's work being its bodies, its impulse components and
  :data:`PART_COST` for each part solved), the forces set now kept on every step, as a
  program that sets them each frame; no body falls asleep on the copy;
- **each constraint's impulse**, recovered every step from the momentum its bodies gained:
  a body's gain in the step, less the kick of its ``velocity_func`` (gravity, damping, its
  forces: read by wrapping that function on the copy) and the impulses of its contacts
  (``Arbiter.total_impulse``, less what a contact touching again carried in and pymunk did
  not apply; and its torque where the contact has one point, at that point on the body's
  own shape), is the sum of
  the impulses of its constraints. Each constraint's impulse has a known form (along the
  axis of a pin, slide or spring; any direction at a pivot or groove; a torque for the
  rotary kinds, a gear's scaled by its ratio on its first body), so the gains of all bodies
  are a linear system in the impulses, solved by least squares. Each impulse found is
  checked against the magnitude pymunk reports (``Constraint.impulse``); a constraint whose
  impulse the system does not determine (two joints acting on the same motion, a body whose
  contacts have two points and so an unknown torque) or whose impulse does not match is
  *not separated*, and named so;
- **the work**: each step, the impulse times the mean, over the step, of the relative
  velocity it acts on (the velocities before and after the step; a static end at rest, a
  kinematic end at its velocity): what :class:`~dumbbell.spaces.Ledger` books as the
  constraint's term, here from public attributes only.

The energy scale is the ledger's: the largest kinetic energy and change of the potentials
(gravity, springs) over the probe.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..model.energy import spring_potential
from ._copy import MAKERS, Copy, Uncopyable
from ._layout import body_function
from ._probe_parts import _End, _on_groove, _Part, _replace_end, _solved, _springs
from ._scan import batch

#: Simulated time the probe covers (s), when the budget allows.
PROBE_TIME = 2.0
#: Most steps of a probe, and most work: steps times (bodies of the space plus impulse
#: components solved for); most bodies a probe copies.
MAX_STEPS = 1200
MAX_WORK = 100_000
MAX_BODIES = 2_000
#: Fewest steps a probe is worth: past the budget with fewer, it is not run.
MIN_STEPS = 20
#: What solving for one part of the constraints costs a step, in bodies stepped (about).
PART_COST = 20
#: Most impulse components the probe solves for together (constraints tied by their bodies).
MAX_UNKNOWNS = 120
#: Relative agreement asked of a recovered impulse with pymunk's own magnitude.
AGREE = 1e-6
#: Impulses under this fraction of the probe's largest momentum are all alike: at rest.
AT_REST = 1e-9

#: Constraint kinds whose impulse is a torque, and the springs (the guard's own rows).
ROTARY = ("DampedRotarySpring", "RotaryLimitJoint", "RatchetJoint", "GearJoint", "SimpleMotor")
SPRINGS = ("DampedSpring", "DampedRotarySpring")


@dataclass(frozen=True)
class Drift:
    """One constraint over the probe: ``work`` (energy units) it put into the bodies (None
    when it could not be separated), and ``why`` not."""

    label: str
    work: float | None
    why: str = ""


@dataclass
class Probe:
    """What the probe measured: ``steps`` of ``dt`` (s), ``seconds`` of simulated time,
    ``cost`` (s of wall-clock time it took), the energy ``scale``, each constraint's
    :class:`Drift` (by its place in ``space.constraints``), or ``problem``: why no probe
    was run (the constraints are then not checked)."""

    dt: float
    steps: int = 0
    cost: float = 0.0
    scale: float = 0.0
    drifts: dict[int, Drift] = field(default_factory=dict)
    problem: str = ""

    @property
    def seconds(self) -> float:
        return self.steps * self.dt


def probe(space: Any, dt: float, wanted: list[int], steps: int | None = None) -> Probe:
    """Run the probe on a copy of ``space`` at steps of ``dt`` (s) for the constraints at
    places ``wanted`` of ``space.constraints`` (see the module docstring): over
    :data:`PROBE_TIME` within the budget, or ``steps`` steps when given (to cover the time
    another probe covered)."""
    started = time.perf_counter()
    result = Probe(dt)
    bodies = len(space.bodies)
    if bodies > MAX_BODIES:
        result.problem = (f"the space has {bodies:,} bodies, more than the probe copies "
                          f"({MAX_BODIES:,})")
        return result
    try:
        copy = Copy(space)
    except Uncopyable as e:
        result.problem = f"the probe cannot copy the space: {e}"
        return result
    run = _Run(copy, dt, wanted)
    work = len(copy.space.bodies) + run.unknowns() + PART_COST * len(run.parts)
    if steps is None:
        steps = min(math.ceil(PROBE_TIME / dt - 1e-9), MAX_STEPS, MAX_WORK // max(1, work))
    if steps < MIN_STEPS:
        n = len(copy.space.bodies)
        k = run.unknowns()
        result.problem = (f"{n:,} bod{'y' if n == 1 else 'ies'} to step and {k:,} impulse "
                          f"component{'' if k == 1 else 's'} to solve for: fewer than "
                          f"{MIN_STEPS} steps fit in the probe's budget")
        return result
    for _ in range(steps):
        if not run.step():
            break
    result.steps = run.steps
    result.scale = run.scale()
    result.drifts = run.drifts()
    result.problem = run.problem
    result.cost = time.perf_counter() - started
    return result


# --- the run ---------------------------------------------------------------------------------

#: The batch fields the run reads each step (x, y, angle, vx, vy, w per body).
_FIELDS = ("POSITION", "ANGLE", "VELOCITY", "ANGULAR_VELOCITY")


class _Run:
    """The copy stepped, each constraint's impulse recovered and its work summed."""

    def __init__(self, copy: Copy, dt: float, wanted: list[int]) -> None:
        import pymunk

        self.copy, self.dt, self.wanted = copy, dt, wanted
        self.space = space = copy.space
        space.sleep_time_threshold = math.inf     # every body stays in pymunk's batch rows
        self.problem = ""
        self.steps = 0
        cons = copy.constraints
        self.kinds = [next(k for k in MAKERS if isinstance(c, getattr(pymunk, k)))
                      for c in cons]
        self.width = [1 if k in ROTARY or k in ("PinJoint", "SlideJoint", "DampedSpring")
                      else 2 for k in self.kinds]
        ids, rows = batch(space, _FIELDS)
        self.ids = ids.copy()
        slot = {int(k): j for j, k in enumerate(ids)}
        by_slot: list[Any] = [space.static_body] * len(ids)   # what is not in space.bodies
        for b in space.bodies:
            by_slot[slot[int(b.id)]] = b
        dynamic = np.array([b.body_type == pymunk.Body.DYNAMIC for b in by_slot], dtype=bool)
        self.mass = np.array([b.mass if d else 0.0 for b, d in zip(by_slot, dynamic,
                                                                   strict=True)])
        self.moment = np.array([b.moment if d else 0.0 for b, d in zip(by_slot, dynamic,
                                                                       strict=True)])
        self.cog = np.array([tuple(b.center_of_gravity) for b in by_slot]).reshape(-1, 2)
        self.dynamic = dynamic
        self.static = space.static_body
        self.work = np.zeros(len(cons))
        self.unsure: dict[int, str] = {}
        self.peak = 0.0  # the largest momentum of a body so far
        self.parts = self._parts(cons, slot, by_slot, pymunk)
        self.kicks: dict[int, tuple[float, float, float]] = {}
        # Each contact's last step, and its impulse along and across its normal then.
        self.contacts: dict[tuple[int, int], tuple[int, float, float]] = {}
        for i, body in enumerate(self.row_bodies):
            self._wrap(body, i)
        moments = self.moment[self.rows] if len(self.rows) else np.zeros(0)
        self.turns = np.where(np.isfinite(moments), moments, 0.0)
        self.springs = _springs(copy.constraints, slot, pymunk)
        self.start = rows.copy()
        self.energy0 = self._energies(rows)
        self.biggest = [0.0, 0.0, 0.0]  # kinetic, gravity's change, the springs' change

    def _parts(self, cons: list[Any], slot: dict[int, int], by_slot: list[Any],
               pymunk: Any) -> list[_Part]:
        """The constraints in parts tied together through dynamic bodies, those with a
        wanted constraint kept; the ends of every constraint (``ends``) and the rows'
        bodies (``rows``: their batch rows, ``row_bodies``, ``row_ends``)."""
        tied, root = self._tie(cons, slot, pymunk)
        groups: dict[int, list[int]] = {}
        for k, j in enumerate(tied):
            if j is None:
                if k in self.wanted:
                    self.unsure[k] = "it joins no dynamic body: there is no motion to measure"
                continue
            groups.setdefault(root(j), []).append(k)
        wanted = set(self.wanted)
        self.row_slots: list[int] = []
        row_of: dict[int, int] = {}
        parts = []
        for members in groups.values():
            if wanted & set(members):
                part = self._part(members, wanted, row_of)
                if part is not None:
                    parts.append(part)
        self.rows = np.array(self.row_slots, dtype=int)
        self.row_bodies = [by_slot[j] for j in self.row_slots]
        self.row_ends = [_End(j, i, False, (0.0, 0.0), tuple(self.cog[j]))
                         for i, j in enumerate(self.row_slots)]
        return parts

    def _tie(self, cons: list[Any], slot: dict[int, int], pymunk: Any
             ) -> tuple[list[int | None], Any]:
        """The ends of every constraint (``ends``), a dynamic body each is tied to (None: it
        joins none), and the function that names the group of such a body (constraints
        joined through dynamic bodies are one group)."""
        parent: dict[int, int] = {}

        def root(j: int) -> int:
            while parent.setdefault(j, j) != j:
                parent[j] = parent[parent[j]]
                j = parent[j]
            return j

        self.ends: list[tuple[_End, _End]] = []
        tied: list[int | None] = []
        for c, kind in zip(cons, self.kinds, strict=True):
            pair, moving = [], []
            for body, which in ((c.a, "a"), (c.b, "b")):
                j = slot.get(int(body.id), -1)
                if j >= 0 and self.dynamic[j]:
                    moving.append(j)
                anchor = (0.0, 0.0) if kind in ROTARY or (kind == "GrooveJoint"
                                                          and which == "a") \
                    else tuple(getattr(c, f"anchor_{which}"))
                pair.append(_End(j, -1, body.body_type == pymunk.Body.KINEMATIC, anchor,
                                 tuple(body.center_of_gravity), body))
            if len(moving) == 2:
                parent[root(moving[0])] = root(moving[1])
            tied.append(moving[0] if moving else None)
            self.ends.append((pair[0], pair[1]))
        return tied, root

    def _part(self, members: list[int], wanted: set[int], row_of: dict[int, int]
              ) -> _Part | None:
        """The part of the constraints ``members`` (one group, some wanted), its bodies given
        rows (``row_of``, ``row_slots``); None, with the wanted ones unsure, when it has more
        unknowns than the probe solves together."""
        first = [0]
        for k in members:
            first.append(first[-1] + self.width[k])
        if first[-1] > MAX_UNKNOWNS:
            for k in wanted & set(members):
                self.unsure[k] = (f"it is tied to {len(members)} constraints through the "
                                  f"bodies they join, more than the probe solves together "
                                  f"({MAX_UNKNOWNS} impulse components)")
            return None
        rows = []
        for k in members:
            for e, end in enumerate(self.ends[k]):
                if end.slot >= 0 and self.dynamic[end.slot]:
                    if end.slot not in row_of:
                        row_of[end.slot] = len(self.row_slots)
                        self.row_slots.append(end.slot)
                    self.ends[k] = _replace_end(self.ends[k], e, row_of[end.slot])
                    if row_of[end.slot] not in rows:
                        rows.append(row_of[end.slot])
        return _Part(members, first, rows)

    def _wrap(self, body: Any, i: int) -> None:
        """Record the kick ``body``'s velocity update gives it each step."""
        import pymunk

        inner = body_function(body, "velocity_func") or pymunk.Body.update_velocity
        kicks = self.kicks

        def recorded(b: Any, gravity: Any, damping: float, dt: float) -> None:
            v0, w0 = b.velocity, b.angular_velocity
            inner(b, gravity, damping, dt)
            v1 = b.velocity
            kicks[i] = (v1.x - v0.x, v1.y - v0.y, b.angular_velocity - w0)

        body.velocity_func = recorded

    def step(self) -> bool:
        """One step of the copy; False once its state is not finite (the probe stops)."""
        for body, force, torque in self.copy.pushes:
            body.force, body.torque = force, torque
        self.kicks.clear()
        self.space.step(self.dt)
        self.steps += 1
        ids, rows = batch(self.space, _FIELDS)
        if not np.isfinite(rows).all():
            self.problem = (f"the copy's state stopped being finite at step {self.steps} of "
                            "the probe")
            return False
        if len(ids) != len(self.ids) or not np.array_equal(ids, self.ids):
            order = np.argsort(ids)
            rows = rows[order[np.searchsorted(ids[order], self.ids)]]
        self._account(self.start, rows)
        kinetic, gravity, springs = self._energies(rows)
        big = self.biggest
        big[0] = max(big[0], kinetic)
        big[1] = max(big[1], abs(gravity - self.energy0[1]))
        big[2] = max(big[2], abs(springs - self.energy0[2]))
        self.start = rows.copy()
        return True

    def _account(self, before: np.ndarray, after: np.ndarray) -> None:
        """Recover the step's impulse of every constraint from the rows' bodies' momentum
        gains and add up each one's work (see the module docstring)."""
        rows = self.rows
        n = len(rows)
        kick = np.zeros((n, 3))
        for i, k in self.kicks.items():
            kick[i] = k
        gain = after[rows, 3:6] - before[rows, 3:6] - kick
        rhs = np.empty((n, 3))
        rhs[:, :2] = self.mass[rows, None] * gain[:, :2]
        rhs[:, 2] = self.turns * np.where(self.turns > 0, gain[:, 2], 0.0)
        use = np.ones((n, 3), dtype=bool)
        use[:, 2] = self.turns > 0                 # a body that cannot turn: no spin equation
        pose = [after[:, 0].tolist(), after[:, 1].tolist(), np.cos(after[:, 2]).tolist(),
                np.sin(after[:, 2]).tolist()]
        for i, b in enumerate(self.row_bodies):
            found = _arbiters(b)
            if not found:
                continue
            cx, cy, _, _ = self._world(self.row_ends[i], self.row_ends[i].cog, pose)
            for arb in found:
                # total_impulse is what the arbiter's first shape's body got; the contact
                # point of each body is on its own shape.
                mine = arb.shapes[0].body is b
                imp = arb.total_impulse if mine else -arb.total_impulse
                key = (id(arb.shapes[0]), id(arb.shapes[1])) if mine else \
                    (id(arb.shapes[1]), id(arb.shapes[0]))
                n = arb.normal if mine else -arb.normal
                carried = self.contacts.get(key)
                self.contacts[key] = (self.steps, imp.dot(n), imp.cross(n))
                if (arb.is_first_contact and carried is not None
                        and self.steps - carried[0] <= self.space.collision_persistence):
                    # A contact that touches again within the persistence keeps what it had
                    # accumulated (along its normal and across it), which pymunk does not
                    # apply on a first contact.
                    imp = imp - n * carried[1] + n.perpendicular() * carried[2]
                rhs[i, 0] -= imp.x
                rhs[i, 1] -= imp.y
                points = arb.contact_point_set.points
                if len(points) == 1:
                    p = points[0].point_a if mine else points[0].point_b
                    rhs[i, 2] -= (p.x - cx) * imp.y - (p.y - cy) * imp.x
                elif points:
                    use[i, 2] = False       # two contact points: their torque is not known
        mean = (0.5 * (before[:, 3:6] + after[:, 3:6])).tolist()   # per batch row
        moving = after[:, 3:6].tolist()
        self.momentum = (self.mass[rows] * np.hypot(after[rows, 3], after[rows, 4])
                         + self.turns * np.abs(after[rows, 5]))
        self.peak = max(self.peak, float(self.momentum.max(initial=0.0)))
        for part in self.parts:
            if not all(k in self.unsure for k in part.cons):
                self._solve(part, rhs, use, (pose, mean, moving))

    def _columns_of(self, part: _Part, pose: list[list[float]], mean: list[list[float]],
                    moving: list[list[float]]
                    ) -> tuple[np.ndarray, list[float], list[int], set[int]]:
        """The part's matrix (a column per impulse component, three rows per body), the mean
        relative velocity each component acts on, the components pymunk sets to 0 this step
        and the constraints that apply nothing whatever they report."""
        cons = self.copy.constraints
        m = part.first[-1]
        local = {r: i for i, r in enumerate(part.rows)}
        velocity = [0.0] * m          # the mean relative velocity each component acts on
        where_r: list[int] = []
        where_c: list[int] = []
        value: list[float] = []
        idle: list[int] = []          # components pymunk sets to 0 this step
        silent: set[int] = set()      # constraints that apply nothing whatever they report
        for at, k in enumerate(part.cons):
            columns, rest = self._columns(cons[k], self.kinds[k], self.ends[k], pose)
            if not any(any(v) for pair in columns for v in pair):
                silent.add(k)
            first = part.first[at]
            idle += [first + r for r in rest]
            for col, ends in enumerate(columns, start=first):
                for end, vec in zip(self.ends[k], ends, strict=True):
                    if end.row >= 0:
                        i = local[end.row]
                        where_r += [3 * i, 3 * i + 1, 3 * i + 2]
                        where_c += [col, col, col]
                        value += vec
                        u = mean[end.slot]
                    elif end.kinematic:
                        u = (moving[end.slot] if end.slot >= 0 else
                             [*end.body.velocity, end.body.angular_velocity])
                    else:
                        continue
                    velocity[col] += vec[0] * u[0] + vec[1] * u[1] + vec[2] * u[2]
        mat = np.zeros((3 * len(part.rows), m))
        mat[where_r, where_c] = value          # each (row, column) once: a body per end
        return mat, velocity, idle, silent

    def _solve(self, part: _Part, rhs: np.ndarray, use: np.ndarray,
               motion: tuple[list[list[float]], list[list[float]], list[list[float]]]) -> None:
        """Recover the impulses of one part's constraints and add up their work (``motion``:
        the bodies' pose, mean velocity and moving velocity over the step)."""
        cons = self.copy.constraints
        m = part.first[-1]
        mat, velocity, idle, silent = self._columns_of(part, *motion)
        keep = use[part.rows].reshape(-1)
        a_mat, values = mat[keep], rhs[part.rows].reshape(-1)[keep]
        if idle:
            a_mat = np.vstack([a_mat, np.eye(m)[idle]])
            values = np.concatenate([values, np.zeros(len(idle))])
        solution = _solved(a_mat, values)
        if solution is None:                  # not of full rank: least squares, and why
            solution, _, _, _ = np.linalg.lstsq(a_mat, values, rcond=None)
            if not all(k in self.unsure for k in part.cons):
                self._underdetermined(a_mat, part)
        # The size of the part's impulses: what it moved and the momentum of its bodies,
        # and at least a rounding of the largest momentum of the probe (a ball at rest on
        # its friction joints holds impulses of 1e-17 that two roundings tell apart: they
        # do no work the drift could show).
        rows = part.rows
        scale = max(float(np.abs(values).max(initial=0.0)), self.momentum[rows].max(),
                    AT_REST * self.peak, 1e-300)
        sol = solution.tolist()
        for at, k in enumerate(part.cons):
            lo, hi = part.first[at], part.first[at + 1]
            got, said = math.hypot(*sol[lo:hi]), 0.0 if k in silent else abs(cons[k].impulse)
            if k not in self.unsure and abs(got - said) > AGREE * max(said, scale):
                self.unsure[k] = (f"its impulse recovered from the bodies' motion ({got:.6g}) "
                                  f"is not pymunk's ({said:.6g}) at step {self.steps}")
            self.work[k] += sum(p * v for p, v in zip(sol[lo:hi], velocity[lo:hi],
                                                      strict=True))

    def _underdetermined(self, a_mat: np.ndarray, part: _Part) -> None:
        """Name the constraints whose impulses the bodies' motion does not determine."""
        _, s, vt = np.linalg.svd(a_mat, full_matrices=True)
        tol = max(a_mat.shape) * np.finfo(float).eps * (s[0] if len(s) else 1.0)
        null = vt[int((s > tol).sum()):]
        for at, k in enumerate(part.cons):
            block = null[:, part.first[at]:part.first[at + 1]]
            if k not in self.unsure and np.abs(block).max(initial=0.0) > 1e-9:
                self.unsure[k] = ("its impulse is not separable from its neighbours' by the "
                                  "bodies' motion (they act on the same motion, or a contact "
                                  "of two points hides a torque)")

    def _world(self, end: _End, point: tuple[float, float], pose: list[list[float]]
               ) -> tuple[float, float, float, float]:
        """``point`` (body coordinates of ``end``'s body) in the world, and its offset from
        that body's centre of gravity."""
        if end.slot >= 0:
            j = end.slot
            x, y, cos, sin = pose[0][j], pose[1][j], pose[2][j], pose[3][j]
        else:
            body = end.body if end.body is not None else self.static
            p = body.position
            x, y, cos, sin = p.x, p.y, math.cos(body.angle), math.sin(body.angle)
        px, py = point[0] - end.cog[0], point[1] - end.cog[1]
        rx, ry = cos * px - sin * py, sin * px + cos * py
        gx = x + cos * end.cog[0] - sin * end.cog[1]
        gy = y + sin * end.cog[0] + cos * end.cog[1]
        return gx + rx, gy + ry, rx, ry

    def _columns(self, c: Any, kind: str, ends: tuple[_End, _End],
                 pose: list[list[float]]) -> tuple[list[tuple[list[float], list[float]]],
                                                    list[int]]:
        """Each impulse component of ``c`` as what it gives its bodies a and b (a (px, py, L)
        triple for each, per unit of the component), and the components pymunk leaves at 0
        this step (a slide or rotary limit within its limits, a groove's component along it
        while its anchor is inside its ends)."""
        end_a, end_b = ends
        if kind in ROTARY:
            ratio = 1.0 / c.ratio if kind == "GearJoint" else 1.0
            idle = []
            if kind == "RotaryLimitJoint" and c.min <= c.b.angle - c.a.angle <= c.max:
                idle = [0]
            return [([0.0, 0.0, -ratio], [0.0, 0.0, 1.0])], idle
        bx, by, rbx, rby = self._world(end_b, end_b.anchor, pose)
        idle = []
        if kind == "GrooveJoint":
            (ax, ay, rax, ray), (tx, ty), inside = _on_groove(self, c, end_a, (bx, by), pose)
            directions = [(-ty, tx), (tx, ty)]
            idle = [1] if inside else []
        else:
            ax, ay, rax, ray = self._world(end_a, end_a.anchor, pose)
            dx, dy = bx - ax, by - ay
            length = math.hypot(dx, dy)
            if kind in ("PinJoint", "SlideJoint", "DampedSpring"):
                # Of length 0 pymunk's axis is 0: whatever it accumulates, it applies nothing.
                directions = [(dx / length, dy / length) if length > 0 else (0.0, 0.0)]
                if length == 0:
                    idle = [0]
            else:
                directions = [(1.0, 0.0), (0.0, 1.0)]
            if kind == "SlideJoint" and c.min <= length <= c.max:
                idle = [0]
        return [([-nx, -ny, -(rax * ny - ray * nx)], [nx, ny, rbx * ny - rby * nx])
                for nx, ny in directions], idle

    def _energies(self, rows: np.ndarray) -> tuple[float, float, float]:
        """Kinetic energy, gravity's and the springs' potential of the copy (batch ``rows``)."""
        d = self.dynamic
        m, inertia = self.mass[d], self.moment[d]
        v = rows[d, 3:5]
        spin = np.where(np.isfinite(inertia), inertia, 0.0) * rows[d, 5] ** 2
        kinetic = 0.5 * float((m * (v ** 2).sum(axis=1)).sum() + spin.sum())
        cos, sin = np.cos(rows[d, 2]), np.sin(rows[d, 2])
        cog = self.cog[d]
        cx = rows[d, 0] + cos * cog[:, 0] - sin * cog[:, 1]
        cy = rows[d, 1] + sin * cog[:, 0] + cos * cog[:, 1]
        g = self.space.gravity
        gravity = -float((m * (g.x * cx + g.y * cy)).sum())
        springs = 0.0
        if self.springs is not None:
            ends, stiff, rest, rotary = self.springs
            x, y, angle = rows[:, 0], rows[:, 1], rows[:, 2]
            world = []
            for slot, ax, ay, fixed in ends:             # each spring end in the world
                live = slot >= 0
                j = np.where(live, slot, 0)
                c, s_ = np.cos(angle[j]), np.sin(angle[j])
                world.append((np.where(live, x[j] + c * ax - s_ * ay, fixed[:, 0]),
                              np.where(live, y[j] + s_ * ax + c * ay, fixed[:, 1]),
                              np.where(live, angle[j], fixed[:, 2])))
            (xa, ya, ta), (xb, yb, tb) = world
            extent = np.where(rotary, ta - tb, np.hypot(xb - xa, yb - ya))
            springs = float(np.sum(spring_potential(stiff, extent, rest)))
        return kinetic, gravity, springs

    def scale(self) -> float:
        return max(self.biggest)

    def unknowns(self) -> int:
        """The impulse components solved for each step."""
        return sum(part.first[-1] for part in self.parts)

    def drifts(self) -> dict[int, Drift]:
        out = {}
        for k in self.wanted:
            label = f"{self.kinds[k]} {k}"
            why = self.unsure.get(k, "")
            out[k] = Drift(label, None if why else float(self.work[k]), why)
        return out


def _arbiters(body: Any) -> list[Any]:
    """The arbiters of ``body`` from its last step, each seen from the body."""
    found: list[Any] = []
    body.each_arbiter(found.append)
    return found
