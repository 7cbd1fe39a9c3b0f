"""The ledger's hook into a pymunk space: a constraint that applies nothing and calls the
ledger twice in every step (before the constraints are prepared, after the solver), plus a
post-step callback at the end of each step.

Why the hook is written through Chipmunk's C API (and what that writes):

- The hook must be called in every step whoever calls ``space.step``, and before any spring
  applies its impulse (Munk2D prepares each constraint in the order of the space's C array,
  calling its ``preSolve`` first). The only per-step calls pymunk offers are callbacks: a
  constraint's ``pre_solve``/``post_solve``, collision handlers (only when shapes touch),
  post-step callbacks (one step only, registered from inside a step) and a body's velocity
  or position function (taken from the program).
- A pymunk ``Constraint`` added with ``space.add`` would be one of ``space.constraints``:
  programs iterate that (pymunk's own tests assert its contents, drawing code draws it,
  ``space.copy()`` would copy it and ``space.remove(*space.constraints)`` take it away).
  So the hook is a ``cpSimpleMotor`` between two bodies of its own (not the space's static
  body, which pymunk creates lazily), added with ``cpSpaceAddConstraint`` (Chipmunk's public
  C API, through pymunk's compiled module): pymunk's Python lists never see it.
- No public call puts a constraint first in the space's C array: ``cpSpaceAddConstraint``
  appends it, and removing and adding the others would wake every sleeping body they join.
  So :func:`_rotate` rewrites the array's order (the one write into pymunk's C state): the
  hook first on attaching, last before removing it (``cpSpaceRemoveConstraint`` moves the
  last constraint into the hole), so that the others keep their order, which is the
  solver's. On a build whose layout is not validated the hook is appended and never
  rotated (:mod:`._public`).

Lifetime, so that nothing a program does with a ledger ends the process:

- the hook holds the space's C struct (``space._space``) until the hook is out of it, so
  pymunk cannot free the space while the hook is in it (pymunk's own free function removes
  every constraint it finds, and would find a freed one);
- it is taken out only when the space is not inside ``cpSpaceStep`` (``cpSpaceIsLocked``):
  from a callback, it is disarmed at once and taken out by a post-step callback
  (``space.add_post_step_callback``, the public route);
- it is taken out when the ledger is dropped (a ``weakref.finalize`` on the ledger: a copy
  of a ledger owns no hook), when the space is collected (a ``weakref.finalize`` on the
  space, which runs before pymunk frees the C space, in a reference cycle too), and at
  interpreter exit; each of these is idempotent, whichever comes first.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from functools import cache
from typing import Any

from . import _memory as mem

#: Hooks that could not be taken out (a space freed while locked: never seen); kept so that
#: their memory outlives any space that may still list them.
_KEPT: list[Any] = []


def addresses(space: Any) -> set[int]:
    """Addresses of the hooks now in ``space``."""
    return mem.hooks(space)


class Hook:
    """A hidden constraint in ``space`` calling ``before()`` before the constraints are
    prepared and ``after()`` after the solver, and ``end()`` after the step (from a
    post-step callback) in every step, until :meth:`release`. ``first``: put it first in the
    space's constraint array (the layout is validated) or leave it last."""

    def __init__(self, space: Any, before: Callable[[], None], after: Callable[[], None],
                 end: Callable[[], None], first: bool) -> None:
        from pymunk._chipmunk_cffi import ffi, lib

        self._ffi, self._lib = ffi, lib
        self._calls: tuple[Callable[[], None], ...] | None = (before, after, end)
        self._space = weakref.ref(space)
        self._cspace = space._space  # kept allocated while the hook is in it
        self._first = first
        self._a = ffi.gc(lib.cpBodyNew(1.0, 1.0), lib.cpBodyFree)
        self._b = ffi.gc(lib.cpBodyNew(1.0, 1.0), lib.cpBodyFree)
        self._c = ffi.gc(lib.cpSimpleMotorNew(self._a, self._b, 0.0), lib.cpConstraintFree)
        lib.cpConstraintSetMaxForce(self._c, 0.0)  # it applies nothing
        # Two C callbacks for every hook (one closure each per process, not per hook): the
        # constraint's user data leads them to this hook.
        self._handle = ffi.new_handle(self)
        lib.cpConstraintSetUserData(self._c, self._handle)
        pre, post = _callbacks()
        lib.cpConstraintSetPreSolveFunc(self._c, pre)
        lib.cpConstraintSetPostSolveFunc(self._c, post)
        self.at = int(ffi.cast("uintptr_t", self._c))
        lib.cpSpaceAddConstraint(self._cspace, self._c)
        self.inside = True
        mem._hooks().setdefault(space, set()).add(self.at)
        if first:
            _rotate(self._cspace, self.at, first=True)
        self._on_space = weakref.finalize(space, self.release, True)

    @property
    def armed(self) -> bool:
        return self._calls is not None

    def locked(self) -> bool:
        """True while the space is inside ``cpSpaceStep`` (callbacks run)."""
        return self._cspace is not None and bool(self._lib.cpSpaceIsLocked(self._cspace))

    def _on_pre(self) -> None:
        if self._calls is not None:
            self._calls[0]()

    def _on_post(self) -> None:
        if self._calls is None:
            return
        self._calls[1]()
        owner = self._space()
        if owner is not None:
            owner.add_post_step_callback(_end_of_step, self)

    def end(self) -> None:
        if self._calls is not None:
            self._calls[2]()

    def release(self, final: bool = False) -> None:
        """Stop calling and take the hook out of the space: now if the space is not inside
        a step, else from a post-step callback. A hook that was not put first is taken out
        only while it is last (else ``cpSpaceRemoveConstraint`` would move the space's last
        constraint into its place): otherwise it stays, disarmed, until the space goes
        (``final``). Idempotent."""
        self._calls = None
        if not self.inside:
            return
        lib = self._lib
        if not (self._first or final or self._last()):
            return
        if lib.cpSpaceIsLocked(self._cspace):
            space = self._space()
            if space is not None:
                space.add_post_step_callback(_release_after_step, (self, "release"))
            else:  # a space collected inside its own step: cannot happen; never free it
                _KEPT.append(self)
            return
        if self._first:
            _rotate(self._cspace, self.at, first=False)
        lib.cpSpaceRemoveConstraint(self._cspace, self._c)
        self.inside = False
        space = self._space()
        if space is not None:
            mem._hooks().get(space, set()).discard(self.at)
        self._on_space.detach()
        self._cspace = None


    def order(self) -> list[int]:
        """The addresses of the space's constraints in its C array's order (the solver's),
        this hook's among them (through Chipmunk's iterator, its public C API)."""
        ffi, lib = self._ffi, self._lib
        items: list[Any] = []
        lib.cpSpaceEachConstraint(self._cspace, lib.ext_cpSpaceConstraintIteratorFunc,
                                  ffi.new_handle(items))
        return [int(ffi.cast("uintptr_t", item)) for item in items]

    def _last(self) -> bool:
        """The hook is the last constraint of the space."""
        order = self.order()
        return bool(order) and order[-1] == self.at

    def to_last(self) -> None:
        """Put a hook that was added last (``first`` False) last again, between steps:
        removing a constraint moves the space's last one into its place
        (``cpSpaceRemoveConstraint``), and a program removing its own puts the hook there.
        Taken out, the space's last constraint takes the hook's place, where a space without
        the hook has it; added again, the hook is appended (Chipmunk's public C API)."""
        if self._first or not self.inside or self.locked() or self._last():
            return
        self._lib.cpSpaceRemoveConstraint(self._cspace, self._c)
        self._lib.cpSpaceAddConstraint(self._cspace, self._c)


