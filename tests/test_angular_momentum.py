"""L_cm, the angular momentum about the centre of mass, on every 2D solver: constant in
flight (the spring is central, gravity has no torque about the centre of mass), and the
angular momentum about the contact point unchanged by a frictionless impact."""

from __future__ import annotations

import numpy as np
import pytest

from dumbbell.model.energy import column_unit, momentum_columns
from dumbbell.model.scene import load_scene
from dumbbell.solvers import simulate, supported

from .conftest import SCENES


def thrown(name: str):
    """A 2D scene with A thrown sideways, so that the dumbbell turns from the start."""
    return load_scene(SCENES / f"{name}.toml").with_values({"bodies.A.velocity": [1.5, 0.0]})


CASES = [(name, solver) for name in ("tilted-2d", "rigid-2d")
         for solver in supported(thrown(name))]


def about_contact(run, i: int, P: float, t_hit: float) -> float:
    """Angular momentum about the floor point (P, 0) at the impact time (kg m^2/s), carried
    from sample ``i`` by gravity's torque -M g (R_x - P) (the only external one in flight)."""
    scene = run.scene
    M, mA, mB = scene.system.M, scene.system.A.mass, scene.system.B.mass
    R = [(mA * run[f"{c}A"][i] + mB * run[f"{c}B"][i]) / M for c in "xy"]
    V = [(mA * run[f"v{c}A"][i] + mB * run[f"v{c}B"][i]) / M for c in "xy"]
    L = run["L_cm"][i] + M * ((R[0] - P) * V[1] - R[1] * V[0])
    span = t_hit - run.t[i]
    return L - M * scene.system.g * (R[0] + V[0] * span / 2 - P) * span


@pytest.mark.parametrize("name, solver", CASES)
def test_l_cm_constant_in_flight_and_contact_momentum_kept(name, solver):
    run = simulate(thrown(name), solver, dt=1e-5, t_end=0.6, every=1)
    assert run.verdict.ok and len(run.events) >= 1
    L = run["L_cm"]
    hit = run.events[0]
    j = int(np.searchsorted(run.t, hit.t))  # first sample after the impact
    assert abs(L[0]) > 0.01
    assert np.ptp(L[:j]) <= 1e-11 * abs(L[0])
    P = run[f"x{hit.body}"][j - 1] + run[f"vx{hit.body}"][j - 1] * (hit.t - run.t[j - 1])
    before, after = about_contact(run, j - 1, P, hit.t), about_contact(run, j, P, hit.t)
    assert after == pytest.approx(before, rel=1e-8)
    assert abs(L[j] - L[j - 1]) > 1e-3  # the impact did change L_cm


def test_l_cm_is_a_column_of_2d_scenes_only(textbook):
    run = simulate(thrown("tilted-2d"), "reference", dt=1e-3, t_end=0.01, every=1)
    assert run.columns[-1] == "L_cm" and column_unit("L_cm") == "kg m^2/s"
    assert momentum_columns(textbook) == []
    # mu (d x w) for the particles
    d = np.array([run["xA"] - run["xB"], run["yA"] - run["yB"]])
    w = np.array([run["vxA"] - run["vxB"], run["vyA"] - run["vyB"]])
    mu = run.scene.system.mu
    np.testing.assert_allclose(run["L_cm"], mu * (d[0] * w[1] - d[1] * w[0]), rtol=1e-12)


def test_l_cm_of_the_rigid_body_is_i_omega_with_disc_spin():
    scene = thrown("rigid-2d").with_values({"pymunk.spin": True, "bodies.A.radius": 0.03})
    run = simulate(scene, "exact", dt=1e-3, t_end=1.0, every=1)
    np.testing.assert_allclose(run["L_cm"], run.info["moment"] * run.state["omega"], rtol=1e-12)
