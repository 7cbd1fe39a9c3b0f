"""E_heat (what the contacts dissipated) and E_err (the method's own error): they split
E_lost = E(0) - E, vanish on elastic frictionless floors, and agree with the closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from dumbbell.model.energy import heat
from dumbbell.model.scene import load_scene
from dumbbell.solvers import simulate, supported

from .conftest import SCENES

ELASTIC = [(name, solver) for name in ("textbook-1d", "tilted-2d", "rigid-2d")
           for solver in supported(load_scene(SCENES / f"{name}.toml"))]


@pytest.mark.parametrize("name, solver", ELASTIC)
def test_no_heat_on_an_elastic_frictionless_floor(name, solver):
    run = simulate(load_scene(SCENES / f"{name}.toml"), solver, dt=1e-4, t_end=2.0, every=10)
    assert len(run.events) >= 3
    assert np.max(np.abs(heat(run.scene, run.t, run.state, run.events))) < 1e-12


def test_friction_first_impact_heat():
    scene = load_scene(SCENES / "friction-2d.toml")
    run = simulate(scene, "pymunk", t_end=1.2, every=100)
    first, second = run.events[0], run.events[1]
    between = (run.t > first.t + 1e-3) & (run.t < second.t)
    assert run["E_heat"][between] == pytest.approx(0.0375, rel=0.01)
    E0 = run["E"][0]
    np.testing.assert_allclose(run["E"] + run["E_heat"] + run["E_err"], E0, rtol=0, atol=1e-12)
    assert np.max(np.abs(run["E_err"])) < 0.05 * run["E_heat"][-1]


@pytest.mark.parametrize("name", ["textbook-1d", "rigid-2d", "tilted-2d"])
def test_exact_heat_is_all_of_the_lost_energy(name):
    scene = load_scene(SCENES / f"{name}.toml").with_values({"floor.elasticity": 0.7})
    solver = "reference" if name == "tilted-2d" else "exact"
    run = simulate(scene, solver, every=100, t_end=3.0)
    assert run["E_heat"][-1] > 0.1
    # The truth's own energy error is rounding: all of E_lost is heat.
    assert np.max(np.abs(run["E_err"])) < 1e-9
    # pymunk counts its heat from the contact impulses: the rest is its small step error.
    engine = simulate(scene, "pymunk", every=100, t_end=3.0)
    assert np.max(np.abs(engine["E_err"])) < 2e-2 * engine["E_heat"][-1]
