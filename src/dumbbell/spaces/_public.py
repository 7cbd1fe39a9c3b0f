"""The ledger on a pymunk build whose structs it cannot read (another layout, another
platform): counted with pymunk's public API only.

The bodies are read through pymunk's getters; the hook is the same hidden constraint, added
last and never rotated (no array of the space is read or written). What the struct reads
gave and the getters do not is lumped:

- the solver's impulses (contacts, joints, spring damping, and any constraint callback):
  one ``contacts and joints`` term, the work of every body's change of velocity in the
  solver less gravity's, its forces' and damping's; no heat per pair;
- the springs (to the static body too): their elastic kicks (computed from their settings,
  as Munk2D prepares them; working on the step's mean velocity, as every impulse does) and
  their potential's change over the moves, one ``springs`` step error;
- the contacts' position correction: the bias velocities are not public, so a body's move
  beyond its velocity is the correction when it touched something in the last step (and is
  named in ``unaccounted`` when it matters: a position the program set cannot be told from
  it), and the program's otherwise.

Declared potentials are not available here (they need the velocity functions' kicks apart
from the solver's). Everything else (E, gravity's step error, forces, damping, the
program's changes, bodies entering and leaving, callbacks after the solver) is counted as
the full ledger counts it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._pymunk import spring_function
from . import _memory as mem
from . import _physics as phys
from ._inventory import Build, Names, other_ends
from ._layout import body_function
from ._records import Before, Move, Potentials

#: What the fallback says about what it lumps.
LUMPED = "pymunk's structs are not readable on this build: lumped"


class _Getters:
    """Reads of the bodies of a table through pymunk's getters, shaped as the struct
    readers' (:class:`._memory.Reader`): ``floats()`` rows as :data:`._inventory.PRE` (or
    velocities and zero bias velocities, ``post``), ``pointers()`` (sleeping, custom
    velocity function, custom position function) as 0 or 1."""

    def __init__(self, bodies: list[Any], post: bool) -> None:
        self.bodies = bodies
        self.post = post

    def floats(self) -> np.ndarray:
        import pymunk

        out = np.zeros((6 if self.post else 14, len(self.bodies)))
        for j, b in enumerate(self.bodies):
            v, w = b.velocity, b.angular_velocity
            if self.post:
                out[0:3, j] = (v[0], v[1], w)
                continue
            cog = b.local_to_world(b.center_of_gravity)
            f = b.force
            out[:, j] = (cog[0], cog[1], b.angle, v[0], v[1], w, f[0], f[1], b.torque,
                         b.mass, b.moment, b.center_of_gravity[0], b.center_of_gravity[1],
                         np.inf if b.body_type == pymunk.Body.STATIC else 0.0)
        return out

    def both(self) -> tuple[np.ndarray, np.ndarray]:
        return self.floats(), self.pointers()

    def pointers(self) -> np.ndarray:
        import pymunk

        out = np.zeros((1 if self.post else 3, len(self.bodies)), dtype=np.uint64)
        for j, b in enumerate(self.bodies):
            out[0, j] = b.body_type == pymunk.Body.DYNAMIC and b.is_sleeping
            if not self.post:
                out[1, j] = body_function(b, "velocity_func") is not None
                out[2, j] = body_function(b, "position_func") is not None
        return out


class _Table:
    """The ledger's table (:class:`._inventory.Table`) read through pymunk's getters."""

    def __init__(self, space: Any, names: Names) -> None:
        import pymunk

        from ._inventory import Table

        bodies = list(space.bodies)
        dyn = [b for b in bodies if b.body_type == pymunk.Body.DYNAMIC]
        kin = [b for b in bodies if b.body_type == pymunk.Body.KINEMATIC]
        self.constraint_key = tuple(space.constraints)
        # Past the moving rows, the other ends of the constraints (a spring to the static
        # body, say), as the struct-read table has them: a spring's potential needs both.
        other = other_ends(self.constraint_key, {id(b) for b in (*dyn, *kin)})
        self.bodies = [*dyn, *kin, *other]
        self.body_key = tuple(bodies)
        n, k = len(dyn), len(kin)
        self.n, self.k, self.rows = n, k, len(self.bodies)
        self.uid = np.array([names.uid(b) for b in self.bodies], dtype=np.int64)
        self.labels = [names.labels[u] for u in self.uid.tolist()]
        self.pre = _Getters(self.bodies, post=False)
        self.post = _Getters(self.bodies, post=True)
        self.state = self.pre
        first = self.pre.floats()
        self.settings = first[9:13].copy()
        self.static = np.isinf(first[13])
        self.idle = first[13, n:].copy()
        Table._derive(self, first)  # the arrays the struct-read table derives
        for r in range(n + k, self.rows):  # a body outside the space moves with none
            self.drives[r] = self.bodies[r].body_type != pymunk.Body.STATIC
        self.any_driven = bool(self.drives.any())


class _Spring:
    """A spring as :func:`._physics.spring_energy` reads it, from pymunk's getters."""

    def __init__(self, c: Any, kind: str, a: int, b: int, label: str) -> None:
        self.obj, self.kind, self.label = c, kind, label
        self.a, self.b = np.array([a]), np.array([b])
        self.default = np.array([True])
        self.spring = True
        self.settings = self.read()
        if kind == "spring":
            self.anchor = np.array([[c.anchor_a[0] - c.a.center_of_gravity[0],
                                     c.anchor_a[1] - c.a.center_of_gravity[1],
                                     c.anchor_b[0] - c.b.center_of_gravity[0],
                                     c.anchor_b[1] - c.b.center_of_gravity[1]]])

    def read(self) -> np.ndarray:
        c = self.obj
        rest = c.rest_length if self.kind == "spring" else c.rest_angle
        return np.array([[rest], [c.stiffness], [c.damping], [c.max_force]])

    def changed(self) -> bool:
        return not np.array_equal(self.read(), self.settings)


