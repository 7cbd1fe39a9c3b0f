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

The counters of a space listen on its wildcard handler (``on_collision(None, None)``)
through one dispatcher (``pre_solve`` and ``post_solve``): callbacks already there are kept
and called after the counters with their own data, handlers the user sets for particular
collision types keep firing (their ``post_solve``, which pymunk calls before the wildcard
one, runs after the counters too: a velocity it sets is the program's, not a contact's
heat), and when the last counter detaches (in any order; dropping a
counter detaches it) the handler's callbacks and data are as they were (a wildcard handler
pymunk made for the counters stays, with no callbacks: pymunk offers no way to remove one).
Setting another wildcard ``pre_solve`` or ``post_solve`` afterwards stops the counters: each
warns once (a ``RuntimeWarning`` naming what stopped counting, at the next contact it would
have counted or when its count is read) and says so in ``stopped``. ``Space.copy()`` and
pickling work with counters attached; the copy has the callbacks the space had before
them, and no counter.

Everything is set through pymunk's public API (``Space.on_collision``, the handler's
``pre_solve``/``post_solve`` properties and its ``data`` dict) and nothing is stored on the
space; pymunk 7 has no public getter for a handler, so the wildcard one is read from
``Space._handlers`` (checked to be pymunk's ``CollisionHandler``). Impulses are read from
pymunk's contact structs (``Arbiter._arbiter``, through pymunk's own compiled declarations).
:class:`dumbbell.spaces.Ledger` counts the same contact heat per pair of bodies, with every
other source of energy.
"""

from __future__ import annotations

import warnings
import weakref
from typing import Any

__all__ = ["HeatCounter"]

_PHASES = ("pre_solve", "post_solve")
#: pymunk's compiled declarations (``pymunk._chipmunk_cffi.ffi``), set by the first counter:
#: pymunk is imported only when a counter is made.
_FFI: Any = None


class HeatCounter:
    """Attach to ``space``: ``total`` (J) is the heat its contacts dissipated since, ``steps``
    the contact-steps counted. ``detach()`` stops counting; ``stopped`` says why counting
    stopped (None while it counts). ``units`` names the space's units as the recorder takes
    them (its repr prints the total in them).

    Parameters
    ----------
    space : pymunk.Space
        The space to count.
    units : str or tuple of str or None, default None
        The space's units, as :func:`dumbbell.spaces.energy` takes them; the total's repr
        is in them.

    Raises
    ------
    UsageError
        A ``space`` that is not a pymunk Space, or units not allowed.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a ball dropped from 1 m onto a floor
    >>> space.gravity = (0.0, -9.8)
    >>> ball = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.1))
    >>> ball.position = (0.0, 1.0)
    >>> floor = pymunk.Segment(space.static_body, (-1.0, 0.0), (1.0, 0.0), 0.01)
    >>> ball_shape = pymunk.Circle(ball, 0.1)
    >>> ball_shape.elasticity, floor.elasticity = 0.5, 1.0     # a bounce that loses energy
    >>> space.add(ball, ball_shape, floor)
    >>> heat = spaces.HeatCounter(space)
    >>> for _ in range(1000):
    ...     space.step(1e-3)
    >>> heat.total > 0, heat.stopped                 # J, dissipated by the bounces
    (True, None)
    >>> heat.detach()
    """

    #: True for a counter made by :meth:`_on`: its space's dispatcher is sealed, so reading
    #: its counts needs no look (the pymunk solver reads ``total`` at every sample).
    _sealed = False

    def __init__(self, space: Any, units: Any = None) -> None:
        from ..model import args
        from .units import check_units

        args.space(space)
        self.units = check_units(units)
        self._start(space)

    @classmethod
    def _on(cls, space: Any) -> HeatCounter:
        """A counter on a space already checked and set up whole (the pymunk solver's own,
        its collision handlers all made): no program can replace its callbacks, so they are
        not looked at again at every contact (a third of a contact-rich run's time)."""
        self = cls.__new__(cls)
        self._start(space)
        _DISPATCH[space].sealed = self._sealed = True
        return self

    def _start(self, space: Any) -> None:
        global _FFI
        if _FFI is None:
            from pymunk._chipmunk_cffi import ffi

            _FFI = ffi
        self.space = space
        self._total = 0.0
        self._steps = 0
        self._stopped: str | None = None
        self._before: dict[int, list[tuple[float, float, float, float]]] = {}
        # The bodies of each arbiter counted in the step, and their velocities at the
        # solver's end (taken at the step's first post_solve, before any program's).
        self._ends: dict[int, tuple[Any, Any]] = {}
        self._after: dict[int, tuple[float, float, float]] | None = None
        self._last_dt: float | None = None
        _Dispatch.of(space).add(self)

    @property
    def total(self) -> float:
        """Heat the space's contacts dissipated since the counter attached (energy units)."""
        self._look()
        return self._total

    @property
    def steps(self) -> int:
        """Contact-steps counted."""
        self._look()
        return self._steps

    @property
    def stopped(self) -> str | None:
        """Why the counter stopped counting (None while it counts)."""
        self._look()
        return self._stopped

    def _dispatch(self) -> _Dispatch | None:
        """The space's dispatcher (None for a copy, which has no space)."""
        space = self.__dict__.get("space")
        return None if space is None else _DISPATCH.get(space)

    def _look(self) -> None:
        """Notice callbacks the program set over the counters' since they last ran."""
        if self._sealed:
            return
        d = self._dispatch()
        if d is not None and not d.sealed and self._stopped is None:
            d.check()

    @property
    def attached(self) -> bool:
        """True while the counter counts (False after ``detach()`` or once its callbacks
        were replaced)."""
        d = self._dispatch()
        return self.stopped is None and d is not None and self in d.counters

    def __repr__(self) -> str:
        from .._display import one_line
        from .units import UNNAMED, energy_unit

        state = "attached" if self.attached else (self.stopped or "not attached")
        unit = energy_unit(self.__dict__.get("units", UNNAMED))
        return one_line(f"HeatCounter({state}, total={self.total:.6g} {unit})")

    def detach(self) -> None:
        """Stop counting. When the space's last counter detaches, its wildcard callbacks are
        the ones it had before the first counter attached.


        """
        self._look()
        d = self._dispatch()
        if d is not None:
            d.remove(self)
        if self._stopped is None:
            self._stopped = "detached"

    def __del__(self) -> None:
        # A counter dropped without detach() leaves the handler as the others need it.
        try:
            if "space" in self.__dict__ and self._stopped is None:
                self.detach()
        except Exception:  # noqa: BLE001, S110 - never raise from a finalizer
            pass

    def __getstate__(self) -> dict[str, Any]:
        # A copy of a counter keeps its counts and does not count (no callbacks point to
        # it), and holds no space: a pickled space or state brings its own bodies, which a
        # second space would claim.
        state = dict(self.__dict__)
        state["_before"], state["_ends"], state["_after"] = {}, {}, None
        state["space"] = None
        if state["_stopped"] is None:
            state["_stopped"] = "a copy: it does not count"
        return state

    def __deepcopy__(self, memo: dict[int, Any]) -> HeatCounter:
        # In a copy of its space (space.copy()), the copy's counter names the copied space.
        other = object.__new__(HeatCounter)
        other.__dict__.update(self.__getstate__())
        other.space = memo.get(id(self.space))
        return other

    def _relative(self, arbiter: Any) -> tuple[Any, Any, Any]:
        raw = arbiter._arbiter
        shapes = arbiter.shapes
        a, b = (shapes[1], shapes[0]) if raw.swapped else shapes
        return raw, a.body, b.body

    @staticmethod
    def _velocities(raw: Any, ba: Any, bb: Any,
                    at: dict[int, tuple[float, float, float]] | None = None
                    ) -> list[tuple[float, float]]:
        """The relative velocity at each contact point of ``raw``: from the bodies' own
        velocities, or from those taken in ``at`` (by id)."""
        if at is None:
            (vax, vay), wa = ba.velocity, ba.angular_velocity
            (vbx, vby), wb = bb.velocity, bb.angular_velocity
        else:
            vax, vay, wa = at[id(ba)]
            vbx, vby, wb = at[id(bb)]
        out = []
        for i in range(raw.count):
            c = raw.contacts[i]
            r1, r2 = c.r1, c.r2
            out.append(((vbx - wb * r2.y) - (vax - wa * r1.y),
                        (vby + wb * r2.x) - (vay + wa * r1.x)))
        return out

    def _pre_solve(self, arbiter: Any, space: Any) -> None:
        if self._after is not None:
            # A post_solve ran and this step is another: the last one's end (_end_step) was
            # cut short by an exception raised inside a callback (a stop signal's handler).
            self._forget()
        raw, ba, bb = self._relative(arbiter)
        # pymunk starts a step from the impulse accumulated in the last one, applied scaled by
        # dt / previous dt ("warm starting"); on a first contact it keeps an impulse cached
        # from an earlier touch there without applying it. What the step applies is the
        # accumulator's growth from here plus the part applied at the start.
        carried = 0.0 if arbiter.is_first_contact else (
            space.current_time_step / self._last_dt if self._last_dt else 1.0)
        key = int(_FFI.cast("uintptr_t", raw))
        kept = 1.0 - carried
        contacts = raw.contacts
        before = []
        for i, (ux, uy) in enumerate(self._velocities(raw, ba, bb)):
            c = contacts[i]
            before.append((ux, uy, c.jnAcc * kept, c.jtAcc * kept))
        # The bodies first: a stop signal raised between these two lines (its handler runs
        # inside this callback) leaves a pair whose post_solve counts nothing, never a
        # contact whose bodies the first post_solve's snapshot of velocities lacks.
        self._ends[key] = (ba, bb)
        self._before[key] = before
        # A contact whose post_solve never comes (the user rejected it) must not linger.
        space.add_post_step_callback(self._end_step, self)

    def _forget(self) -> None:
        """Drop what the counter took of the step (its pairs and the solver's velocities)."""
        self._after = None
        self._before.clear()
        self._ends.clear()

    def _end_step(self, space: Any, key: Any) -> None:
        self._forget()
        # Arbiters that carry impulses into the next step had contacts in this one, so this
        # is the 'previous dt' pymunk scales them by.
        self._last_dt = space.current_time_step

    def _post_solve(self, arbiter: Any, space: Any) -> None:
        raw = arbiter._arbiter
        key = int(_FFI.cast("uintptr_t", raw))
        before = self._before.pop(key, None)
        if self._after is None:
            # The step's first post_solve: every program's post_solve runs after it (the
            # counters run first in every handler), so these are the solver's velocities.
            self._after = {id(b): (*b.velocity, b.angular_velocity)
                           for pair in self._ends.values() for b in pair}
        if before is not None and len(before) == raw.count:
            # The bodies its pre_solve took (the arbiter's own, whichever way a handler
            # sees it): a pair with ``before`` has them.
            ba, bb = self._ends[key]
            nx, ny = raw.n.x, raw.n.y
            contacts = raw.contacts
            work = 0.0
            for i, (ux1, uy1) in enumerate(self._velocities(raw, ba, bb, self._after)):
                ux0, uy0, jn0, jt0 = before[i]
                c = contacts[i]
                jn, jt = c.jnAcc - jn0, c.jtAcc - jt0
                # Impulse on b: n jn + t jt with t = perp(n); -that on a.
                jx, jy = nx * jn - ny * jt, ny * jn + nx * jt
                work += 0.5 * (jx * (ux0 + ux1) + jy * (uy0 + uy1))
            self._total -= work
            self._steps += 1


#: Each space's dispatcher (held weakly: the space keeps none of this).
_DISPATCH: weakref.WeakKeyDictionary[Any, _Dispatch] = weakref.WeakKeyDictionary()


def _same(value: Any) -> Any:
    return value


class _Phase:
    """The callback a space's wildcard handler calls for one phase: every counter, then
    the user's callback that was there before. Copied or pickled, it is that callback
    (or nothing): a copy of the space has no counter."""

    def __init__(self, dispatch: _Dispatch, phase: str, user: Any) -> None:
        self.dispatch = dispatch
        self.phase = phase
        self.method = f"_{phase}"  # the counters' method for the phase
        self.user = user

    def __call__(self, arbiter: Any, space: Any, data: Any) -> Any:
        if not self.dispatch.sealed:
            self.dispatch.check()
        for counter in self.dispatch.counters:
            if counter._stopped is None:
                getattr(counter, self.method)(arbiter, space)
        if self.user is not None:
            return self.user(arbiter, space, data)
        return None

    def __reduce__(self) -> tuple[Any, ...]:
        return (_same, (self.user,)) if self.user is not None else (type(None), ())


def _wildcard(space: Any) -> Any:
    """The space's wildcard collision handler, made if it has none (``on_collision``).
    pymunk 7 has no public getter for a handler: it is read from ``Space._handlers``,
    checked to be pymunk's ``CollisionHandler`` with the public properties used here."""
    from pymunk._collision_handler import CollisionHandler

    from ..errors import DumbbellError

    space.on_collision(None, None)
    handler = getattr(space, "_handlers", {}).get((None, None))
    if not isinstance(handler, CollisionHandler) or not isinstance(
            getattr(handler, "data", None), dict):
        from ._memory import pymunk_version

        raise DumbbellError(f"dumbbell.spaces.HeatCounter: pymunk {pymunk_version()} does not "
                            "keep its wildcard collision handler where pymunk 7 does")
    return handler


class _Dispatch:
    """The counters of one space and the wildcard handler they share. It holds the space
    and the counters weakly: the user's references keep the counters, dropping one detaches
    it, and no cycle runs through the space."""

    def __init__(self, space: Any) -> None:
        self._space = weakref.ref(space)
        self._counters: list[weakref.ref[HeatCounter]] = []
        #: True where the space's owner made every handler before the counter attached and
        #: replaces none (HeatCounter._on): check() is then never needed.
        self.sealed = False
        handler = _wildcard(space)
        # Weakly: the map of dispatchers holds them, and the handler holds its space.
        self._handler = weakref.ref(handler)
        self.phases = {phase: _Phase(self, phase, getattr(handler, phase))
                       for phase in _PHASES}
        # pymunk passes the handler's data for the phase: the user's, or None if none.
        self.no_data = [phase for phase in _PHASES if phase not in handler.data]
        for phase, callback in self.phases.items():
            handler.data.setdefault(phase, None)
            setattr(handler, phase, callback)  # the property: data stays the user's
        # The post_solve callbacks the program set for particular collision types, run
        # after the counters (see :meth:`wrap`).
        self.specific: list[tuple[weakref.ref[Any], _Phase]] = []
        self.wrap()

    def wrap(self) -> None:
        """Run the counters before every post_solve the program set for particular
        collision types (pymunk calls the most specific handler first, then the wildcard
        one): a callback there that changes a velocity is the program's, not a contact's
        heat. The handlers are read from ``Space._handlers``, as the wildcard one is."""
        space = self._space()
        if space is None:
            return
        for key, handler in list(getattr(space, "_handlers", {}).items()):
            user = getattr(handler, "post_solve", None)
            if key == (None, None) or user is None or isinstance(user, _Phase):
                continue
            phase = _Phase(self, "post_solve", user)
            self.specific.append((weakref.ref(handler), phase))
            handler.post_solve = phase

    @classmethod
    def of(cls, space: Any) -> _Dispatch:
        d = _DISPATCH.get(space)
        if d is None:
            d = _DISPATCH[space] = cls(space)
        return d

    @property
    def counters(self) -> list[HeatCounter]:
        """The counters attached, still alive."""
        return [c for c in (ref() for ref in self._counters) if c is not None]

    def add(self, counter: HeatCounter) -> None:
        self._counters.append(weakref.ref(counter))

    def remove(self, counter: HeatCounter) -> None:
        self._counters = [ref for ref in self._counters if ref() not in (None, counter)]
        if not self._counters:
            self.uninstall()

    def uninstall(self) -> None:
        """Put back the handler's callbacks and data as they were (phases the user
        replaced since stay theirs). Nothing is touched once the space is going: its
        handler lives in the C space, which pymunk may have freed already."""
        space, h = self._space(), self._handler()
        if space is None or h is None:
            return
        for phase, callback in self.phases.items():
            if getattr(h, phase) is callback:
                setattr(h, phase, callback.user)
                if phase in self.no_data:
                    h.data.pop(phase, None)
        for ref, callback in self.specific:
            handler = ref()
            if handler is not None and handler.post_solve is callback:
                handler.post_solve = callback.user
        self.specific = []
        if _DISPATCH.get(space) is self:
            del _DISPATCH[space]

    def check(self) -> None:
        """Stop the counters (each warning once) when the program set a wildcard
        ``pre_solve`` or ``post_solve`` over theirs."""
        handler = self._handler()
        if handler is None:
            return
        self.wrap()
        for phase, mine in self.phases.items():
            new = getattr(handler, phase)
            if new is mine:
                continue
            for counter in self.counters:
                if counter._stopped is None:
                    counter._stopped = (f"the space's wildcard {phase} callback was replaced "
                                        f"(by {getattr(new, '__name__', repr(new))}) after "
                                        f"{counter._steps} contact-steps: contact heat after "
                                        "that is not counted")
                    warnings.warn("dumbbell.spaces.HeatCounter stopped counting: "
                                  f"{counter._stopped}", RuntimeWarning, stacklevel=4)
