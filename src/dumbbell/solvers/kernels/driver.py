"""The one event driver of the stepping kernels: the loop around a solver's step.

:func:`advance` turns a :class:`~dumbbell.solvers.kernels.Kernel` into the compiled loop of
the kernel contract (see the package docstring): it applies the floor's flip for steps that
leave it to the driver, records impacts, samples every ``every``-th step, and stops at the step
where the state blows up or a particle is through the floor. What differs between solvers is
their step, and only their step; scipy's ``solve_ivp`` handles events once for every method
in the same way.

The loop is generated once per (kernel, dimensions) by closing over the step, which numba
inlines (a step takes and returns plain values: an array passed to it would cost reference
counting at every step), and cached on disk by numba (``cache=True``). numba keys a cached closure by a hash of
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

from numba import njit
from numba.cpython.unsafe.tuple import tuple_setitem
from numba.extending import register_jitable
from numba.np.unsafe.ndarray import to_fixed_tuple

from . import BIG, BLOWUP, FLOOR_RULES, MAX_HITS, OK, REST, REST_SPEED, TUNNEL_A, TUNNEL_B, Kernel

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
        _JITABLE[fn] = register_jitable(inline="always")(fn)
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
    if kernel.floor not in FLOOR_RULES:
        raise ValueError(f"Kernel.floor = {kernel.floor!r}: must be one of {FLOOR_RULES}")
    step = _jitable(kernel.step)
    start = _jitable(kernel.start or _same)
    flip, end = kernel.floor == "flip", kernel.floor == "end"
    at_radius = kernel.through_at_radius
    one = dimensions == 1
    n = 4 if one else 8
    hA, vA, hB, vB = (0, 1, 2, 3) if one else (1, 3, 5, 7)
    fingerprint = _fingerprint(kernel.step, kernel.start or _same)

    @njit(cache=True, nogil=True)
    def loop(st, i, i_stop, p, every, out, j0, ev):  # pragma: no cover - compiled
        fingerprint  # noqa: B018 - part of the cache key (see the module docstring)
        s = start(to_fixed_tuple(st, n), p)
        dt, e, floor = p.dt, p.e, p.floor
        dA = p.rA if at_radius else 0.0
        dB = p.rB if at_radius else 0.0
        n_ev = 0
        status = OK
        # A countdown to the next kept step: an integer modulo every step costs more than
        # the textbook's step.
        until_sample = every - i % every
        while i < i_stop:
            if flip:
                old = s
                s = step(s, p)
                if floor:
                    # The textbook's rule, B first as in its listing.
                    t = (i + 1) * dt
                    if s[hB] < 0.0 and old[hB] >= 0.0:
                        s, n_ev = _flip(s, vB, 1.0, e, t, ev, n_ev)
                    if s[hA] < 0.0 and old[hA] >= 0.0:
                        s, n_ev = _flip(s, vA, 0.0, e, t, ev, n_ev)
            elif end:
                s, hits = step(s, p)
                t = (i + 1) * dt
                if hits[0]:
                    n_ev = record(ev, n_ev, t, 0.0, hits[1], hits[2])
                if hits[3]:
                    n_ev = record(ev, n_ev, t, 1.0, hits[4], hits[5])
            else:
                rem = dt
                count = 0
                while True:
                    s, h, body = step(s, p, rem)
                    if body < 0:
                        break
                    rem = rem - h
                    count += 1
                    # Placed on the floor where the step's own path meets it, so that
                    # rounding cannot leave it a hair below; its velocity reflected.
                    v_in = s[vA] if body == 0 else s[vB]
                    v_out = e * abs(v_in) if v_in < 0.0 else v_in
                    n_ev = record(ev, n_ev, i * dt + (dt - rem), body, v_in, v_out)
                    if body == 0:
                        s = start(tuple_setitem(tuple_setitem(s, hA, 0.0), vA, v_out), p)
                    else:
                        s = start(tuple_setitem(tuple_setitem(s, hB, 0.0), vB, v_out), p)
                    if abs(v_in) < REST_SPEED or count > MAX_HITS:
                        status = REST
                        break
                if status != OK:
                    break  # at rest: the step is not counted
            i += 1
            if floor:
                if s[hB] < -dB and s[vB] < 0.0:
                    status = TUNNEL_B
                if s[hA] < -dA and s[vA] < 0.0:
                    status = TUNNEL_A
            # Each component named (not indexed in a loop), so the state stays in registers.
            if not (_finite(s) if one else _finite_2d(s)):
                status = BLOWUP
            until_sample -= 1
            if until_sample == 0:
                until_sample = every
                j = i // every - j0
                if one:
                    _keep(out, j, s)
                else:
                    _keep_2d(out, j, s)
            if status != OK or n_ev > ev.shape[0] - MAX_HITS - 4:
                break
        for c in range(n):
            st[c] = s[c]
        return i, status, n_ev

    return loop


@njit(cache=True, nogil=True)
def _finite(s):  # pragma: no cover - compiled
    """Whether the 1D state's four components are below :data:`BIG` in size (not NaN)."""
    return abs(s[0]) < BIG and abs(s[1]) < BIG and abs(s[2]) < BIG and abs(s[3]) < BIG


@njit(cache=True, nogil=True)
def _finite_2d(s):  # pragma: no cover - compiled
    """Whether the 2D state's eight components are below :data:`BIG` in size (not NaN)."""
    return (abs(s[0]) < BIG and abs(s[1]) < BIG and abs(s[2]) < BIG and abs(s[3]) < BIG
            and abs(s[4]) < BIG and abs(s[5]) < BIG and abs(s[6]) < BIG and abs(s[7]) < BIG)


@njit(cache=True, nogil=True)
def _keep(out, j, s):  # pragma: no cover - compiled
    """The 1D state as sample ``j`` of the columns ``out``."""
    out[0, j] = s[0]
    out[1, j] = s[1]
    out[2, j] = s[2]
    out[3, j] = s[3]


@njit(cache=True, nogil=True)
def _keep_2d(out, j, s):  # pragma: no cover - compiled
    """The 2D state as sample ``j`` of the columns ``out``."""
    out[0, j] = s[0]
    out[1, j] = s[1]
    out[2, j] = s[2]
    out[3, j] = s[3]
    out[4, j] = s[4]
    out[5, j] = s[5]
    out[6, j] = s[6]
    out[7, j] = s[7]


@njit(cache=True, nogil=True)
def record(rows, n, t, body, before, after):  # pragma: no cover - compiled
    """Row ``n`` of the impact table ``rows``: ``body`` (0 A, 1 B) met the floor at ``t``
    (s) with vertical velocity ``before`` and left with ``after`` (m/s); returns ``n + 1``."""
    rows[n, 0] = t
    rows[n, 1] = body
    rows[n, 2] = before
    rows[n, 3] = after
    return n + 1


@njit(cache=True, nogil=True)
def _flip(s, v, body, e, t, ev, n_ev):  # pragma: no cover - compiled
    """``s`` with its velocity component ``v`` reversed and scaled by ``e`` (the floor's
    elasticity), the impact of ``body`` recorded as row ``n_ev`` of ``ev`` at ``t`` (s);
    and the next free row."""
    after = e * abs(s[v])
    return tuple_setitem(s, v, after), record(ev, n_ev, t, body, s[v], after)
