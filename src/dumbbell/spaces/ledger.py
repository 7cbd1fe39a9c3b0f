"""An energy ledger for any pymunk space: E(t) + heat + work_out - work_in = E(0), with
every term measured step by step and named by its source.

How a pymunk step moves energy (Munk2D's ``cpSpaceStep``): positions move first with the
velocities plus the contacts' bias velocities (``p += (v + v_bias) dt``); collisions are found
(collision ``begin`` and ``pre_solve`` callbacks); each constraint is prepared (its
``pre_solve`` first; a ``DampedSpring`` or ``DampedRotarySpring`` applies its spring impulse
there); velocities are integrated (``v = v d + (g + f/m) dt`` with d = ``space.damping **
dt``, or the body's own ``velocity_func``); then the contacts' and joints' impulses, the
cached ones first, then ``iterations`` passes; then the constraints' ``post_solve`` and the
collisions' ``post_solve`` callbacks; then, in pymunk, the adds and removes asked for from
callbacks and the post-step callbacks.

The ledger hooks into every step three times (:mod:`._hook`; the calls: :mod:`._counting`):
before the constraints are prepared (velocities v0, positions after the move, applied
forces), after the solver (velocities v1, every impulse the step applied: :mod:`._physics`,
:mod:`._contacts`, which does the contacts' share for a batch of steps at once), and at the
end of the step (what callbacks changed after the solver). It reads bodies, joints and
contacts in bulk from pymunk's C structs (:mod:`._memory`), and rebuilds what it reads when
the space changes (:mod:`._inventory`). The terms:

- ``contact`` (one per pair of bodies): the work of its impulses; heat when negative
  (inelastic impacts, friction), energy put in when positive (a surface velocity, ...);
- ``correction``: the energy the contacts' position correction gives by pushing overlapping
  shapes apart (gravity's part per pair, the springs' and fields' part as one term);
- ``constraint``: the work of each joint's impulses on the bodies' relative motion: a stop
  or limit reached (``SlideJoint`` snapping taut, ``RotaryLimitJoint``, ``RatchetJoint``), a
  finite ``max_force`` slipping, ``max_bias``/``error_bias`` correcting a drift, a
  ``SimpleMotor`` driving; a rigid joint's share is the step's error and tends to 0 with dt;
- ``spring damping``: what a spring's damping takes out;
- ``kinematic``: what a kinematic body (or the fixed spin of a body of infinite moment) does
  through the joints and contacts it drives;
- ``damping``: what ``space.damping`` takes out; ``force``: the work of ``Body.force``;
- ``step error``: the integrator's own error on each conservative force (gravity, each
  spring, each declared field): what its kick added minus what its potential lost over the
  move. For gravity it is exactly 1/2 dt g . (P1 - P0) per step (P the momentum), so it
  adds up to 1/2 dt g . (P(t) - P(0)) at a fixed dt: bounded while the momentum is;
- ``velocity_func``: the kick of a custom velocity function and the move it causes; with a
  declared potential (:meth:`Ledger.declare_potential`) it is the field's step error,
  without one the body is named in ``unaccounted`` and ``complete`` is False;
- ``program``: what the program changed between steps (velocities or positions set,
  impulses applied, settings changed; a collision ``begin`` or ``pre_solve`` callback
  cannot be told from it): measured, named per body, and ``complete`` is False;
  ``entered``/``left``: bodies added or removed, with their energy;
- ``unattributed``: what changed inside the step that no source explains: an impulse a
  constraint's ``pre_solve`` callback applies, a velocity or position a ``post_solve``
  callback (constraint or collision) or an earlier post-step callback sets: named per body,
  ``complete`` is False; ``rounding``: what the sums round off.

``E`` counts the dynamic bodies as :func:`dumbbell.spaces.energy` does, plus the declared
fields' potential. ``closure`` = E(t) - E(0) - the sum of all terms is the ledger's own error
(rounding). ``complete`` is True only when nothing is named in ``unaccounted`` (the sources
above that say so, beyond ``tolerance`` times the energy ``scale``) and the closure is within
``tolerance`` of the scale: the largest of the kinetic energy and of the change of each
potential (gravity, springs, fields) from its start, over the steps seen. The potentials'
zero is arbitrary (pixel spaces put U_g near -1e8), so |E(0)| is no scale; but below the
energies' own last bits (``Balance.rounding``) nothing is measurable, and a closure or a
term within them is rounding whatever the scale (a pile at rest).
"""

from __future__ import annotations

import math
import warnings
import weakref
from collections.abc import Callable
from typing import Any

from . import _layout as layout
from . import _memory as mem
from . import _physics as phys
from . import _public
from ._counting import Counting, inside
from ._inventory import Names, Pairs, declared
from ._records import Before
from ._terms import Sums, pair_terms
from .balance import Balance, Term, notes, order
from .units import check_units, energy_unit