def public_build(space: Any, names: Names) -> Build:
    """What ``space`` holds, read through pymunk's getters (see the module docstring)."""
    import pymunk

    t = _Table(space, names)
    n, labels = t.n, t.labels
    current: dict[str, str] = {}
    rows = {id(b): r for r, b in enumerate(t.bodies)}
    springs: list[Any] = []
    joints = 0
    for i, c in enumerate(t.constraint_key):
        label = f"{type(c).__name__} {i}"
        spring = isinstance(c, pymunk.DampedSpring | pymunk.DampedRotarySpring)
        custom = spring and spring_function(c) is not None
        if spring and not custom and id(c.a) in rows and id(c.b) in rows:
            springs.append(_Spring(c, "spring" if isinstance(c, pymunk.DampedSpring)
                                   else "rotary_spring", rows[id(c.a)], rows[id(c.b)], label))
        elif spring:
            current[label] = f"{LUMPED}: a spring with a custom force"
        joints += not spring
        if c.pre_solve is not None or c.post_solve is not None:
            current[label] = (f"{LUMPED}: its pre_solve or post_solve callback acts inside the "
                              "solver's lumped term")
    for slot, g in enumerate(springs):
        g.slot = slot
    P = t.pre.pointers()
    vf, pf = P[1, :n].copy(), P[2, :n].copy()
    custom = vf.astype(bool)
    for i in np.nonzero(custom)[0]:
        current[labels[i]] = (f"custom velocity_func: {LUMPED} with the solver's impulses "
                              "(declared potentials need the full ledger)")
    for i in np.nonzero(pf)[0]:
        current[labels[i]] = "custom position_func: its moves are not predicted"
    for i in np.nonzero(t.unsteppable)[0]:
        current[labels[i]] = "a dynamic body of mass or moment 0: pymunk cannot step it"
    gravity = tuple(float(g) for g in space.gravity)
    funcs = [body_function(t.bodies[i], "velocity_func") if custom[i] else None
             for i in range(n)]
    return Build(t, {}, springs, [], gravity, vf, pf, custom, np.zeros(n, dtype=bool), funcs,
                 current)


def _spring_kicks(b: Build, pos: np.ndarray, dt: float, springs: list[Any] | None = None
                  ) -> np.ndarray:
    """The impulses (3, rows) the springs (``springs``, default all) applied when the step
    prepared them: their force at the positions ``pos``, clamped to ``max_force``, times dt
    (Munk2D's preStep)."""
    t = b.table
    out = np.zeros((3, t.rows))
    for g in b.springs if springs is None else springs:
        ia, ib = int(g.a[0]), int(g.b[0])
        rest, k, _, max_force = g.settings[:, 0]
        if g.kind == "spring":
            an = g.anchor[0]
            ca, sa = np.cos(pos[2, ia]), np.sin(pos[2, ia])
            cb, sb = np.cos(pos[2, ib]), np.sin(pos[2, ib])
            r1 = (ca * an[0] - sa * an[1], sa * an[0] + ca * an[1])
            r2 = (cb * an[2] - sb * an[3], sb * an[2] + cb * an[3])
            dx = (pos[0, ib] + r2[0]) - (pos[0, ia] + r1[0])
            dy = (pos[1, ib] + r2[1]) - (pos[1, ia] + r1[1])
            dist = float(np.hypot(dx, dy))
            nx, ny = (dx / dist, dy / dist) if dist else (0.0, 0.0)
            j = float(np.clip((rest - dist) * k, -max_force, max_force)) * dt
            jx, jy = nx * j, ny * j
            out[:, ia] -= (jx, jy, r1[0] * jy - r1[1] * jx)
            out[:, ib] += (jx, jy, r2[0] * jy - r2[1] * jx)
        else:
            j = float(np.clip(((pos[2, ia] - pos[2, ib]) - rest) * k, -max_force,
                              max_force)) * dt
            out[2, ia] -= j
            out[2, ib] += j
    return out


