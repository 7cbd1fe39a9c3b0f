"""How far a run is from the truth: each measure defined once, used by compare and bench.

- Position (m): the distance |r - r_truth| of either particle, the larger of A and B, at each
  shared sample (:func:`position_error_series`; in 1D the height difference, in 2D
  sqrt(dx^2 + dy^2)), and its largest value over [0, window] (:func:`position_error`). The
  motion is chaotic, so errors after the window say nothing about the method.
- Impact times (s): :func:`impact_time_error`, the largest |t_i - t_i(truth)|, impacts paired
  in order.
- Energy (dimensionless): :func:`energy_error`, the largest relative drift |E - E(0)| / scale
  over the whole run, or for a dissipative scene the largest distance from the truth's E at the
  same times.

Every measure needs the two runs sampled at the same times (the first samples of both): a
run with other sample times is an error, not silently compared sample by sample.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import UsageError
from ..model import args
from ..model.energy import _relative_energy_error, _start_scale
from ..model.trajectory import Trajectory

#: No public names: the measures :func:`dumbbell.compare` reports.
__all__: list[str] = []


def _pair(run: Any, truth: Any, name: str = "run") -> tuple[Trajectory, Trajectory]:
    """Two trajectories of scenes of the same dimensions (UsageError naming the argument)."""
    run, truth = args.trajectory(run, name), args.trajectory(truth, "truth")
    if run.scene.system.dimensions != truth.scene.system.dimensions:
        raise UsageError(f"truth: a {truth.scene.system.dimensions}D run cannot be the truth of "
                         f"a {run.scene.system.dimensions}D one", param="truth")
    return run, truth


def _check_shared_times(run: Trajectory, truth: Trajectory, n: int) -> None:
    # Sample times built as step * every * dt by different (dt, every) agree to rounding only.
    if not np.allclose(run.t[:n], truth.t[:n], rtol=1e-9, atol=0.0):
        raise UsageError(f"truth: {run.solver} and {truth.solver} do not share their sample "
                         "times; run both with the same dt * every", param="truth")


def position_error_series(run: Trajectory, truth: Trajectory) -> np.ndarray:
    """The position error at each sample both runs have (m): the distance |r - r_truth| of
    either particle, the larger of A and B (in 1D the height difference)."""
    return _position_error_series(*_pair(run, truth))


def _position_error_series(run: Trajectory, truth: Trajectory) -> np.ndarray:
    n = min(len(run.t), len(truth.t))
    _check_shared_times(run, truth, n)
    per_body = []
    for body in "AB":
        cols = [c for c in (f"x{body}", f"y{body}") if c in run.state]
        per_body.append(np.sqrt(sum((run.state[c][:n] - truth.state[c][:n]) ** 2
                                    for c in cols)))
    return np.max(per_body, axis=0)


def position_error(run: Trajectory, truth: Trajectory, window: float) -> float:
    """The largest :func:`position_error_series` over the samples in [0, window] (m); inf if
    the run stopped before the window ended. Both must share their sample times."""
    run, truth = _pair(run, truth)
    return _position_error(run, truth, args.real(window, "window", "s"))


def _position_error(run: Trajectory, truth: Trajectory, window: float) -> float:
    n = int(np.searchsorted(truth.t, window * (1 + 1e-12), side="right"))
    if len(run.t) < n:
        return math.inf
    return float(np.max(_position_error_series(run, truth)[:n]))


def impact_time_error(traj: Trajectory, truth: Trajectory, window: float
                      ) -> tuple[float, int, int]:
    """(largest |t_i - t_i(truth)| in s, impacts compared, truth's impacts in [0, window]).

    Impacts are paired in order; inf if the solver's sequence misses one or names another
    body before the window ends."""
    traj, truth = _pair(traj, truth, "traj")
    return _impact_time_error(traj, truth, args.real(window, "window", "s"))


def _impact_time_error(traj: Trajectory, truth: Trajectory, window: float
                       ) -> tuple[float, int, int]:
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
    if truth is None:
        return _energy_error(args.trajectory(traj), None)
    return _energy_error(*_pair(traj, truth, "traj"))


def _energy_error(traj: Trajectory, truth: Trajectory | None) -> float:
    if len(traj.t) == 0:
        return math.nan
    if not traj.scene.system.dissipative:
        return float(np.max(_relative_energy_error(traj.energy, traj.scene.system)))
    if truth is None:
        return math.nan
    n = min(len(traj.t), len(truth.t))
    E, E_true = traj["E"][:n], truth["E"][:n]
    return float(np.max(np.abs(E - E_true)) / _start_scale(truth.energy, truth.scene.system))
