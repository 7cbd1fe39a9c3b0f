"""The dispatcher of :mod:`.heat`'s counters: one per space, on its wildcard collision
handler (``pre_solve`` and ``post_solve``), calling every counter and then the callbacks the
program had set there, running the counters before the program's post_solve of handlers for
particular collision types, putting the handler back as it was when the last counter detaches,
and stopping the counters (each warning once) when the program sets another wildcard callback
over theirs. The counters are held weakly, as is the space."""

from __future__ import annotations

import warnings
import weakref
from typing import Any

__all__: list[str] = []

_PHASES = ("pre_solve", "post_solve")


#: Each space's dispatcher (held weakly: the space keeps none of this).
DISPATCH: weakref.WeakKeyDictionary[Any, Dispatch] = weakref.WeakKeyDictionary()


def _same(value: Any) -> Any:
    return value


class _Phase:
    """The callback a space's wildcard handler calls for one phase: every counter, then
    the user's callback that was there before (``typed``: the post_solve of a handler for
    particular collision types, see :meth:`Dispatch.wrap`). Copied or pickled, it is that
    callback (or nothing): a copy of the space has no counter."""

    def __init__(self, dispatch: Dispatch, phase: str, user: Any, typed: bool = False) -> None:
        self.dispatch = dispatch
        self.phase = phase
        self.method = getattr(dispatch.kind, f"_{phase}")  # the counters' method for the phase
        self.user = user
        self.typed = typed
        # The wildcard post_solve, which pymunk calls right after a typed one for the same
        # arbiter.
        self.wild_post = phase == "post_solve" and not typed

    def __call__(self, arbiter: Any, space: Any, data: Any) -> Any:
        dispatch = self.dispatch
        if not dispatch.sealed:
            dispatch.check()
        run = True
        if self.wild_post:
            counted, dispatch.counted = dispatch.counted, None
            # Counted already in the arbiter's typed post_solve (where nothing is left for
            # the counters: their pre_solve's record of it is gone).
            run = counted is None or counted != arbiter._arbiter
        elif not self.typed:
            dispatch.counted = None  # a pre_solve: the step's post_solves are to come
        if run:
            method = self.method
            for ref in dispatch.refs:
                counter = ref()
                if counter is not None and counter._stopped is None:
                    method(counter, arbiter, space)
            if self.typed:
                dispatch.counted = arbiter._arbiter
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


class Dispatch:
    """The counters of one space and the wildcard handler they share. It holds the space
    and the counters weakly: the user's references keep the counters, dropping one detaches
    it, and no cycle runs through the space."""

    def __init__(self, space: Any, kind: type) -> None:
        self._space = weakref.ref(space)
        #: The counters' class (:class:`.heat.HeatCounter`), whose methods the phases call.
        self.kind = kind
        #: The arbiter (pointer) the counters last counted in a typed post_solve, until the
        #: wildcard post_solve that follows it or the next pre_solve.
        self.counted: Any = None
        #: The counters, weakly, in the order they attached.
        self.refs: tuple[weakref.ref[Any], ...] = ()
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
        # What the last look saw: how many handlers the space had, and each typed one with
        # its post_solve (so that a look finding the same costs no scan).
        self._known = -1
        self._typed: list[tuple[weakref.ref[Any], Any]] = []
        self.wrap()

    def wrap(self) -> None:
        """Run the counters before every post_solve the program set for particular
        collision types (pymunk calls the most specific handler first, then the wildcard
        one): a callback there that changes a velocity is the program's, not a contact's
        heat. The handlers are read from ``Space._handlers``, as the wildcard one is; the
        space is scanned again only when it has a new handler or a typed handler's
        post_solve is not the one the last scan left (pymunk never removes a handler)."""
        space = self._space()
        if space is None:
            return
        handlers = getattr(space, "_handlers", {})
        if len(handlers) == self._known:
            for ref, seen in self._typed:
                handler = ref()
                if handler is not None and handler.post_solve is not seen:
                    break
            else:
                return
        self._known = len(handlers)
        typed = []
        for key, handler in list(handlers.items()):
            if key == (None, None):
                continue
            user = getattr(handler, "post_solve", None)
            if user is not None and not isinstance(user, _Phase):
                phase = _Phase(self, "post_solve", user, typed=True)
                self.specific.append((weakref.ref(handler), phase))
                handler.post_solve = user = phase
            typed.append((weakref.ref(handler), user))
        self._typed = typed

    @classmethod
    def of(cls, space: Any, kind: type) -> Dispatch:
        d = DISPATCH.get(space)
        if d is None:
            d = DISPATCH[space] = cls(space, kind)
        return d

    @property
    def counters(self) -> list[Any]:
        """The counters attached, still alive."""
        return [c for c in (ref() for ref in self.refs) if c is not None]

    def add(self, counter: Any) -> None:
        # A new tuple, never changed in place: a callback going through it is not disturbed.
        self.refs = (*self.refs, weakref.ref(counter))

    def remove(self, counter: Any) -> None:
        self.refs = tuple(ref for ref in self.refs if ref() not in (None, counter))
        if not self.refs:
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
        if DISPATCH.get(space) is self:
            del DISPATCH[space]

    def check(self) -> None:
        """Stop the counters (each warning once) when the program set a wildcard
        ``pre_solve`` or ``post_solve`` over theirs."""
        handler = self._handler()
        if handler is None:
            return
        self.wrap()
        phases = self.phases
        if (handler.pre_solve is phases["pre_solve"]
                and handler.post_solve is phases["post_solve"]):
            return
        for phase, mine in phases.items():
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
