"""How far a run is from the truth: each measure defined once, used by compare and bench.

Positions (m):

- :func:`coordinate_error`: at each sample both runs have, the largest |difference| of any
  position coordinate of either particle (a series; ``compare`` reports its largest value in
  the window and when it first passes 1 mm);
- :func:`position_error`: over the samples in [0, window], the largest distance between a
  particle and its true position, sqrt(dx^2 + dy^2) (one number; ``bench`` reports it). In 1D
  both are the same; in 2D the distance is up to sqrt(2) times the coordinate difference.

Impacts: :func:`impact_time_error`, the largest |t_i - t_i(truth)| (s), impacts paired in order.

Energy (dimensionless):

- :func:`energy_spread`: (max E - min E) / |E(0)| over the whole run, the width of the band E
  stays in (``compare``);
- :func:`energy_error`: the largest relative drift |E - E(0)| / scale over the whole run, or
  for a dissipative scene the largest distance from the truth's E at the same times
  (``bench``). A run whose E swings symmetrically about E(0) has a spread about twice its
  error.

Every measure needs the two runs sampled at the same times (the first samples of both): a
run with other sample times is an error, not silently compared sample by sample.
"""

from __future__ import annotations

import math

import numpy as np

from ..model.energy import BOOKKEEPING, energy_scale, relative_energy_error
from ..model.scene import Scene
from ..model.trajectory import Trajectory


def _check_shared_times(run: Trajectory, truth: Trajectory, n: int) -> None:
    # Sample times built as step * every * dt by different (dt, every) agree to rounding only.
    if not np.allclose(run.t[:n], truth.t[:n], rtol=1e-9, atol=0.0):
        raise ValueError(f"{run.solver} and {truth.solver} do not share their sample times")


def position_columns(scene: Scene) -> list[str]:
    """The position columns of a scene (m)."""
    return ["xA", "xB"] if scene.system.dimensions == 1 else ["xA", "yA", "xB", "yB"]


def coordinate_error(run: Trajectory, truth: Trajectory) -> np.ndarray:
    """Largest |position coordinate difference| of either particle at each sample both runs
    have (m): as long as the shorter run."""
    n = min(len(run.t), len(truth.t))
    _check_shared_times(run, truth, n)
    return np.max([np.abs(run[c][:n] - truth[c][:n]) for c in position_columns(run.scene)],
                  axis=0)


def energy_spread(traj: Trajectory) -> float:
    """(max E - min E) / |E(0)| over the whole run (dimensionless)."""
    E = traj["E"]
    if not len(E):
        return math.nan
    scale = abs(float(E[0])) or 1.0
    return float((np.max(E) - np.min(E)) / scale)


def position_error(traj: Trajectory, truth: Trajectory, window: float) -> float:
    """Largest distance |r - r_truth| of either particle over the samples in [0, window] (m);
    inf if the run stopped before the window ended. Both must share their sample times."""
    n = int(np.searchsorted(truth.t, window * (1 + 1e-12), side="right"))
    if len(traj.t) < n:
        return math.inf
    _check_shared_times(traj, truth, n)
    worst = 0.0
    for body in "AB":
        cols = [c for c in (f"x{body}", f"y{body}") if c in traj.state]
        sq = sum((traj.state[c][:n] - truth.state[c][:n]) ** 2 for c in cols)
        worst = max(worst, float(np.sqrt(np.max(sq))))
    return worst


def impact_time_error(traj: Trajectory, truth: Trajectory, window: float
                      ) -> tuple[float, int, int]:
    """(largest |t_i - t_i(truth)| in s, impacts compared, truth's impacts in [0, window]).

    Impacts are paired in order; inf if the solver's sequence misses one or names another
    body before the window ends."""
    wanted = [e for e in truth.events if e.t <= window]
    worst, compared = 0.0, 0
    for mine, true in zip(traj.events, wanted):
        if mine.body != true.body:
            return math.inf, compared, len(wanted)
        worst = max(worst, abs(mine.t - true.t))
        compared += 1
    if compared < len(wanted):
        return math.inf, compared, len(wanted)
    return (worst if compared else math.nan), compared, len(wanted)


def energy_error(traj: Trajectory, truth: Trajectory | None) -> float:
    """Largest relative energy error over the whole run: drift from E(0), or for a
    dissipative scene the distance from the truth's E at the same times (dimensionless)."""
    if len(traj.t) == 0:
        return math.nan
    if not traj.scene.system.dissipative:
        return float(np.max(relative_energy_error(traj)))
    if truth is None:
        return math.nan
    n = min(len(traj.t), len(truth.t))
    E, E_true = traj["E"][:n], truth["E"][:n]
    terms = {k: float(v[0]) for k, v in truth.energy.items() if k not in BOOKKEEPING}
    return float(np.max(np.abs(E - E_true)) / energy_scale(float(E_true[0]), terms))