@cache
def _callbacks() -> tuple[Any, Any]:
    """The C pre- and post-solve callbacks every hook shares."""
    from pymunk._chipmunk_cffi import ffi, lib

    def pre(constraint: Any, space: Any) -> None:
        ffi.from_handle(lib.cpConstraintGetUserData(constraint))._on_pre()

    def post(constraint: Any, space: Any) -> None:
        ffi.from_handle(lib.cpConstraintGetUserData(constraint))._on_post()

    return (ffi.callback("cpConstraintPreSolveFunc", pre),
            ffi.callback("cpConstraintPostSolveFunc", post))


def _end_of_step(space: Any, hook: Hook) -> None:
    hook.end()


def _release_after_step(space: Any, key: tuple[Hook, str]) -> None:
    key[0].release()


def _rotate(cspace: Any, at: int, first: bool) -> None:
    """Rotate the space's C constraint array so that the constraint at ``at`` is first (or
    last, to be removed), keeping every other constraint in its order (the solver's).

    The one write into pymunk's C state: no public call orders the array (see the module
    docstring). The array is the space's ``constraints`` field, past ``dt``, which
    :func:`._memory.check_space` validated before the ledger attached; its items are
    written through pymunk's compiled declaration of ``cpArray``."""
    pffi = mem._pymunk_ffi()
    arr = pffi.cast("cpArray *", mem.view("space", mem.address(cspace)).constraints)
    items = mem.array_items(mem.address(arr)).tolist()
    if at not in items:
        return
    items.remove(at)
    items = [at, *items] if first else [*items, at]
    ptrs = arr.arr
    for i, item in enumerate(items):
        ptrs[i] = pffi.cast("void *", item)
