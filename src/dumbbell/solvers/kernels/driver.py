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

from numba.core import config
from numba.extending import register_jitable

if config.DISABLE_JIT:
    # NUMBA_DISABLE_JIT=1 runs the loops as Python, where numba's two intrinsics below
    # cannot run ("<intrinsic to_fixed_tuple> is not usable in pure-python"): their
    # meaning, in Python. The floats are the same, so the runs give the same numbers.
    def to_fixed_tuple(array: Any, n: int) -> tuple[float, ...]:
        """The first ``n`` values of ``array`` as a tuple of floats."""
        return tuple(float(x) for x in array[:n])

    def tuple_setitem(tup: tuple[Any, ...], i: int, value: Any) -> tuple[Any, ...]:
        """``tup`` with item ``i`` replaced by ``value``."""
        return (*tup[:i], value, *tup[i + 1:])
else:
    from numba.cpython.unsafe.tuple import tuple_setitem
    from numba.np.unsafe.ndarray import to_fixed_tuple

from ..._install import njit
from ...errors import UsageError
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


def _layout(dimensions: int) -> tuple[int, tuple[int, ...], Callable[..., Any],
                                      Callable[..., Any]]:
    """For a state in ``dimensions``: its sampled size, where the heights and vertical
    velocities of A and B are, and the compiled check and sampling of it."""
    if dimensions == 1:
        return 4, (0, 1, 2, 3), _finite_1d, _keep_1d
    return 8, (1, 3, 5, 7), _finite_2d, _keep_2d


