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
``Space._handlers`` (checked to be pymunk's ``CollisionHandler``). Impulses and the
arbiter's bodies are read from pymunk's contact structs (``Arbiter._arbiter``, through
pymunk's own compiled declarations: the contact points' fields unpacked in one call from
their bytes, each field checked to be a double), the bodies' velocities and the step's time
stamp through Chipmunk's C getters (the space's struct is ``Space._space``, checked).
:class:`dumbbell.spaces.Ledger` counts the same contact heat per pair of bodies, with every
other source of energy.
"""

from __future__ import annotations

import warnings
from typing import Any

from ._heat_dispatch import DISPATCH, Dispatch

__all__ = ["HeatCounter"]

#: pymunk's compiled declarations and functions (``pymunk._chipmunk_cffi.ffi`` and ``lib``),
#: set by the first counter: pymunk is imported only when a counter is made.
_FFI: Any = None
_LIB: Any = None


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
        not looked at again at every contact."""
        self = cls.__new__(cls)
        self._start(space)
        DISPATCH[space].sealed = self._sealed = True
        return self

    def _start(self, space: Any) -> None:
        global _FFI, _LIB
        if _FFI is None:
            from pymunk._chipmunk_cffi import ffi, lib

            _FFI, _LIB = ffi, lib
            try:
                for count in (1, 2):  # Chipmunk's most contact points per arbiter: 2
                    _UNPACK[count] = _unpacker(count)
            except Exception:
                _FFI = None
                raise
        self.space = space
        self._total = 0.0
        self._steps = 0
        self._stopped: str | None = None
        # Keyed by the arbiter's pointer (pymunk's cdata: equal and hashed by address).
        self._before: dict[Any, list[tuple[float, float, float, float]]] = {}
        # The bodies (Chipmunk's pointers) of each arbiter counted in the step, and their
        # velocities at the solver's end (taken at the step's first post_solve, before any
        # program's).
        self._ends: dict[Any, tuple[Any, Any]] = {}
        self._after: dict[Any, tuple[float, float, float]] | None = None
        self._last_dt: float | None = None
        # The step of the last pre_solve (the space's time stamp) and, for that step, the
        # share of the impulses carried from the last one that pymunk applies at its start.
        self._stamp: int | None = None
        self._carried = 1.0
        self._cp_space = _cp_space(space)
        Dispatch.of(space, HeatCounter).add(self)

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

    def _dispatch(self) -> Dispatch | None:
        """The space's dispatcher (None for a copy, which has no space)."""
        space = self.__dict__.get("space")
        return None if space is None else DISPATCH.get(space)

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
        state["space"] = state["_cp_space"] = state["_stamp"] = None
        if state["_stopped"] is None:
            state["_stopped"] = "a copy: it does not count"
        return state

    def __deepcopy__(self, memo: dict[int, Any]) -> HeatCounter:
        # In a copy of its space (space.copy()), the copy's counter names the copied space.
        other = object.__new__(HeatCounter)
        other.__dict__.update(self.__getstate__())
        other.space = memo.get(id(self.space))
        return other

    def _pre_solve(self, arbiter: Any, space: Any) -> None:
        raw = arbiter._arbiter
        lib = _LIB
        stamp = lib.cpSpaceGetTimestamp(self._cp_space)
        if stamp != self._stamp:
            # The step's first contact.
            if self._after is not None or self._ends:
                # What the counter took of the last step, whose end (_end_step) was cut
                # short by an exception raised inside a callback (a stop signal's handler).
                self._forget()
            self._stamp = stamp
            # pymunk starts a step from the impulse accumulated in the last one, applied
            # scaled by dt / previous dt ("warm starting").
            self._carried = (space.current_time_step / self._last_dt if self._last_dt
                             else 1.0)
            # A contact whose post_solve never comes (the user rejected it) must not linger.
            space.add_post_step_callback(self._end_step, self)
        # The arbiter's bodies: a's and b's (its shapes in Chipmunk's order; pymunk's
        # Arbiter.shapes gives them swapped when ``raw.swapped``).
        ba, bb = raw.body_a, raw.body_b
        first = lib.cpArbiterIsFirstContact(raw)
        if first and (lib.cpShapeGetBody(raw.a) != ba or lib.cpShapeGetBody(raw.b) != bb):
            self._refuse("pymunk's arbiter does not hold its shapes' bodies where pymunk 7 "
                         "does")
            return
        # On a first contact pymunk keeps an impulse cached from an earlier touch there
        # without applying it. What the step applies is the accumulator's growth from here
        # plus the part applied at the start.
        kept = 1.0 - (0.0 if first else self._carried)
        v = lib.cpBodyGetVelocity(ba)
        vax, vay, wa = v.x, v.y, lib.cpBodyGetAngularVelocity(ba)
        v = lib.cpBodyGetVelocity(bb)
        vbx, vby, wb = v.x, v.y, lib.cpBodyGetAngularVelocity(bb)
        points = _points(raw)
        before = []
        for k in range(0, len(points), 6):
            r1x, r1y, r2x, r2y, jn, jt = points[k:k + 6]
            # The relative velocity at the point, and the impulses the step starts from.
            before.append(((vbx - wb * r2y) - (vax - wa * r1y),
                           (vby + wb * r2x) - (vay + wa * r1x),
                           jn * kept, jt * kept))
        # The bodies first: a stop signal raised between these two lines (its handler runs
        # inside this callback) leaves a pair whose post_solve counts nothing, never a
        # contact whose bodies the first post_solve's snapshot of velocities lacks.
        self._ends[raw] = (ba, bb)
        self._before[raw] = before

    def _refuse(self, why: str) -> None:
        """Stop counting (warning once) on a pymunk whose structs are not what this reads."""
        from ._memory import pymunk_version

        self._forget()
        self._stopped = f"pymunk {pymunk_version()}: {why}: contact heat is not counted"
        warnings.warn(f"dumbbell.spaces.HeatCounter stopped counting: {self._stopped}",
                      RuntimeWarning, stacklevel=2)

    def _forget(self) -> None:
        """Drop what the counter took of the step (its pairs and the solver's velocities)."""
        self._after = None
        self._before.clear()
        self._ends.clear()

    def _end_step(self, space: Any, key: Any) -> None:
        self._forget()
        self._stamp = None
        # Arbiters that carry impulses into the next step had contacts in this one, so this
        # is the 'previous dt' pymunk scales them by.
        self._last_dt = space.current_time_step

    def _post_solve(self, arbiter: Any, space: Any) -> None:
        raw = arbiter._arbiter
        before = self._before.pop(raw, None)
        after = self._after
        if after is None:
            # The step's first post_solve: every program's post_solve runs after it (the
            # counters run first in every handler), so these are the solver's velocities.
            lib, after = _LIB, {}
            for pair in self._ends.values():
                for b in pair:
                    if b not in after:
                        v = lib.cpBodyGetVelocity(b)
                        after[b] = (v.x, v.y, lib.cpBodyGetAngularVelocity(b))
            self._after = after
        if before is not None and len(before) == raw.count:
            # The bodies its pre_solve took (the arbiter's own, whichever way a handler
            # sees it): a pair with ``before`` has them.
            ba, bb = self._ends[raw]
            vax, vay, wa = after[ba]
            vbx, vby, wb = after[bb]
            n = raw.n
            nx, ny = n.x, n.y
            points = _points(raw)
            work = 0.0
            for i, (ux0, uy0, jn0, jt0) in enumerate(before):
                r1x, r1y, r2x, r2y, jn, jt = points[6 * i:6 * i + 6]
                ux1 = (vbx - wb * r2y) - (vax - wa * r1y)
                uy1 = (vby + wb * r2x) - (vay + wa * r1x)
                jn, jt = jn - jn0, jt - jt0
                # Impulse on b: n jn + t jt with t = perp(n); -that on a.
                jx, jy = nx * jn - ny * jt, ny * jn + nx * jt
                work += 0.5 * (jx * (ux0 + ux1) + jy * (uy0 + uy1))
            self._total -= work
            self._steps += 1