__all__ = ["Ledger"]  # Balance and Term: balance.py


def _warn_fallback(why: str) -> None:
    """Say once per process that the ledger counts with pymunk's public API only."""
    if _FALLBACK_SAID:
        return
    _FALLBACK_SAID.append(why)
    warnings.warn(f"dumbbell.spaces.Ledger: pymunk {mem.pymunk_version()}'s structs are not "
                  f"laid out as the ledger reads them ({why}); it counts with pymunk's public "
                  "API only: the joints' and contacts' work as one lumped term", RuntimeWarning,
                  stacklevel=3)


_FALLBACK_SAID: list[str] = []


def _layout_problem(space: Any) -> str | None:
    """Why the ledger cannot read this space's structs (None when it can)."""
    why = layout.problem()
    if why is not None:
        return why
    try:
        layout.check_space(space)
        for b in space.bodies:
            layout.check_body(b)
        for c in space.constraints:
            if mem.struct_of(c) is not None:
                layout.check_constraint(c)
    except mem.LayoutError as e:
        return str(e)
    return None


class Ledger(Counting):
    """Attach an energy ledger to ``space``: every later ``space.step`` (whoever calls it)
    is counted while the ledger is referenced (dropping it detaches it), and
    :meth:`balance` gives the account so far.

    ``tolerance`` (relative to the energy scale) is what ``complete`` allows for the closure
    and for anything unattributed or changed by the program. ``units`` names the space's
    units as the recorder takes them (the length unit alone, 'px', or (length, mass, time));
    energies are printed in them (J in SI; "energy units" when not named). See the module docstring for the terms. A copy
    or a pickle of a ledger holds its account so far and does not count; a copy of the
    space has no ledger attached.

    Parameters
    ----------
    space : pymunk.Space
        The space to count.
    tolerance : float, default 1e-6
        What ``complete`` allows, relative to the energy scale.
    units : str or tuple of str or None, default None
        The space's units, as :func:`dumbbell.spaces.energy` takes them; the balance prints
        its energies in them.

    Raises
    ------
    UsageError
        An argument that is not allowed, or a space being stepped or not finite.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a box sliding to a stop on a rough floor
    >>> space.gravity = (0.0, -9.8)
    >>> floor = pymunk.Segment(space.static_body, (-5.0, 0.0), (5.0, 0.0), 0.0)
    >>> box = pymunk.Body(1.0, pymunk.moment_for_box(1.0, (0.2, 0.1)))
    >>> box.position, box.velocity = (0.0, 0.05), (2.0, 0.0)     # m, m/s: 2 J to lose
    >>> shape = pymunk.Poly.create_box(box, (0.2, 0.1))
    >>> shape.friction = floor.friction = 1.0          # pymunk multiplies them
    >>> space.add(box, shape, floor)
    >>> ledger = spaces.Ledger(space, units="m")      # counts every later space.step
    >>> for _ in range(100):
    ...     space.step(0.005)
    >>> balance = ledger.balance()
    >>> balance.complete, balance.steps, round(balance.by_kind()["contact"], 3)   # J: all 2
    (True, 100, -2.0)
    >>> ledger.detach()
    """

    def __new__(cls, space: Any = None, *args: Any, **kwargs: Any) -> Ledger:  # noqa: PYI034
        if cls is Ledger:
            from ..model import args as check

            why = _layout_problem(check.space(space))
            if why is not None:
                _warn_fallback(why)
                return super().__new__(PublicLedger)
        return super().__new__(cls)

    def __init__(self, space: Any, tolerance: float = 1e-6, units: Any = None) -> None:
        from ..model import args

        self.space = args.space(space)
        self.tolerance = args.real(tolerance, "tolerance", "-")
        self.units = check_units(units)
        self.unit = energy_unit(self.units)
        self._refuse_now(space)
        self._names = Names(space)
        self._potentials: list[tuple[Any, Callable[..., Any], str]] = []
        self._sums = Sums()
        self._unaccounted: dict[str, str] = {}
        self._pairs = Pairs()
        self.steps = 0
        self.t = 0.0
        self._worst = 0.0
        self._error: str | None = None
        self._bad: str | None = None
        self._frozen: Balance | None = None
        self._before: Before | None = None
        self._awaiting_end = False
        self._quiet_end = False
        self._dt_prev = float(space.current_time_step)
        # A space made with pymunk.Space(threaded=True): the most threads a counted step ran on.
        self._threaded = bool(getattr(space, "threaded", False))
        self._threads = 1
        self._attach()

    def _refuse_now(self, space: Any) -> None:
        """Refuse a space being stepped, or whose state or settings are not finite."""
        from pymunk._chipmunk_cffi import lib

        from ..errors import UsageError
        from ._refusals import check_finite
        from .accounting import energy

        if lib.cpSpaceIsLocked(space._space):
            raise UsageError("space: attach the ledger between steps, not from a callback",
                             param="space")
        check_finite(space)
        energy(space)  # refuses settings that are not finite and energies past the floats

    def _attach(self) -> None:
        from . import _hook
        from ._contacts import Contacts, arbiters_address

        self._space_at = layout.check_space(self.space)
        self._contacts = Contacts(arbiters_address(self._space_at))
        self._rebuild()
        _public.start(self)
        self._hook = _hook.Hook(self.space, *_calls(self), first=True)
        self._finalizer = weakref.finalize(self, self._hook.release)

    # -- public ------------------------------------------------------------------------

    @property
    def attached(self) -> bool:
        """True while the ledger is counting."""
        return self._hook is not None and self._error is None

    def detach(self) -> None:
        """Stop counting and take the hook out of the space: its constraints are back in
        the order they had. :meth:`balance` keeps the account up to here. Inside a step (a
        callback), it stops counting at once and the hook is taken out after the step.


        """
        hook = self.__dict__.get("_hook")
        if hook is None:
            return
        self._sync()
        self._hook = None
        self._finalizer.detach()
        hook.release()

    def declare_potential(self, target: Any, potential: Callable[..., Any],
                          name: str | None = None) -> None:
        """Declare the potential of a field that a custom ``velocity_func`` applies.

        ``target``: a body, a list of bodies, or a velocity function (every body that uses
        it, bodies added later included). ``potential(x, y, m)`` returns the field's
        potential energy of bodies of mass ``m`` whose centres of gravity are at ``x``,
        ``y``. It is called with numpy arrays: write it with numpy, e.g. ``lambda x, y, m:
        -GM * m / np.hypot(x - 300, y - 300)``. Declare it before the first step the ledger
        counts: the field's energy joins E from E(0) on, and each step's kicks count as the
        field's step error instead of unaccounted work. ``name`` labels its term (at most
        60 printable characters).

        Parameters
        ----------
        target : pymunk.Body or list of pymunk.Body or callable
            The bodies, or a velocity function (every body that uses it).
        potential : callable
            ``potential(x, y, m)``: the field's potential energy, numpy in and out.
        name : str or None, default None
            The term's label.

        Raises
        ------
        UsageError
            A target, potential or name that is not allowed, or a declaration after the first step
            counted.

        Examples
        --------
        >>> import pymunk
        >>> from dumbbell import spaces
        >>> def spring_to_origin(body, gravity, damping, dt):     # a field F = -k m r, k = 4 /s²
        ...     pymunk.Body.update_velocity(body, -4.0 * body.position, damping, dt)
        >>> space = pymunk.Space()
        >>> body = pymunk.Body(1, 1)
        >>> body.position, body.velocity = (1, 0), (0, 1)
        >>> body.velocity_func = spring_to_origin
        >>> space.add(body, pymunk.Circle(body, 0.1))
        >>> ledger = spaces.Ledger(space)
        >>> ledger.declare_potential(spring_to_origin, lambda x, y, m: 2.0 * m * (x**2 + y**2),
        ...                          name="harmonic field")
        >>> for _ in range(200):
        ...     space.step(0.005)
        >>> ledger.balance().complete
        True
        """
        from ..errors import UsageError

        if self._frozen is not None:
            raise UsageError("a copy of a Ledger does not count: attach a new Ledger",
                             param="potential")
        key, label = declared(target, potential, name, self.steps, self._names)
        self._sync()
        self._sums.fold(self._b, self._scale, self._floor)
        self._potentials.append((key, potential, label))
        try:
            self._rebuild()
            self._snap = self._remap(self._snap)
        except phys.FieldError as e:
            from ..errors import UsageError

            self._potentials.pop()
            self._rebuild()
            self._snap = self._remap(self._snap)
            raise UsageError(f"potential: {e}", param="potential") from None
        after = phys.energy(self._b, self._snap)
        self._E0 += after.E - self._E
        self._Uref[2] = after.Ud
        self._E = after.E

    def __repr__(self) -> str:
        # What the ledger holds already: no accounting is run to show it.
        from .._display import one_line

        state = "attached" if self.attached else (
            "a copy, not counting" if self._frozen is not None else "detached")
        return one_line(f"Ledger({state}, steps={self.steps}, t={self.t:.6g} {self.units[2]}, "
                        f"E0={self._E0:.6g} {self.unit}, E={self._E:.6g} {self.unit}; "
                        "balance() for the terms)")

    def balance(self) -> Balance:
        """The account from attaching until now (what the program changed since the last
        step counts as ``program``). Raises a :class:`~dumbbell.errors.DumbbellError` naming
        the body once the space's state stopped being finite.

        Returns
        -------
        Balance
            The account, frozen.

        Raises
        ------
        DumbbellError
            The space's state stopped being finite (naming the body).
        """
        if self._frozen is not None:
            return self._frozen
        if self._bad is not None:
            from ..errors import DumbbellError

            raise DumbbellError(self._bad)
        self._flush()
        self._sync()
        self._sums.fold(self._b, self._scale, self._floor)
        u = self.unit
        terms = [Term(src, kind, val, self._sums.notes.get((src, kind), ""), u)
                 for (src, kind), val in self._sums.terms.items() if val != 0.0]
        terms += [Term(*fields, u) for fields in pair_terms(self._pairs, self._names.labels)]
        total = math.fsum(t.energy for t in terms)
        unacc = {**self._unaccounted, **self._b.current}
        if self._error is not None:
            unacc["ledger"] = self._error
        limit = max(self.tolerance * self._scale, self._floor)
        for t in terms:
            if t.kind == "unattributed" and abs(t.energy) > limit:
                unacc.setdefault(t.source, inside(self._threads))
            elif t.kind == "program" and abs(t.energy) > limit:
                unacc.setdefault(t.source, "changed by the program between steps (a velocity, "
                                 "position, impulse or setting; or a collision's begin, "
                                 "pre_solve or separate callback)")
        return Balance(E0=self._E0, E=self._E, terms=tuple(sorted(terms, key=order)),
                       closure=self._E - self._E0 - total,
                       worst_step=self._worst / self._scale if self._scale > 0 else 0.0,
                       scale=self._scale, tolerance=self.tolerance,
                       unaccounted=tuple(sorted(unacc.items())), steps=self.steps, t=self.t,
                       notes=notes(terms, self._scale, u), unit=u, time_unit=self.units[2],
                       rounding=self._floor)

    # -- copies ------------------------------------------------------------------------

    def _copy(self, space: Any) -> Ledger:
        """A ledger holding this one's account so far, which does not count."""
        try:
            frozen = self.balance()
            bad = None
        except Exception as e:  # noqa: BLE001 - a stopped ledger's copy keeps why
            frozen, bad = None, str(e)
        other = object.__new__(Ledger)
        other.__dict__.update(space=space, tolerance=self.tolerance, units=self.units,
                              unit=self.unit, steps=self.steps, t=self.t, _E0=self._E0,
                              _E=self._E, _hook=None, _error=None, _bad=bad, _frozen=frozen)
        if frozen is None:
            other._frozen = None
        return other

    def __copy__(self) -> Ledger:
        return self._copy(self.space)

    def __deepcopy__(self, memo: dict[int, Any]) -> Ledger:
        # In a copy of its space (space.copy()), the copy's ledger names the copied space;
        # copied alone, the original (the copy does not count: it only names it).
        return self._copy(memo.get(id(self.space), self.space))

    def __reduce__(self) -> tuple[Any, ...]:
        # Pickled, it holds its account and no space: a pickled space or state brings its
        # own bodies, which a second space would claim.
        state = dict(self._copy(None).__dict__)
        return (_restored, (state,))