def start(self: Any) -> None:
    """The first snapshot of a ledger ``self`` (either kind), just built: E(0), the
    potentials' reference and the energy scale."""
    self._snap = phys.read_snapshot(self._b)
    self._snap_uid = self._b.table.uid.copy()
    e = phys.energy(self._b, self._snap)
    self._E0 = self._E = e.E
    self._Uref = np.array([e.Ug, e.Us, e.Ud])
    self._scale = e.K
    self._size = phys.magnitude(*e[:5])


def attach(self: Any, calls: Any) -> None:
    """Attach the fallback ledger ``self`` (a :class:`.ledger.PublicLedger`): its hook
    is added last and never rotated."""
    import weakref

    from . import _hook

    self._touching = np.zeros(0, dtype=bool)
    self._rebuild()
    start(self)
    self._hook = _hook.Hook(self.space, *calls, first=False)
    self._finalizer = weakref.finalize(self, self._hook.release)


def rebuild(self: Any) -> None:
    """Read again what the space holds (pymunk's getters)."""
    old = self.__dict__.get("_b")
    if old is not None and self.steps > self._built_at:
        self._unaccounted.update(old.current)
    self._built_at = self.steps
    self._b = public_build(self.space, self._names)
    t = self._b.table
    self._sums.reset(t.n, t.rows, 0)
    # The bodies that touched something in the last step still do (their move this step
    # has the contacts' position correction), whatever came or went.
    touching = self.__dict__.get("_touching")
    had = old.table.uid[touching] if old is not None and touching is not None and len(
        touching) == old.table.rows else ()
    self._touching = np.isin(t.uid, had)


def pre(self: Any) -> None:
    """Before the solver (after every spring's kick: the hook is last): the program's
    changes, the move, and the springs' kicks taken back out of the velocities."""
    from ._inventory import changed

    if self._threaded:
        self._note_threads()
    self._awaiting_end = False
    dt = float(self.space.current_time_step)
    t = self._b.table
    F, P = t.pre.floats(), t.pre.pointers()
    ahead = None  # the springs prepared before the hook: all while it is last
    if changed(self._b, self.space, F, P):
        gone = self._gone()
        if gone.any():
            self._catch_up(F, "program", gone)
        self._restructure("the space's bodies, constraints or settings", dt, "program")
        t = self._b.table
        F, P = t.pre.floats(), t.pre.pointers()
        ahead = _ahead_of_hook(self)
    b, s, n = self._b, self._snap, t.n
    coef = 0.0 if self._dt_prev == 0.0 else dt / self._dt_prev
    kicks = _spring_kicks(b, F[0:3], dt)
    vel_r = F[3:6].copy()
    vel0 = vel_r.copy()  # kinematic rows (past the dynamic ones) take no spring's kick
    # The velocities read hold the kicks of the springs prepared before the hook: taken
    # back out (the others kick after the read, inside the step's velocity change).
    done = kicks if ahead is None else _spring_kicks(b, F[0:3], dt, ahead)
    vel0[:, :n] -= done[:, :n] * t.inv3
    # Bodies no spring kicked keep their velocity bit for bit; a kick taken back out
    # leaves a few roundings, which are not the program's.
    vel0 = np.where(phys.same(vel0, s.vel), s.vel, vel0)
    moving = t.moves & ~np.concatenate([P[0, :n].astype(bool), np.zeros(t.rows - n, bool)])
    expected = np.where(moving, s.pos + vel0 * dt, s.pos)
    beyond = ~np.all(phys.same(F[0:3], expected), axis=0)
    # Moved with the velocity the last step left, set anew after the move (a collision's
    # begin, pre_solve or separate callback): where it was, not a position the program set.
    beyond &= ~np.all(phys.same(F[0:3], np.where(moving, s.pos + s.vel * dt, s.pos)), axis=0)
    corrected = beyond & self._touching & moving
    start = np.where(beyond & ~corrected, F[0:3] - np.where(moving, vel0 * dt, 0.0), s.pos)
    total = 0.0
    per_body, springs = phys.changes(b, s, start, vel0)
    if np.any(per_body) or springs:
        self._sums.program += per_body
        if springs:
            self._sums.add("program: springs stretched by moved bodies", "program",
                           springs)
        total += float(np.sum(per_body)) + springs
    # Gravity and the springs over the move: the velocities' part, and the rest (the
    # contacts' position correction on the bodies that touched).
    gx, gy = b.gravity
    mid = np.where(moving, start + vel0 * dt, start)
    g_int = -float(gx * (t.m @ (mid[0, :n] - start[0, :n]))
                   + gy * (t.m @ (mid[1, :n] - start[1, :n])))
    corr = -float(gx * (t.m @ (F[0, :n] - mid[0, :n])) + gy * (t.m @ (F[1, :n] - mid[1, :n])))
    u_start, u_mid = phys.spring_energy(b, start), phys.spring_energy(b, mid)
    u_end = phys.spring_energy(b, F[0:3])
    spring_int = sum(float(np.sum(m2 - a2)) for a2, m2 in zip(u_start, u_mid, strict=True))
    corr += sum(float(np.sum(e2 - m2)) for m2, e2 in zip(u_mid, u_end, strict=True))
    if corr:
        self._sums.add("position correction", "correction", corr,
                       "the contacts' position correction, with any position the program "
                       f"set on a body that touched something ({LUMPED})")
    # The springs' kicks work on the step's mean velocity, as every impulse of the step
    # does (:func:`post`): their potential's change over the move now, their work then.
    self._sums.add(f"springs ({LUMPED})", "step error", spring_int,
                   "the springs' kicks and their potential's change over the moves")
    total += corr + spring_int
    self._kicks = kicks
    force = F[6:9, :n]
    awake = P[0, :n] == 0
    move = Move(F[0:3].copy(), vel0, start, dt)
    self._before = Before(dt, coef, move, force if force.any() else None,
                          None if awake.all() else awake, g_int, None,
                          Potentials([], u_end, None, s.ud), [], False, total)


