"""A heat counter for any pymunk space: the energy its contacts dissipate, impact by impact.

Each step, every contact point i applies an impulse J_i (normal and friction) between its two
bodies. The work it does on their relative motion is J_i . (u_i + u'_i) / 2, with u_i the
relative velocity at the point before the step and u'_i after it; for impulses applied at
once this sums to the change of kinetic energy they cause exactly, with several contacts on
one body too. The heat is minus that work, summed over contacts and steps (J):

- an elastic, frictionless contact reverses u_n and does no work: heat 0 (pymunk aims the
  bounce at the velocity before the step, so gravity's kick during the step does not count);
- a sliding contact gives mu N |u_t| dt per step; an inelastic impact (1 - e^2) of its
  normal energy;
- a resting contact (u = u' = 0) gives nothing.

``Arbiter.total_ke`` is not used: it leaves out the 1/2 and sliding friction.

What is left, E(0) - E(t) - heat, is the method's error. For pymunk's step under gravity it
is -1/2 M g^2 dt per second of flight (positions move with the velocity before gravity's
kick), so it shrinks with dt.

The counter listens on the space's wildcard handler (``on_collision(None, None)``) with
``pre_solve`` and ``post_solve``; callbacks already there are kept and called after it with
their own data, and handlers the user sets for particular collision types keep firing.
Impulses are read from pymunk's contact structs (``Arbiter._arbiter``; pymunk 7).
"""

from __future__ import annotations

from typing import Any

__all__ = ["HeatCounter"]


class HeatCounter:
    """Attach to ``space``: ``total`` (J) is the heat its contacts dissipated since, ``steps``
    the contact-steps counted. ``detach()`` restores the callbacks that were there before."""

    def __init__(self, space: Any) -> None:
        from pymunk._chipmunk_cffi import ffi

        from ..model import args

        self.space = args.space(space)
        self.total = 0.0
        self.steps = 0
        self._ffi = ffi
        self._before: dict[int, list[tuple[float, float, float, float]]] = {}
        self._last_dt: float | None = None
        old = space._handlers.get((None, None))
        self._user = {
            phase: (getattr(old, phase), old.data.get(phase)) if old is not None
            and getattr(old, phase) is not None else None
            for phase in ("pre_solve", "post_solve")
        }
        space.on_collision(None, None, pre_solve=self._pre_solve, post_solve=self._post_solve)
        self._handler = space._handlers[(None, None)]

    @property
    def attached(self) -> bool:
        """False once someone replaced the counter's callbacks on the wildcard handler (then
        ``total`` stops counting)."""
        h = self._handler
        return h.pre_solve == self._pre_solve and h.post_solve == self._post_solve

    def detach(self) -> None:
        """Stop counting and put back the wildcard callbacks that were there before."""
        from pymunk import empty_callback

        if not self.attached:
            return
        for phase, saved in self._user.items():
            if saved is None:
                self.space.on_collision(None, None, **{phase: empty_callback})
            else:
                self.space.on_collision(None, None, data=saved[1], **{phase: saved[0]})

    def _relative(self, arbiter: Any) -> tuple[Any, Any, Any]:
        raw = arbiter._arbiter
        shapes = arbiter.shapes
        a, b = (shapes[1], shapes[0]) if raw.swapped else shapes
        return raw, a.body, b.body

    @staticmethod
    def _velocities(raw: Any, ba: Any, bb: Any) -> list[tuple[float, float]]:
        va, wa, vb, wb = ba.velocity, ba.angular_velocity, bb.velocity, bb.angular_velocity
        out = []
        for i in range(raw.count):
            c = raw.contacts[i]
            r1, r2 = c.r1, c.r2
            out.append(((vb.x - wb * r2.y) - (va.x - wa * r1.y),
                        (vb.y + wb * r2.x) - (va.y + wa * r1.x)))
        return out

    def _pre_solve(self, arbiter: Any, space: Any, data: Any) -> None:
        raw, ba, bb = self._relative(arbiter)
        # pymunk starts a step from the impulse accumulated in the last one, applied scaled by
        # dt / previous dt ("warm starting"); on a first contact it keeps an impulse cached
        # from an earlier touch there without applying it. What the step applies is the
        # accumulator's growth from here plus the part applied at the start.
        carried = 0.0 if arbiter.is_first_contact else (
            space.current_time_step / self._last_dt if self._last_dt else 1.0)
        self._before[int(self._ffi.cast("uintptr_t", raw))] = [
            (ux, uy, raw.contacts[i].jnAcc * (1.0 - carried),
             raw.contacts[i].jtAcc * (1.0 - carried))
            for i, (ux, uy) in enumerate(self._velocities(raw, ba, bb))
        ]
        # A contact whose post_solve never comes (the user rejected it) must not linger.
        space.add_post_step_callback(self._end_step, self)
        user = self._user["pre_solve"]
        if user is not None:
            user[0](arbiter, space, user[1])

    def _end_step(self, space: Any, key: Any) -> None:
        self._before.clear()
        # Arbiters that carry impulses into the next step had contacts in this one, so this
        # is the 'previous dt' pymunk scales them by.
        self._last_dt = space.current_time_step

    def _post_solve(self, arbiter: Any, space: Any, data: Any) -> None:
        raw, ba, bb = self._relative(arbiter)
        before = self._before.pop(int(self._ffi.cast("uintptr_t", raw)), None)
        if before is not None and len(before) == raw.count:
            nx, ny = raw.n.x, raw.n.y
            work = 0.0
            for i, (ux1, uy1) in enumerate(self._velocities(raw, ba, bb)):
                ux0, uy0, jn0, jt0 = before[i]
                c = raw.contacts[i]
                jn, jt = c.jnAcc - jn0, c.jtAcc - jt0
                # Impulse on b: n jn + t jt with t = perp(n); -that on a.
                jx, jy = nx * jn - ny * jt, ny * jn + nx * jt
                work += 0.5 * (jx * (ux0 + ux1) + jy * (uy0 + uy1))
            self.total -= work
            self.steps += 1
        user = self._user["post_solve"]
        if user is not None:
            user[0](arbiter, space, user[1])
