"""The ledger's count at every step: what its hook calls (:mod:`._hook`) before the
constraints are prepared (:meth:`Counting._pre`: the program's changes since the last step,
the move, the contacts and impulses carried in), after the solver (:meth:`Counting._post`:
each source's work, the step closed against E) and at the end of the step
(:meth:`Counting._end`: what a callback changed after the solver). A mixin of
:class:`.ledger.Ledger`, beside :class:`._changes.Changes` (what it does when the space
changes), which holds the state these methods read and write: the build ``_b``, the
snapshot ``_snap``, the running sums, the contacts and pairs, E, the scale and the steps."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from . import _layout as layout
from . import _physics as phys
from ._changes import Changes
from ._contacts import UnknownBody
from ._inventory import came_or_went, changed
from ._records import Before, Snapshot, Step
from ._terms import ROUNDED
from ._threaded import hazard

__all__: list[str] = []


class Counting(Changes):
    """The ledger's work at each step (see the module docstring)."""

    _contacts: Any
    _pairs: Any
    _before: Before | None
    _bad: str | None
    _dt_prev: float
    _worst: float
    _threaded: bool
    _threads: int
    _quiet_end: bool
    t: float

    def _call(self, name: str) -> None:
        """Run a hook's work; any failure stops the count, never the user's step."""
        if self._error is not None or self._hook is None:
            return
        try:
            if name == "_end":
                self._end()  # quiets numpy itself, only when there is arithmetic to do
            else:
                _quietly(getattr(self, name))
        except phys.FieldError as e:
            self._stop(f"{e} after step {self.steps}: the ledger stopped counting there")
        except Exception as e:  # noqa: BLE001 - never break the user's step
            self._before = None
            self._error = f"stopped counting at step {self.steps}: {type(e).__name__}: {e}"
            warnings.warn(f"dumbbell.spaces.Ledger {self._error}", RuntimeWarning,
                          stacklevel=2)

    @property
    def _floor(self) -> float:
        """The energies' own rounding (:data:`._terms.ROUNDED` of the largest magnitude of E
        and its parts seen): what the closure and a term may be and still be rounding."""
        return ROUNDED * self._size

    def _stop(self, why: str) -> None:
        self._bad = self._error = why
        self._before = None

    def _blown(self, snap: Snapshot) -> None:
        """The state stopped being finite: stop counting, naming the body and the step."""
        from ..model import args

        t = self._b.table
        for name, rows in (("velocity", (0, 1)), ("angular_velocity", (2,)),
                           ("position", (0, 1)), ("angle", (2,))):
            block = snap.pos if name in ("position", "angle") else snap.vel
            bad = ~np.all(np.isfinite(block[list(rows), : t.n]), axis=0)
            if bad.any():
                i = int(np.argmax(bad))
                value = tuple(float(block[r, i]) for r in rows)
                shown = value[0] if len(value) == 1 else value
                why = self._b.current.get(t.labels[i], "")
                why = f" ({why})" if why.startswith("a dynamic body of mass") else ""
                self._stop(f"{t.labels[i]}: {name} = {args.show(shown)} after step "
                           f"{self.steps + 1}{why}: the ledger stopped counting there")
                return
        self._stop(f"the energy stopped being finite after step {self.steps + 1}")

    # -- the step ----------------------------------------------------------------------

    def _note_threads(self) -> None:
        """On a threaded space: the threads this step runs on (``space.threads``)."""
        n = int(self.space.threads)
        self._threads = max(self._threads, n)

    def _pre(self) -> None:
        """Before the constraints are prepared: positions have moved, velocities are the
        step's start. Count the program's changes and the move's energy; read the impulses
        carried in."""
        if self._threaded:
            self._note_threads()
        self._awaiting_end = False
        dt = float(self.space.current_time_step)
        t = self._b.table
        F, P = t.pre.both()
        reason = changed(self._b, self.space, F, P)
        if reason:
            gone = self._gone()
            if gone.any():
                self._catch_up(F, "program", gone)
            self._restructure(reason, dt, "program")
        coef = 0.0 if self._dt_prev == 0.0 else dt / self._dt_prev
        for attempt in (0, 1):
            try:
                contacts = self._contacts.before(self._b.table, coef)
                break
            except UnknownBody:
                if attempt:
                    raise RuntimeError("a contact touches a body the ledger does not "
                                       "know") from None
                self._restructure("a body touched for the first time", dt, "program")
        if self._b.table is not t:
            t = self._b.table
            F, P = t.pre.both()
        b, s, n = self._b, self._snap, t.n
        move = phys.move_of(b, s, F[0:3], F[3:6], dt)
        total = 0.0
        vel = F[3:6, :n]
        if move.start is not s.pos or (vel.tobytes() != s.vel[:, :n].tobytes()
                                       and not (vel == s.vel[:, :n]).all()):
            per_body, springs = phys.changes(b, s, move.start, F[3:6])
            self._sums.program += per_body
            if springs:
                self._sums.add("program: springs stretched by moved bodies", "program",
                               springs)
            total += float(np.sum(per_body)) + springs
        g_int, g_rows, corr = phys.gravity_over(b, s, move)
        pots, corr = phys.potentials_over(b, s, move, corr)
        self._contacts.next_dt(dt, self._pairs, self._sums)
        if corr:
            self._sums.add("position correction", "correction", corr,
                           "potential energy the contacts' position correction adds (beyond "
                           "each pair's part through gravity)")
        force = F[6:9, :n]
        roots = P[0, :n]
        # (np.count_nonzero: the fastest test of any, and each call here is paid for in
        # caches the collision search has just used)
        self._before = Before(dt, coef, move, force if np.count_nonzero(force) else None,
                              roots == 0 if np.count_nonzero(roots) else None, g_int, g_rows, pots,
                              [g.before.floats() for g in b.groups.values()], contacts,
                              total + corr)

    def _flush(self) -> None:
        """Do the held steps' contact work (:meth:`._contacts.Contacts.flush`): before the
        sums are folded or the table changes."""
        contacts = self.__dict__.get("_contacts")
        if contacts is not None:
            contacts.flush(self._b.table, self._pairs, self._sums, self._b)

    def _quiet(self) -> bool:
        """Nothing can change a body between the solver and the ledger's end of this step:
        no constraint has a ``post_solve``, the space has no collision handler, no
        post-step callback before the ledger's, and no add or remove pymunk deferred to the
        step's end (asked for from a constraint's ``pre_solve``, a ``velocity_func`` or a
        ``position_func``: a shape added or removed changes its body's mass)
        (:func:`._layout.callbacks_known`). Then :meth:`_end` checks only that the bodies
        and constraints are those it knows."""
        space = self.space
        return (layout.callbacks_known() and not space._handlers
                and not space._post_step_callbacks
                and not space._add_later and not space._remove_later
                and all(c.post_solve is None for c in self._b.table.constraint_key))

    def _post(self) -> None:
        """After the solver: every impulse of the step is applied. Count each source's work
        and close the step."""
        p = self._before
        if p is None:
            return
        self._before = None
        self._quiet_end = self._quiet()
        b = self._b
        t = b.table
        Q, root = t.post.both()
        vel0, vel1 = p.move.vel, Q[0:3]
        damping = float(self.space.damping)
        # Velocities the sources act on: the mean of before and after (kinematic bodies
        # keep theirs; static ones have none).
        u = vel0 + vel1
        u *= 0.5
        total = p.total
        if damping == 1.0 and p.force is None and p.awake is None and b.plain:
            if p.contacts:
                self._record(u)
            total += phys.plain_step(b, p, vel0, vel1, u, self._sums)
            self._close_step(Q, root, p, total)
            return
        step = Step(p.dt, p.coef, p.move.pos, vel0, vel1, u, np.zeros((2, t.rows)),
                    np.zeros((3, t.rows)) if damping != 1.0 and b.springs else None,
                    p.potentials.spring_int)
        for g, initial in zip(b.groups.values(), p.initial, strict=True):
            total += phys.constraint_work(t, g, g.after.floats(), initial, step)
        if p.contacts:
            self._record(step.u)
        lin, ang, w_g, external = phys.external(b, step, p, damping, self._sums)
        total += external
        total += phys.unexplained(b, step, p, (lin, ang, w_g), self._sums)
        self._close_step(Q, root, p, total)

    def _record(self, u: np.ndarray) -> None:
        """The contacts' impulses of the step, acting on the velocities ``u``: their work is
        done a batch of steps at a time; until then it is in the unexplained impulses' sums
        (which the batch takes it out of), and the step's total counts it through them."""
        self._contacts.record(u)
        if self._contacts.due:
            self._flush()

    def _close_step(self, Q: np.ndarray, root: np.ndarray, p: Before, total: float) -> None:
        """Snapshot the end of the step (``Q``: the post reader's floats, ``root`` its
        pointers), check it against the terms, track the scale."""
        t = self._b.table
        # Q and the move's positions are this step's own reads: the snapshot keeps them.
        bias = Q[3:6]
        if t.rows > t.n:
            bias[:, t.n:] = 0.0
        roots = root[0, : t.n]
        asleep = np.count_nonzero(roots) > 0
        snap = Snapshot(p.move.pos, Q[0:3], bias, roots != 0 if asleep else t.none_asleep,
                        p.potentials.u_end, p.potentials.d_end, asleep, np.count_nonzero(bias) > 0)
        E, K, Ug, Us, Ud = phys.totals(self._b, snap)
        if not (math.isfinite(E) and math.isfinite(total)):
            self._blown(snap)
            return
        self._snap = snap
        step = E - self._E - total
        self._E = E
        self.steps += 1
        self.t += p.dt
        self._dt_prev = p.dt
        self._awaiting_end = True
        ref = self._Uref
        self._scale = max(self._scale, K, abs(Ug - ref[0]), abs(Us - ref[1]), abs(Ud - ref[2]))
        self._size = max(self._size, phys.magnitude(E, K, Ug, Us, Ud))
        self._worst = max(self._worst, abs(step))  # relative to the scale when shown

    def _end(self) -> None:
        """At the end of the step (pymunk's post-step callbacks): what a callback changed
        since the solver, bodies or constraints, masses, gravity or springs' settings too."""
        if not self._awaiting_end:
            return
        self._awaiting_end = False
        t = self._b.table
        if self._quiet_end and not came_or_went(t, self.space):
            return
        F, s = t.state.floats(), self._snap
        if not (F[0:3].tobytes() == s.pos.tobytes() and F[3:6].tobytes() == s.vel.tobytes()):
            _quietly(lambda: self._catch_up(F, "unattributed"))
        what = changed(self._b, self.space, F)  # the floats only: no function pointers
        if what:
            _quietly(lambda: self._restructure(f"{what} inside the step", None, "unattributed"))


def inside(threads: int) -> str:
    """Why a body's energy changed inside the step with no source to explain it: a callback,
    or (a space that stepped on more than one thread) pymunk's threaded solver."""
    callback = ("a callback: a constraint's pre_solve or post_solve, a collision's "
                "post_solve, a post-step callback")
    if threads <= 1:
        return f"changed inside pymunk's step by something no source explains ({callback})"
    return (f"changed inside pymunk's step by something no source explains: the space "
            f"steps with space.threads = {threads}, and {hazard(threads)} (space.threads = "
            f"1, pymunk's default, avoids it); or {callback}")


@np.errstate(invalid="ignore", over="ignore", divide="ignore")
def _quietly(work: Callable[[], None]) -> None:
    """Run ``work`` with numpy's floating-point warnings off (non-finite states are
    caught and named by the ledger itself). Decorated once rather than a ``with
    np.errstate`` per call: the context manager's object costs a few microseconds, three
    times a step."""
    work()
