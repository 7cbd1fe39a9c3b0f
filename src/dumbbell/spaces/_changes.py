"""How the ledger follows a space that changes: what the program or a callback changed,
per body (:meth:`Changes._catch_up`), and bodies, constraints or settings that came or went
(:meth:`Changes._restructure`: the running sums are folded, what the space holds is read
again, and the energy that entered or left with bodies is counted). A mixin of
:class:`.ledger.Ledger`, which holds the state these methods read: the build ``_b``, the
snapshot ``_snap`` and the ids of its rows ``_snap_uid``, the sums, E and the potentials'
references."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _physics as phys
from ._inventory import build, changed
from ._records import Snapshot


class Changes:
    """What the ledger does when the space changes (see the module docstring)."""

    _b: Any
    _snap: Snapshot
    _snap_uid: np.ndarray
    _sums: Any
    _hook: Any
    _error: str | None
    _awaiting_end: bool
    _unaccounted: dict[str, str]
    _names: Any
    _potentials: list[Any]
    _scale: float
    _size: float
    _floor: float
    _Uref: np.ndarray
    _E: float
    steps: int
    space: Any

    def _end(self) -> None:  # pragma: no cover - the ledger's own
        raise NotImplementedError

    def _flush(self) -> None:  # pragma: no cover - the ledger's own
        raise NotImplementedError

    def _rebuild(self) -> None:
        """(Re)read what the space holds. What could not be accounted for while steps were
        taken stays named."""
        old = self.__dict__.get("_b")
        if old is not None and self.steps > self._built_at:
            self._unaccounted.update(old.current)
        self._built_at = self.steps
        self._b = build(self.space, self._names, self._potentials)
        t = self._b.table
        self._sums.reset(t.n, t.rows, len(self._b.fields))

    def _remap(self, snap: Snapshot) -> Snapshot:
        """``snap`` (taken on the previous table) on the present one: bodies in both keep
        their values, new ones get their present state."""
        t = self._b.table
        now = phys.read_snapshot(self._b)
        old = {int(u): r for r, u in enumerate(self._snap_uid.tolist())}
        src = np.array([old.get(int(u), -1) for u in t.uid.tolist()], dtype=np.int64)
        have = src >= 0
        for mine, theirs in ((now.pos, snap.pos), (now.vel, snap.vel), (now.bias, snap.bias)):
            mine[:, have] = theirs[:, src[have]]
        keep = have[: t.n] & (src[: t.n] < len(snap.sleeping))
        now.sleeping[keep] = snap.sleeping[src[: t.n][keep]]
        self._snap_uid = t.uid.copy()
        return phys.snapshot(self._b, now.pos, now.vel, now.bias, now.sleeping)

    def _restructure(self, reason: str, dt: float | None, kind: str) -> None:
        """The space changed (bodies, constraints, settings): fold the running sums,
        rebuild, and count the energy that entered or left with bodies, and what the change
        itself did (``kind``: 'program' or 'unattributed'). ``dt`` is the step under way
        (None between steps): bodies new in it start where they were before its move."""
        self._flush()
        b0 = self._b
        old = phys.energy(b0, self._snap)
        old_dyn = b0.table.uid[: b0.table.n].copy()
        springs_what, bodies_what = _what_changed(b0, self.space, reason)
        old_rows = self._snap_uid.copy()
        self._sums.fold(b0, self._scale, self._floor)
        self._rebuild()
        snap = self._remap(self._snap)
        t = self._b.table
        if dt is not None:
            new = ~np.isin(t.uid, old_rows) & t.moves
            new[: t.n] &= ~snap.sleeping
            if np.any(new):
                pos = snap.pos.copy()
                pos[:, new] -= snap.vel[:, new] * dt
                snap = phys.snapshot(self._b, pos, snap.vel, snap.bias, snap.sleeping)
        self._snap = snap
        e = phys.energy(self._b, snap)
        entered = left = 0.0
        labels = self._names.labels
        for i in np.nonzero(~np.isin(t.uid[: t.n], old_dyn))[0]:
            self._sums.add(t.labels[i], "entered", e.body[i],
                           "energy of a body added to the space")
            entered += float(e.body[i])
            self._Uref += (e.Ugb[i], 0.0, e.Udb[i])
        for j in np.nonzero(~np.isin(old_dyn, t.uid[: t.n]))[0]:
            self._sums.add(labels[int(old_dyn[j])], "left", -old.body[j],
                           "energy of a body removed from the space")
            left -= float(old.body[j])
            self._Uref -= (old.Ugb[j], 0.0, old.Udb[j])
        # What the change itself did: the springs' potential (constraints that came or
        # went, a spring's settings) and the bodies that stayed (gravity, a mass...), each
        # named by what changed it.
        rest = e.E - old.E - entered - left
        springs = e.Us - old.Us
        parts = {springs_what: springs}
        parts[bodies_what] = parts.get(bodies_what, 0.0) + (rest - springs)
        floor = 1e-12 * max(abs(old.E), abs(e.E), self._scale)
        for what, value in parts.items():
            if abs(value) > floor:
                source = f"program: {what}" if kind == "program" else f"{what} (a callback)"
                self._sums.add(source, kind, value,
                               "energy changed by what was changed in the space")
        self._Uref[1] += e.Us - old.Us
        self._E = e.E
        self._size = max(self._size, phys.magnitude(*e[:5]))

    def _catch_up(self, F: np.ndarray, kind: str, rows: np.ndarray | None = None) -> None:
        """Count, per body, what changed from the snapshot to the state read now (``F``,
        between two parts of the solver's work or between steps, on the present table) as
        ``kind`` ('program' or 'unattributed'); ``rows``: only those (dynamic) rows."""
        s = self._snap
        n = self._b.table.n
        if rows is None and ((F[0:3].tobytes() == s.pos.tobytes()
                              and F[3:6].tobytes() == s.vel.tobytes())
                             or ((F[0:3] == s.pos).all() and (F[3:6, :n] == s.vel[:, :n]).all())):
            return  # the same bytes are the same values; other bytes may be too (-0, +0)
        pos, vel = F[0:3].copy(), F[3:6].copy()
        if rows is not None:
            pos = np.where(rows, pos, s.pos)
            vel = np.where(rows, vel, s.vel)
        per_body, springs = phys.changes(self._b, s, pos, vel)
        getattr(self._sums, kind)[:] += per_body
        if springs:
            source = ("program: springs stretched by moved bodies" if kind == "program"
                      else "springs stretched by moved bodies (a callback)")
            self._sums.add(source, kind, springs)
        self._snap = phys.snapshot(self._b, pos, vel, s.bias, s.sleeping)
        e = phys.energy(self._b, self._snap)
        self._E = e.E
        self._size = max(self._size, phys.magnitude(*e[:5]))

    def _gone(self) -> np.ndarray:
        """The dynamic rows whose bodies are no longer in the space (pymunk does not move
        them: what they hold now is what they leave with)."""
        t = self._b.table
        space = self.space
        out = np.zeros(t.rows, dtype=bool)
        out[: t.n] = [b.space is not space for b in t.bodies[: t.n]]
        return out

    def _sync(self) -> None:
        """Between steps: count what the program changed since the last look."""
        if self._hook is None or self._error is not None:
            return
        if self._hook.locked():
            return  # inside a step: the account stands at the last step's end
        if self._awaiting_end:
            self._end()  # a post-step callback before the ledger's: still the step's
        t = self._b.table
        F, P = t.pre.floats(), t.pre.pointers()
        self._catch_up(F, "program")
        reason = changed(self._b, self.space, F, P)
        if reason:
            self._restructure(reason, None, "program")


class _Held:
    """The bodies and constraints a build holds, with the space's gravity now: what
    :func:`._inventory.changed` compares a build against to find what else changed beside
    bodies or constraints that came or went."""

    def __init__(self, b: Any, space: Any) -> None:
        self.bodies = b.table.body_key
        self.constraints = b.table.constraint_key
        self.gravity = space.gravity


def _what_changed(b: Any, space: Any, reason: str) -> tuple[str, str]:
    """What changed the springs' potential and what changed the energy of the bodies that
    stayed, when the space changed from build ``b`` for ``reason`` (the first change
    noticed): constraints that came or went, else the reason; for the bodies, the first
    change noticed beside bodies or constraints that came or went, else the reason."""
    t = b.table
    constraints = tuple(space.constraints) != t.constraint_key
    if not constraints and tuple(space.bodies) == t.body_key:
        return reason, reason
    inside = " inside the step" if reason.endswith(" inside the step") else ""
    F, P = t.pre.both()
    other = changed(b, _Held(b, space), F, P) or reason
    return (f"constraints added or removed{inside}" if constraints else other), other
