"""The solver registry: every solver declares its facts, and one class is all a new solver
needs (a registry line gives it a name the scenes and the CLI know)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from dumbbell import DumbbellError, UsageError, load_scene, simulate
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
from dumbbell.solvers.base import contract_problems
from tests.conftest import SCENES

TYPES = {"name": str, "order": (int, type(None)), "has_step": bool,
         "step_limit": (float, type(None)), "flip_floor": bool, "relative_cost": float,
         "is_truth": bool, "estimates_error": bool}


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
    assert cls.relative_cost > 0
    # A solver without a step has no order in dt and no step to be unstable.
    assert cls.has_step or (cls.order is None and cls.step_limit is None)
    assert not cls.has_step or cls.order >= 1
    assert contract_problems(cls) == []


def test_the_step_limits_are_the_theory_of_each_method():
    # Explicit spring steps (Euler-Cromer in either step order, Verlet, pymunk's impulse) are
    # stable iff w*dt < 2; the step-free truths have no limit.
    limits = {name: cls.step_limit for name, cls in METHODS.items()}
    assert limits == {"euler-cromer": 2.0, "exact": None, "verlet": 2.0, "pymunk": 2.0,
                      "reference": None, "euler-cromer-2d": 2.0}
    # Their bounded swing at w*dt = h is h/(2 - h): 19 at 1.9, none past the limit.
    assert METHODS["verlet"].swing(1.9) == pytest.approx(19.0)
    assert METHODS["verlet"].swing(2.1) == float("inf")
    assert METHODS["exact"].swing(1.9) is None


def test_a_class_that_breaks_the_contract_is_refused_by_name():
    class Half(Solver):  # no facts, no solve
        name = "half"

        @staticmethod
        def _supports(scene):
            return None

    problems = contract_problems(Half)
    assert "order is not declared" in problems and "_solve is not written" in problems
    scene = load_scene(SCENES / "textbook-1d.toml")
    with pytest.raises(UsageError, match=r"solver = .*Half: does not keep the solver contract"):
        simulate(scene, Half)
    with pytest.raises(UsageError, match=r"solver = 3: must be one of euler-cromer, .* \(or a Solver subclass\)"):
        simulate(scene, 3)
    assert contract_problems(int) == ["not a subclass of dumbbell.solvers.Solver"]


def test_a_contract_method_called_on_the_class_checks_its_arguments():
    cls = METHODS["euler-cromer"]
    with pytest.raises(DumbbellError, match="scene"):
        cls.supports(None)
    with pytest.raises(UsageError, match="options"):
        cls.solve(SCENES / "textbook-1d.toml", None)
    # ... and shows its parameters.
    import inspect

    assert list(inspect.signature(cls.solve).parameters)[:2] == ["scene", "options"]
    assert list(inspect.signature(cls.supports).parameters) == ["scene"]


def test_a_solver_that_writes_the_public_method_in_place_of_its_impl_is_refused():
    class Old(METHODS["euler-cromer"]):
        @classmethod
        def solve(cls, scene, options):  # the checks of Solver.solve would be bypassed
            return None

    assert contract_problems(Old) == [(
        "solve is written in place of _solve (Solver.solve checks the arguments and calls "
        "_solve)")]
    assert contract_problems(METHODS["euler-cromer"]) == []


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
    step_limit = None
    flip_floor = False
    relative_cost = 0.5
    is_truth = False
    estimates_error = False

    @classmethod
    def _supports(cls, scene):
        return None if scene.system.dimensions == 1 else "still is 1D only"

    @classmethod
    def _solve(cls, scene, options: RunOptions) -> Trajectory:
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
    # Analysis reads the facts from the class: a spring step without a limit is never unstable.
    stiff = scene.with_values({"spring.stiffness": 1e9})
    assert predict(stiff, "still", 1e-3, 1.0).status == "ok"
    assert predict(stiff, "euler-cromer", 1e-3, 1.0).status == "unstable"


def test_a_solver_class_runs_without_a_registry_line():
    # Like scipy's method=, simulate takes the class itself.
    scene = load_scene(SCENES / "textbook-1d.toml")
    traj = simulate(scene, Still, t_end=0.01, every=10)
    assert traj.solver == "still" and len(traj) == 101
    assert np.all(traj["xA"] == scene.system.A.height)
    assert "still" not in METHODS and solver_class(Still) is Still
