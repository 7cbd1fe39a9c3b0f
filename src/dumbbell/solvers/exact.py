"""``exact``: the piecewise-analytic 1D solution (and, in :mod:`.exact_rigid`, the rigid 2D
dumbbell's closed-form flight).

Between impacts the centre of mass falls freely, ``X(t) = X0 + V0 t - g t^2/2``, and the
stretch ``s = xA - xB - b`` is a harmonic oscillator with ``w = sqrt(k/mu)``. Impacts are the
first roots of a particle's height, found by a search that cannot miss one: on an interval of
length h the height dips at most ``C h^2/8`` below its chord, with
``C = g + (m_other/M) w^2 S`` bounding its curvature (S the oscillation's amplitude), so an
interval is either cleared, split, or known to hold one crossing that Brent's method refines
to about 1e-14 s. That is the precision of one impact: the chaotic map amplifies rounding
about tenfold per impact, so late impacts are known less well. Grazing impacts are found by
the splitting. Positions and velocities are then evaluated in closed form at the sample
times, all of them in one pass.

The search and the sampling are compiled with numba (:mod:`.kernels.exact`, loaded on the
first run), and give the floats of the same arithmetic evaluated in Python and numpy, with
scipy's ``brentq``, bit for bit.

A particle that comes to rest on an inelastic floor would bounce infinitely often in finite
time; the run stops there with the verdict ``failed`` and says so.
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._install import compiling
from ..model.scene import Scene
from ..model.trajectory import Impact, Trajectory, Verdict
from . import base
from ._closed_form import MIN_SPLIT, REST_SPEED, ROOT_XTOL, at_rest, search_failed
from .base import RunOptions, SearchBudget, Truth, check_impacts, impact_budget_reason
from .verdicts import RawRun, conclude

#: No public names: the class is ``dumbbell.solvers.METHODS[name]``.
__all__: list[str] = []

NAME = "exact"
#: The state columns, in the order the sampling kernel writes them.
_COLUMNS = ("xA", "vA", "xB", "vB")


@dataclass(frozen=True)
class Segment:
    """Free motion from time ``t0`` (s): centre of mass X0 (m), V0 (m/s); stretch s0 (m) and
    its rate sd0 (m/s)."""

    t0: float
    X0: float
    V0: float
    s0: float
    sd0: float


def _motion(scene: Scene) -> Any:
    """The scalars of the closed-form motion, as the kernels read them
    (:class:`~dumbbell.solvers.kernels.exact.Motion`)."""
    from .kernels.exact import Motion

    system = scene.system
    w = float(system.omega)
    return Motion(float(system.g), w, w**2, float(system.B.mass / system.M),
                  float(system.A.mass / system.M), float(system.b),
                  float(system.floor.elasticity) if system.floor is not None else 1.0,
                  ROOT_XTOL, MIN_SPLIT, REST_SPEED)


@functools.cache
def _kernels(rigid: bool = False) -> Any:
    """The compiled kernels (:mod:`~dumbbell.solvers.kernels.exact`) of the 1D solution, or
    with ``rigid`` of the rigid dumbbell's flight (:mod:`.exact_rigid`), compiled or loaded
    from numba's cache on the first call in a process by a small run of each."""
    from .kernels import exact as kernels

    if rigid:  # an end falling onto the floor, then sampled
        end = kernels.End(0.1, 1.0, 0.0, 0.0, 9.8, 1.0)
        kernels.end_contact(end, (0.0, 1.0, 0.05), (9.9, 0.1, ROOT_XTOL, MIN_SPLIT),
                            (np.array([0.0, math.inf]), 10))
        kernels.rigid_sample(np.zeros((1, 7)), np.linspace(0.0, 1.0, 3), 0.1, -0.1, 9.8)
        return kernels
    m = kernels.Motion(9.8, 63.0, 3969.0, 0.5, 0.5, 0.2, 1.0, ROOT_XTOL, MIN_SPLIT, REST_SPEED)
    segs = kernels.impacts(np.array([0.0, 1.1, 0.0, 0.0, 0.0]), m, (1.0, 10, 10**6, 10), True)[0]
    kernels.sample(segs, np.linspace(0.0, 1.0, 3), m)
    return kernels


def warm_up() -> float:
    """Compile (or load from numba's cache) the impact searches and the samplings, 1D and
    rigid, once per process; returns the seconds it took (about 0 once done)."""
    t0 = time.perf_counter()
    _kernels()
    _kernels(rigid=True)
    return time.perf_counter() - t0


def supports(scene: Scene) -> str | None:
    """None if this solver can run ``scene``, else why not."""
    if scene.system.dimensions != 1:
        if scene.system.rigid is not None:
            from .exact_rigid import supports as rigid_supports

            return rigid_supports(scene)
        return ("the exact solution covers 1D scenes and the rigid 2D dumbbell; use the "
                "reference solver for a 2D spring")
    return scene.system.resting_contact()


def segments(scene: Scene, t_end: float) -> tuple[list[Segment], list[Impact], Verdict]:
    """The free-flight segments up to ``t_end`` (s), the impacts between them, and a verdict:
    ``failed`` when a particle comes to rest or the run reaches its work budget
    (:data:`~dumbbell.solvers.base.MAX_IMPACTS` impacts, :data:`~.base.MAX_SEARCH_WORK`
    units of impact search)."""
    rows, events, verdict = _segments(scene, t_end)
    return [Segment(*row) for row in rows.tolist()], events, verdict