def _loop(kernel: Kernel, dimensions: int) -> Callable[..., Any]:
    if kernel.floor not in FLOOR_RULES:
        raise UsageError(f"kernel.floor = {kernel.floor!r}: must be one of "
                         f"{', '.join(FLOOR_RULES)}", param="kernel")
    step, start = _jitable(kernel.step), _jitable(kernel.start or _same)
    flip, locate = kernel.floor == "flip", kernel.floor == "locate"
    at_radius = kernel.through_at_radius
    n, vert, finite, keep = _layout(dimensions)
    fingerprint = _fingerprint(kernel.step, kernel.start or _same)

    @njit(cache=True, nogil=True)
    def loop(st, i, i_stop, p, every, out, j0, ev):  # pragma: no cover - compiled
        fingerprint  # noqa: B018 - part of the cache key (see the module docstring)
        s = start(to_fixed_tuple(st, n), p)
        n_ev = 0
        status = OK
        # A countdown to the next kept step: an integer modulo every step costs more than
        # the textbook's step.
        until_sample = every - i % every
        while i < i_stop:
            if locate:
                rem, count = p.dt, 0
                while status == OK:
                    s, h, body = step(s, p, rem)
                    if body < 0:
                        break
                    rem = rem - h
                    count += 1
                    # Placed on the floor where the step's own path meets it, so that
                    # rounding cannot leave it a hair below; its velocity reflected.
                    s, hit = _landed(s, body, p.e, vert)
                    n_ev = record(ev, n_ev, i * p.dt + (p.dt - rem), hit)
                    s = start(s, p)
                    if abs(hit[1]) < REST_SPEED or count > MAX_HITS:
                        status = REST
                if status != OK:
                    break  # at rest: the step is not counted
            else:
                if flip:
                    old = s
                    s = step(s, p)
                    s, first, second = _textbook(old, s, p, vert)
                else:
                    s, first, second = _at_end(step(s, p))
                n_ev = record(ev, n_ev, (i + 1) * p.dt, first)
                n_ev = record(ev, n_ev, (i + 1) * p.dt, second)
            i += 1
            status = _status(s, p, at_radius, vert) if finite(s) else BLOWUP
            until_sample -= 1
            if until_sample == 0:
                until_sample = every
                keep(out, i // every - j0, s)
            if status != OK or n_ev > ev.shape[0] - MAX_HITS - 4:
                break
        keep(st[:, None], 0, s)  # the state reached, for the next call
        return i, status, n_ev

    return loop


@register_jitable
def _textbook(old, s, p, vert):  # pragma: no cover - compiled
    """The textbook's rule after a step from ``old`` to ``s``: a particle below the floor
    that was not before has its vertical velocity reversed, times the elasticity; B first,
    as in its listing. ``vert``: where A's and B's heights and vertical velocities are in the
    state. Returns the state and the two impacts (B's, then A's; ``(-1.0, ...)`` where there
    is none)."""
    hA, vA, hB, vB = vert
    first = second = (-1.0, 0.0, 0.0)
    if p.floor and s[hB] < 0.0 and old[hB] >= 0.0:
        first = (1.0, s[vB], p.e * abs(s[vB]))
        s = tuple_setitem(s, vB, first[2])
    if p.floor and s[hA] < 0.0 and old[hA] >= 0.0:
        second = (0.0, s[vA], p.e * abs(s[vA]))
        s = tuple_setitem(s, vA, second[2])
    return s, first, second


@register_jitable
def _at_end(result):  # pragma: no cover - compiled
    """A step's state and its contacts at its end (``"end"`` rule) as the two impacts, A's
    then B's (``(-1.0, ...)`` where there is none)."""
    s, hits = result
    first = (0.0, hits[1], hits[2]) if hits[0] else (-1.0, 0.0, 0.0)
    second = (1.0, hits[4], hits[5]) if hits[3] else (-1.0, 0.0, 0.0)
    return s, first, second


@register_jitable
def _landed(s, body, e, vert):  # pragma: no cover - compiled
    """``s`` with ``body`` (0 A, 1 B) placed on the floor and its vertical velocity
    reflected, times the elasticity ``e``; and the impact (body, v_before, v_after)."""
    hA, vA, hB, vB = vert
    h, v = (hA, vA) if body == 0 else (hB, vB)
    v_in = s[v]
    v_out = e * abs(v_in) if v_in < 0.0 else v_in
    return tuple_setitem(tuple_setitem(s, h, 0.0), v, v_out), (float(body), v_in, v_out)


@register_jitable
def _status(s, p, at_radius, vert):  # pragma: no cover - compiled
    """TUNNEL_A or TUNNEL_B after a step when that particle is below the floor (by more than
    its radius if ``at_radius``) and still moving down, else OK."""
    hA, vA, hB, vB = vert
    if p.floor and s[hA] < (-p.rA if at_radius else 0.0) and s[vA] < 0.0:
        return TUNNEL_A
    if p.floor and s[hB] < (-p.rB if at_radius else 0.0) and s[vB] < 0.0:
        return TUNNEL_B
    return OK


@register_jitable
def _finite_1d(s):  # pragma: no cover - compiled
    """Whether no component of the 1D state passed :data:`BIG` (nor is NaN); each component
    named, so the state stays in registers."""
    return abs(s[0]) < BIG and abs(s[1]) < BIG and abs(s[2]) < BIG and abs(s[3]) < BIG


@register_jitable
def _finite_2d(s):  # pragma: no cover - compiled
    """:func:`_finite_1d` of the 2D state."""
    return (abs(s[0]) < BIG and abs(s[1]) < BIG and abs(s[2]) < BIG and abs(s[3]) < BIG
            and abs(s[4]) < BIG and abs(s[5]) < BIG and abs(s[6]) < BIG and abs(s[7]) < BIG)


@register_jitable
def _keep_1d(out, j, s):  # pragma: no cover - compiled
    """The 1D state as sample ``j`` of the columns ``out``."""
    out[0, j], out[1, j], out[2, j], out[3, j] = s[0], s[1], s[2], s[3]


@register_jitable
def _keep_2d(out, j, s):  # pragma: no cover - compiled
    """The 2D state as sample ``j`` of the columns ``out``."""
    out[0, j], out[1, j], out[2, j], out[3, j] = s[0], s[1], s[2], s[3]
    out[4, j], out[5, j], out[6, j], out[7, j] = s[4], s[5], s[6], s[7]


@register_jitable
def record(rows, n, t, hit):  # pragma: no cover - compiled
    """The impact ``hit`` = (body 0 A / 1 B, v_before, v_after in m/s; body -1: none) at
    ``t`` (s) as row ``n`` of the impact table ``rows``; returns the next free row."""
    if hit[0] < 0.0:
        return n
    rows[n, 0] = t
    rows[n, 1] = hit[0]
    rows[n, 2] = hit[1]
    rows[n, 3] = hit[2]
    return n + 1
