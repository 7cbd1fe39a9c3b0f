"""The solver registry: every solver declares its facts, and one class plus one registry line
is all a new solver needs."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from dumbbell import load_scene, simulate
from dumbbell.analysis.stability import predict
from dumbbell.model.trajectory import Trajectory
from dumbbell.solvers import (
    METHODS,
    RunOptions,
    Solver,
    solver_class,
    supported,
    truth_solver,
)
from tests.conftest import SCENES

TYPES = {"name": str, "order": (int, type(None)), "has_step": bool, "explicit_spring": bool,
         "flip_floor": bool, "relative_cost": float, "is_truth": bool, "estimates_error": bool}


def test_the_capability_list_is_the_one_checked_here():
    assert set(Solver.CAPABILITIES) == set(TYPES)


@pytest.mark.parametrize("name", sorted(METHODS))
def test_every_registered_solver_declares_every_capability(name):
    cls = METHODS[name]
    assert issubclass(cls, Solver) and cls.name == name
    for cap in Solver.CAPABILITIES:
        # Declared by the solver or its family (stepping.Stepper), never left to the contract.
        assert any(cap in vars(c) for c in cls.__mro__ if c is not Solver), f"{name}: {cap}"
        assert isinstance(getattr(cls, cap), TYPES[cap]), f"{name}: {cap}"
    for method in ("supports", "solve"):
        assert getattr(cls, method) is not getattr(Solver, method), f"{name}: {method}"
    assert cls.relative_cost > 0
    # A solver without a step has no order in dt and no explicit step to be unstable.
    assert cls.has_step or (cls.order is None and not cls.explicit_spring)
    assert not cls.has_step or cls.order >= 1


def test_every_truth_solver_is_step_free_and_the_truth_exists_in_1d_and_2d():
    truths = [cls for cls in METHODS.values() if cls.is_truth]
    assert truths and all(not cls.has_step for cls in truths)
    for name in ("textbook-1d", "tilted-2d", "rigid-2d"):
        scene = load_scene(SCENES / f"{name}.toml")
        # Exactly one truth solver claims each kind of scene, and it runs the shipped one.
        owners = [cls for cls in truths if cls.truth_for(scene)]
        assert len(owners) == 1 and truth_solver(scene) == owners[0].name


def test_importing_the_package_loads_no_numba_scipy_or_pymunk():
    code = ("import sys, dumbbell, dumbbell.solvers; "
            "print(sorted(m for m in ('numba', 'scipy', 'pymunk') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"


class Still(Solver):
    """A made-up solver: nothing moves. Only here to show what adding a solver takes."""

    name = "still"
    order = 1
    has_step = True
    explicit_spring = False
    flip_floor = False
    relative_cost = 0.5
    is_truth = False
    estimates_error = False

    @classmethod
    def supports(cls, scene):
        return None if scene.system.dimensions == 1 else "still is 1D only"

    @classmethod
    def solve(cls, scene, options: RunOptions) -> Trajectory:
        t = options.sample_times()
        state = {"xA": np.full_like(t, scene.system.A.height), "vA": np.zeros_like(t),
                 "xB": np.full_like(t, scene.system.B.height), "vB": np.zeros_like(t)}
        return Trajectory(scene=scene, solver=cls.name, t=t, state=state, events=[],
                          dt=options.dt, every=options.every, wall_time=0.0)


def test_a_new_solver_is_one_class_and_one_registry_line(monkeypatch):
    monkeypatch.setitem(METHODS, Still.name, Still)
    scene = load_scene(SCENES / "textbook-1d.toml")
    assert "still" in supported(scene) and solver_class("still") is Still
    traj = simulate(scene, "still", t_end=0.01, every=10)
    assert traj.solver == "still" and traj.verdict.ok
    # Analysis reads the facts from the class: a non-explicit spring has no step limit.
    stiff = scene.with_values({"spring.stiffness": 1e9})
    assert predict(stiff, "still", 1e-3, 1.0).status == "ok"
    assert predict(stiff, "euler-cromer", 1e-3, 1.0).status == "unstable"