def _calls(ledger: Ledger) -> tuple[Callable[[], None], ...]:
    """The hook's three calls into ``ledger``, holding it weakly: the user's reference
    keeps the ledger, and dropping it takes the hook out (a finalizer), with no cycle left
    through the space."""
    me = weakref.ref(ledger)

    def call(name: str) -> Callable[[], None]:
        def run() -> None:
            target = me()
            if target is not None:
                target._call(name)

        return run

    return call("_pre"), call("_post"), call("_end")


def _restored(state: dict[str, Any]) -> Ledger:
    """A ledger unpickled: its account, not counting."""
    other = object.__new__(Ledger)
    other.__dict__.update(state)
    return other


class PublicLedger(Ledger):
    """:class:`Ledger` through pymunk's public API only, on a build whose structs it cannot
    read (see :mod:`._public`)."""

    def _attach(self) -> None:
        _public.attach(self, _calls(self))

    def _rebuild(self) -> None:
        _public.rebuild(self)

    def declare_potential(self, target: Any, potential: Callable[..., Any],
                          name: str | None = None) -> None:
        from ..errors import UsageError

        raise UsageError("potential: declared potentials need the ledger's reads of pymunk's "
                         "structs, which this pymunk build does not allow (see the warning "
                         "given when the ledger attached)", param="potential")

    def _pre(self) -> None:
        _public.pre(self)

    def _post(self) -> None:
        _public.post(self)

    def _end(self) -> None:
        super()._end()
        _public.end(self)
