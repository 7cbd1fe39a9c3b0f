"""The 2D spring reference: the relative vector integrated at a fixed RK8 step, the centre of
mass in closed form, and a floor search that cannot miss an impact."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from dumbbell.model.scene import load_scene
from dumbbell.solvers import simulate

from .conftest import SCENES


def brute_force_impacts(scene, t_end, scan=1e-6):
    """Impacts of the spring dumbbell from scipy's DOP853 on the full state (rtol 1e-11), the
    floor found by scanning both heights on a 1e-6 s grid of its dense output: independent
    of the reference's step and of its bound."""
    A, B = scene.system.A, scene.system.B
    system = scene.system
    mA, mB, k, b, g, e = A.mass, B.mass, system.k, system.b, system.g, system.elasticity

    def rhs(_t, y):
        dx, dy = y[0] - y[4], y[1] - y[5]
        L = math.hypot(dx, dy)
        s = -k * (L - b) / L
        return [y[2], y[3], s * dx / mA, s * dy / mA - g, y[6], y[7], -s * dx / mB,
                -s * dy / mB - g]

    y = np.array([A.x, A.height, A.vx, A.vy, B.x, B.height, B.vx, B.vy])
    t, out = 0.0, []
    while t < t_end:
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=1e-11, atol=1e-12,
                        dense_output=True)
        grid = np.arange(t + scan, t_end, scan)
        Y = sol.sol(grid)
        first = []
        for body, row in (("A", 1), ("B", 5)):
            below = np.flatnonzero(Y[row] <= 0)
            if below.size:
                j = below[0]
                lo = grid[j - 1] if j else t + 1e-9
                first.append((brentq(lambda s, row=row, sol=sol: sol.sol(s)[row], lo,
                                     grid[j], xtol=1e-14), body))
        if not first:
            break
        t, body = min(first)
        y = sol.sol(t)
        y[3 if body == "A" else 7] *= -e
        out.append((t, body))
    return out


@pytest.mark.parametrize("k, vx", [(2e4, 3.0), (5e3, -4.0)])
def test_stiff_fast_spinning_spring_misses_no_impact(k, vx):
    # w * (sample spacing) > 1: the samples alone say nothing about what happens between them.
    scene = load_scene(SCENES / "tilted-2d.toml").with_values(
        {"spring.stiffness": k, "bodies.A.velocity": [vx, 0.0], "bodies.B.height": 0.3})
    spacing = 5e-3
    assert scene.system.omega * spacing > 1
    run = simulate(scene, "reference", dt=spacing, t_end=1.0, every=1)
    assert run.verdict.ok
    truth = brute_force_impacts(scene, 1.0)
    assert len(truth) >= 3
    assert [e.body for e in run.events] == [b for _, b in truth]
    np.testing.assert_allclose([e.t for e in run.events], [t for t, _ in truth], atol=1e-8)


def test_tilted_reference_is_tight_and_checks_itself():
    scene = load_scene(SCENES / "tilted-2d.toml")
    run = simulate(scene, "reference", t_end=2.0, every=100)
    assert run.verdict.ok
    est = run.info["estimated_error"]
    assert est["position_m_window"] < 1e-7
    assert est["energy_relative"] < 1e-12
    assert min(run["yA"].min(), run["yB"].min()) >= -1e-9
    truth = brute_force_impacts(scene, 2.0)
    assert [e.body for e in run.events] == [b for _, b in truth]
    np.testing.assert_allclose([e.t for e in run.events], [t for t, _ in truth], atol=1e-8)