#: Per number of contact points: how to unpack their r1.x, r1.y, r2.x, r2.y, jnAcc, jtAcc
#: from an arbiter's array of ``cpContact`` (see :func:`_points`).
_UNPACK: dict[int, Any] = {}


def _points(raw: Any) -> tuple[float, ...]:
    """r1.x, r1.y, r2.x, r2.y, jnAcc and jtAcc of each of ``raw``'s contact points, unpacked
    in one call from the bytes of its ``cpContact`` array: the doubles the struct's fields
    read, where pymunk's compiled declarations place them."""
    count = raw.count
    unpack = _UNPACK.get(count)
    if unpack is None:
        unpack = _UNPACK[count] = _unpacker(count)
    return unpack.unpack_from(_FFI.buffer(raw.contacts, unpack.size)) if count else ()


def _unpacker(count: int) -> Any:
    """A ``struct.Struct`` reading the fields :func:`_points` gives from ``count`` contacts,
    laid out by pymunk's compiled declarations (each checked to be a double)."""
    import struct

    from ..errors import DumbbellError

    ffi = _FFI
    contact = ffi.typeof("struct cpContact")
    double = ffi.typeof("double")
    fields = [("r1", "x"), ("r1", "y"), ("r2", "x"), ("r2", "y"), ("jnAcc",), ("jtAcc",)]
    kinds = dict(contact.fields)
    vect = dict(kinds["r1"].type.fields)
    for field in fields:
        kind = kinds[field[0]].type if len(field) == 1 else vect[field[1]].type
        if kind != double or (len(field) == 2 and kinds[field[0]].type != kinds["r1"].type):
            raise DumbbellError(f"dumbbell.spaces.HeatCounter: pymunk's cpContact."
                                f"{'.'.join(field)} is not a double")
    offsets = [k * ffi.sizeof(contact) + ffi.offsetof(contact, *field)
               for k in range(count) for field in fields]
    fmt, at = "=", 0
    for offset in offsets:  # ascending: r1, r2 and the impulses are in this order
        if offset < at:
            raise DumbbellError("dumbbell.spaces.HeatCounter: pymunk's cpContact does not "
                                "hold r1, r2, jnAcc and jtAcc in this order")
        fmt += f"{offset - at}xd" if offset > at else "d"
        at = offset + 8
    return struct.Struct(fmt)


def _cp_space(space: Any) -> Any:
    """The space's Chipmunk struct (``Space._space``: pymunk 7 has no public getter for it),
    checked to be a ``cpSpace`` whose (integer) settings Chipmunk's getters read as pymunk's
    public ones do. The counters read only the step's time stamp from it, through Chipmunk's own
    getter."""
    from ..errors import DumbbellError

    ptr = getattr(space, "_space", None)
    lib = _LIB
    if not (isinstance(ptr, _FFI.CData) and _FFI.typeof(ptr) == _FFI.typeof("cpSpace *")
            and lib.cpSpaceGetIterations(ptr) == space.iterations
            and lib.cpSpaceGetCollisionPersistence(ptr) == space.collision_persistence):
        from ._memory import pymunk_version

        raise DumbbellError(f"dumbbell.spaces.HeatCounter: pymunk {pymunk_version()} does not "
                            "keep its space's Chipmunk struct where pymunk 7 does")
    return ptr
