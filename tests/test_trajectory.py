"""The Trajectory is frozen and built once, after the verdict: nothing can change it, and a run
that failed ends at its failure with every column as long as ``t``."""

from __future__ import annotations

from dataclasses import FrozenInstanceError, replace

import numpy as np
import pytest

from dumbbell.model.energy import energy_columns, partition
from dumbbell.model.trajectory import Trajectory, Verdict
from dumbbell.solvers import METHODS, RunOptions, simulate
from dumbbell.solvers.verdicts import RawRun, judge

from .conftest import make_scene

#: w = sqrt(k/mu) = 1000 rad/s: dt = 2.1e-3 s is past the explicit limit w*dt = 2.
STIFF = {"spring.stiffness": 5e4, "bodies.A.height": 1.21, "run.t_end": 0.5,
         "run.unstable_energy": 100.0}


def _relative_error(E: np.ndarray) -> np.ndarray:
    return np.abs(E - E[0]) / abs(E[0])


@pytest.mark.parametrize("solver", ["exact", "euler-cromer", "verlet", "pymunk"])
def test_a_trajectory_cannot_be_changed(solver):
    run = simulate(make_scene(), solver, t_end=0.3, dt=1e-4, every=10)
    for name, value in (("verdict", Verdict("failed", 0.0, "no")), ("t", run.t[:1]),
                        ("events", ()), ("energy", {})):
        with pytest.raises(FrozenInstanceError):
            setattr(run, name, value)
    arrays = [run.t, *run.state.values(), *run.energy.values()]
    for column in arrays:
        with pytest.raises(ValueError, match="read-only"):
            column[0] = 1.0
    assert isinstance(run.events, tuple)
    assert all(len(column) == len(run.t) for column in arrays)


def test_a_hand_built_trajectory_gets_its_energy_at_construction():
    scene = make_scene()
    t = np.linspace(0.0, 0.1, 11)
    state = {"xA": 1.2 + 0 * t, "vA": -9.8 * t, "xB": 1.0 + 0 * t, "vB": -9.8 * t}
    traj = Trajectory(scene, "hand", t, state)
    # Free fall from rest, the spring at its rest length: E = M g X(0) = 0.2 * 9.8 * 1.1 J.
    np.testing.assert_allclose(traj["U_spring"], 0.0, atol=1e-15)
    np.testing.assert_allclose(traj["K_cm"], 0.5 * 0.2 * (9.8 * t) ** 2, rtol=1e-12)
    assert traj["E"][0] == pytest.approx(0.2 * 9.8 * 1.1, rel=1e-12)
    assert list(traj.energy) == energy_columns(scene)
    state["xA"][0] = 2.0  # the caller's array stays its own; the trajectory holds a view
    with pytest.raises(ValueError, match="samples"):
        Trajectory(scene, "hand", t, {**state, "xB": state["xB"][:5]})
    with pytest.raises(ValueError, match="samples"):
        replace(traj, energy={name: col[:3] for name, col in traj.energy.items()})


@pytest.mark.parametrize("solver", ["euler-cromer", "verlet", "pymunk"])
@pytest.mark.parametrize("threshold", [100.0, 0.5])
def test_an_unstable_run_ends_at_its_failure_with_energy_columns_as_long(solver, threshold):
    scene = make_scene({**STIFF, "run.unstable_energy": threshold}, drop=("floor",))
    run = simulate(scene, solver, dt=2.1e-3)
    assert run.verdict.status == "unstable"
    n = len(run.t)
    assert n >= 2 and all(len(col) == n for col in (*run.state.values(), *run.energy.values()))
    assert run.table().shape == (n, len(run.columns)) and np.isfinite(run.table()).all()
    # The energy columns are those of the kept state (J), cut with it.
    own = partition(scene, run.t, run.state, run.events)
    for name in own:
        np.testing.assert_allclose(run.energy[name], own[name], rtol=1e-9, atol=1e-12)
    # It ends at the first sample whose energy error passed the threshold.
    err = _relative_error(run["E"])
    assert err[-1] > threshold and np.all(err[:-1] <= threshold)
    assert run.verdict.t == run.t[-1]


def test_judge_changes_nothing_and_says_where_to_cut():
    scene = make_scene({**STIFF, "run.unstable_energy": 0.5}, drop=("floor",))
    t = np.linspace(0.0, 1.0, 6)
    E_like = np.array([0.0, 0.0, 0.001, 0.002, 0.5, 1.0])
    state = {"xA": 1.21 + E_like, "vA": 0 * t, "xB": 1.0 + 0 * t, "vB": 0 * t}
    before = {name: col.copy() for name, col in state.items()}
    cls, options = METHODS["euler-cromer"], RunOptions(1e-4, 1.0)
    verdict, keep, energy = judge(cls, scene, options, RawRun(t, state))
    for name, col in state.items():
        np.testing.assert_array_equal(col, before[name])
    full = partition(scene, t, state)
    err = _relative_error(full["E"])
    first_bad = int(np.flatnonzero(err > 0.5)[0])
    assert verdict.status == "unstable" and keep == first_bad + 1 < len(t)
    assert verdict.t == t[first_bad]
    assert all(len(col) == keep for col in energy.values())
    # A solver's own failure (not an energy one) keeps every sample.
    verdict, keep, _ = judge(cls, scene, options, RawRun(t, state, (),
                                                         Verdict("tunnelled", 1.0, "x")))
    assert verdict.status == "tunnelled" and keep == len(t)


@pytest.mark.parametrize("solver", ["euler-cromer", "verlet", "pymunk"])
def test_an_energy_cut_drops_the_impacts_after_it(solver):
    # The spring starts at its rest length; w*dt = 2.001 lets the vibration the first impact
    # starts grow until the energy check cuts the run just after that impact, while the
    # uncut run bounces on (and on).
    base = {"spring.stiffness": 5e4, "bodies.A.height": 1.2, "run.t_end": 3.0}
    cut = simulate(make_scene({**base, "run.unstable_energy": 0.5}), solver, dt=2.001e-3)
    uncut = simulate(make_scene({**base, "run.unstable_energy": 1e70}), solver, dt=2.001e-3)
    assert cut.verdict.status == "unstable" and len(cut.t) < len(uncut.t)
    end = cut.t[-1]
    assert any(e.t > end for e in uncut.events)          # there was something to drop
    assert cut.events == tuple(e for e in uncut.events if e.t <= end) != ()