def _segments(scene: Scene, t_end: float) -> tuple[np.ndarray, list[Impact], Verdict]:
    """:func:`segments`, the segments as rows (t0, X0, V0, s0, sd0) of an array."""
    kernels = _kernels()
    m = _motion(scene)
    A, B, floor = scene.system.A, scene.system.B, scene.system.floor
    mA_M, mB_M = m.cB, m.cA
    first = np.array([0.0, mA_M * A.height + mB_M * B.height, mA_M * A.vy + mB_M * B.vy,
                      A.height - B.height - m.b, A.vy - B.vy], dtype=np.float64)
    limit, work_limit = base.MAX_IMPACTS, base.MAX_SEARCH_WORK

    def search(blocks: list[np.ndarray], events: list[Impact]
               ) -> tuple[list[np.ndarray], list[Impact], Verdict]:
        rows, hits, status, rest, work = kernels.impacts(
            first, m, (float(t_end), int(limit), int(work_limit), int(base.BLOCK_WORK)),
            floor is not None)
        blocks.append(rows)
        events += [Impact(t, "AB"[int(body)], v, after) for t, body, v, after in hits.tolist()]
        if status == kernels.REST:
            return blocks, events, at_rest("AB"[int(rest[1])], float(rest[0]), float(rest[2]))
        if status == kernels.IMPACT_LIMIT:
            return blocks, events, Verdict("failed", float(rows[-1, 0]),
                                           impact_budget_reason(limit))
        if status == kernels.OVER_BUDGET:
            SearchBudget(work_limit).spend(int(work))  # raises OverBudget, with its reason
        if status == kernels.ROOT_FAILED:
            raise search_failed(float(rows[-1, 0]))
        return blocks, events, Verdict()

    blocks, events, verdict = base.within_budget(search, lambda rows: float(rows[-1, 0]))
    return blocks[0], events, verdict


def vertical_energy(scene: Scene) -> float:
    """The scene's energy at t = 0 that can move the centre of mass vertically (J): every
    term but the horizontal motion (none in 1D; constant on a frictionless floor in 2D)."""
    from ..model.energy import gravity_potential, spring_potential, translational_ke

    system = scene.system
    if system.rigid is not None:
        from .exact_rigid import vertical_energy as rigid_energy

        return rigid_energy(scene)
    A, B, g = system.A, system.B, system.g
    return float(translational_ke(A.mass, 0.0, A.vy) + translational_ke(B.mass, 0.0, B.vy)
                 + gravity_potential(A.mass, 0.0, -g, 0.0, A.height)
                 + gravity_potential(B.mass, 0.0, -g, 0.0, B.height)
                 + spring_potential(system.k, A.height - B.height, system.b))


def check_work(scene: Scene, options: RunOptions) -> None:
    """UsageError before any work when the run must locate more impacts than
    :data:`~dumbbell.solvers.base.MAX_IMPACTS` (:func:`~.base.check_impacts`)."""
    check_impacts(scene, options, vertical_energy(scene), base.MAX_IMPACTS)


def solve(scene: Scene, options: RunOptions) -> Trajectory:
    """Evaluate the exact solution at the sample times ``i * every * dt`` (s)."""
    check_work(scene, options)
    if scene.system.rigid is not None:
        return _solve_rigid(scene, options)
    with compiling("the exact solution's kernels", options.quiet):
        kernels = _kernels()  # compiled or loaded before the clock starts
    t0 = time.perf_counter()
    rows, events, verdict = _segments(scene, options.t_end)
    t = options.sample_times()
    if not verdict.ok:
        t = t[t <= verdict.t]
    out = kernels.sample(rows, t, _motion(scene))
    cols = {name: out[c] for c, name in enumerate(_COLUMNS)}
    wall = time.perf_counter() - t0
    return conclude(Exact, scene, options, RawRun(t, cols, events, verdict, wall,
                                                  {"segments": len(rows), "root_xtol": ROOT_XTOL}))


def _solve_rigid(scene: Scene, options: RunOptions) -> Trajectory:
    """The rigid 2D dumbbell in closed form (:mod:`.exact_rigid`) at the sample times (s)."""
    from ..model.energy import rigid_moment
    from .exact_rigid import flight, sample

    with compiling("the exact solution's kernels", options.quiet):
        _kernels(rigid=True)  # compiled or loaded before the clock starts
    t0 = time.perf_counter()
    segs, events, verdict = flight(scene, options.t_end)
    t = options.sample_times()
    if not verdict.ok:
        t = t[t <= verdict.t]
    cols = sample(scene, segs, t)
    wall = time.perf_counter() - t0
    return conclude(Exact, scene, options, RawRun(t, cols, events, verdict, wall,
                                                  {"segments": len(segs), "root_xtol": ROOT_XTOL,
                                                   "moment": rigid_moment(scene)}))


class Exact(Truth):
    """The closed-form 1D solution with impacts found by root search (see the module
    docstring)."""

    name = NAME
    relative_cost = 0.01
    estimates_error = False
    _supports = staticmethod(supports)
    _solve = staticmethod(solve)
    _check_work = staticmethod(check_work)
    warm_up = staticmethod(warm_up)

    @staticmethod
    def _truth_for(scene: Scene) -> bool:
        """The truth for 1D scenes and the rigid 2D dumbbell."""
        return scene.system.dimensions == 1 or scene.system.rigid is not None