def _ahead_of_hook(self: Any) -> list[Any] | None:
    """The springs prepared before the hook in this step (None: all, the hook being last).
    A program that removes a constraint other than the space's last moves the hook into
    its place (``cpSpaceRemoveConstraint``): until :func:`end` puts it last again, the
    springs after it kick after the hook's read."""
    hook = self._hook
    order = hook.order()
    if not order or order[-1] == hook.at:
        return None
    self._misplaced = True
    before = set(order[: order.index(hook.at)]) if hook.at in order else set(order)
    try:
        return [g for g in self._b.springs if mem.address(g.obj._constraint) in before]
    except AttributeError:  # a pymunk whose constraints keep their C struct elsewhere
        return None


def end(self: Any) -> None:
    """At the end of a step (a post-step callback: the space is not stepping), put the hook
    last again if a program's removal moved it (:func:`_ahead_of_hook`): the constraints
    are then in the order a space without the hook has them."""
    if self.__dict__.get("_misplaced") and self._hook is not None:
        self._misplaced = False
        self._hook.to_last()


def post(self: Any) -> None:
    """After the solver: gravity, forces and damping as the full ledger counts them;
    everything else the solver did, one lumped term."""
    from ._records import Step

    p, self._before = self._before, None
    if p is None:
        return
    b = self._b
    t = b.table
    n = t.n
    Q = t.post.floats()
    vel0, vel1 = p.move.vel, Q[0:3]  # vel0: before the springs' kicks
    damping = float(self.space.damping)
    kicks = self._kicks
    step = Step(p.dt, p.coef, p.move.pos, vel0, vel1, (vel0 + vel1) * 0.5,
                np.zeros((2, t.rows)), kicks if damping != 1.0 else None, [])
    lin, ang, w_g, external = phys.external(b, step, p, damping, self._sums)
    # The springs' kicks' work on the dynamic bodies (kinematic and static ends take it
    # as work leaving: they do not move by it).
    w_k = float(np.sum(kicks[:, :n] * step.u[:, :n]))
    self._sums.add(f"springs ({LUMPED})", "step error", w_k)
    # The solver's work: of the impulse m (v1 - v0), less the outside impulses'.
    w_s = float(np.sum(t.mass3 * (vel1[:, :n] - vel0[:, :n]) * step.u[:, :n])
                - np.sum(lin) - np.sum(ang)) - w_k
    self._sums.add(f"contacts and joints ({LUMPED})", "contacts and joints", w_s,
                   "the work of the solver's impulses: contacts, joints, spring damping")
    self._sums.add("gravity", "step error", w_g + p.g_int)
    total = p.total + external + w_s + w_g + p.g_int + w_k
    self._close_step(Q, t.post.pointers(), p, total)
    self._touching = np.zeros(t.rows, dtype=bool)
    for r, body in enumerate(t.bodies):
        def touched(arbiter: Any, r: int = r) -> None:
            self._touching[r] = True

        body.each_arbiter(touched)
