"""The one event driver of the stepping kernels: the loop around a solver's step.

:func:`advance` turns a :class:`~dumbbell.solvers.kernels.Kernel` into the compiled loop of
the kernel contract (see the package docstring): it applies the floor's flip for steps that
leave it to the driver, records impacts, samples every ``every``-th step, and stops at the step
where the state blows up or a particle is through the floor. What differs between solvers is
their step, and only their step; scipy's ``solve_ivp`` handles events once for every method
in the same way.

The loop is generated once per (kernel, dimensions) by closing over the step, which numba
inlines, and cached on disk by numba (``cache=True``). numba keys a cached closure by a hash of
what it closes over: the step is pickled by reference (module and name), so the key also holds
a fingerprint of the files of the step and this driver, and an edited step compiles afresh.
"""

from __future__ import annotations

import hashlib
import inspect
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit
from numba.cpython.unsafe.tuple import tuple_setitem
from numba.extending import register_jitable
from numba.np.unsafe.ndarray import to_fixed_tuple

from . import BIG, BLOWUP, OK, TUNNEL_A, TUNNEL_B, Kernel

#: Impacts one step may record (Verlet's located impacts: at most 65 in one step).
HITS = 72

#: (kernel, dimensions) -> its compiled loop.
_LOOPS: dict[tuple[Kernel, int], Callable[..., Any]] = {}
#: Functions registered with numba (each once).
_JITABLE: dict[Any, Callable[..., Any]] = {}


def advance(kernel: Kernel, dimensions: int) -> Callable[..., Any]:
    """The compiled loop of ``kernel`` for scenes of ``dimensions`` (1 or 2)."""
    key = (kernel, dimensions)
    if key not in _LOOPS:
        _LOOPS[key] = _loop(kernel, dimensions)
    return _LOOPS[key]


def _same(s: Any, p: Any) -> Any:  # pragma: no cover - compiled
    return s


def _jitable(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` (a plain function, or a numba dispatcher's Python function) registered so that
    compiled code can call it."""
    fn = getattr(fn, "py_func", fn)
    if fn not in _JITABLE:
        _JITABLE[fn] = register_jitable(fn)
    return _JITABLE[fn]


def _fingerprint(*functions: Callable[..., Any]) -> str:
    """A hash of the source files of ``functions`` and of this module (of a function's own
    code where its file cannot be read)."""
    digest = hashlib.sha256()
    for fn in (*functions, advance):
        module = sys.modules.get(getattr(fn, "__module__", ""), None)
        try:
            path = inspect.getsourcefile(module) if module is not None else None
            digest.update(Path(path).read_bytes() if path else b"")
        except (OSError, TypeError):
            path = None
        if path is None:
            digest.update(getattr(getattr(fn, "__code__", None), "co_code", repr(fn).encode()))
    return digest.hexdigest()


def _loop(kernel: Kernel, dimensions: int) -> Callable[..., Any]:
    step = _jitable(kernel.step)
    start = _jitable(kernel.start or _same)
    own = kernel.finds_impacts
    at_radius = kernel.through_at_radius
    n = 4 if dimensions == 1 else 8
    hA, vA, hB, vB = (0, 1, 2, 3) if dimensions == 1 else (1, 3, 5, 7)
    fingerprint = _fingerprint(kernel.step, kernel.start or _same)

    @njit(cache=True, nogil=True)
    def loop(st, i, i_stop, p, every, out, j0, ev):  # pragma: no cover - compiled
        fingerprint  # noqa: B018 - part of the cache key (see the module docstring)
        s = start(to_fixed_tuple(st, n), p)
        dt, e, floor = p.dt, p.e, p.floor
        dA = p.rA if at_radius else 0.0
        dB = p.rB if at_radius else 0.0
        hits = np.empty((HITS, 4))
        n_ev = 0
        status = OK
        # A countdown to the next kept step: an integer modulo every step costs more than
        # the textbook's step.
        until_sample = every - i % every
        while i < i_stop:
            if own:
                s, n_hits, status = step(s, p, i, hits)
                for h in range(n_hits):
                    for c in range(4):
                        ev[n_ev, c] = hits[h, c]
                    n_ev += 1
                if status != OK:
                    break
                i += 1
            else:
                old = s
                s = step(s, p)
                i += 1
                if floor:
                    # The textbook's rule, B first as in its listing.
                    t = i * dt
                    if s[hB] < 0.0 and old[hB] >= 0.0:
                        s, n_ev = _flip(s, vB, 1.0, e, t, ev, n_ev)
                    if s[hA] < 0.0 and old[hA] >= 0.0:
                        s, n_ev = _flip(s, vA, 0.0, e, t, ev, n_ev)
            if floor:
                if s[hB] < -dB and s[vB] < 0.0:
                    status = TUNNEL_B
                if s[hA] < -dA and s[vA] < 0.0:
                    status = TUNNEL_A
            for c in range(n):
                if not abs(s[c]) < BIG:
                    status = BLOWUP
            until_sample -= 1
            if until_sample == 0:
                until_sample = every
                j = i // every - j0
                for c in range(n):
                    out[c, j] = s[c]
            if status != OK or n_ev > ev.shape[0] - HITS - 2:
                break
        for c in range(n):
            st[c] = s[c]
        return i, status, n_ev

    return loop


@register_jitable
def record(rows, n, t, body, before, after):  # pragma: no cover - compiled
    """Row ``n`` of the impact table ``rows``: ``body`` (0 A, 1 B) met the floor at ``t``
    (s) with vertical velocity ``before`` and left with ``after`` (m/s); returns ``n + 1``."""
    rows[n, 0] = t
    rows[n, 1] = body
    rows[n, 2] = before
    rows[n, 3] = after
    return n + 1


@register_jitable
def _flip(s, v, body, e, t, ev, n_ev):  # pragma: no cover - compiled
    """``s`` with its velocity component ``v`` reversed and scaled by ``e`` (the floor's
    elasticity), the impact of ``body`` recorded as row ``n_ev`` of ``ev`` at ``t`` (s);
    and the next free row."""
    after = e * abs(s[v])
    return tuple_setitem(s, v, after), record(ev, n_ev, t, body, s[v], after)
