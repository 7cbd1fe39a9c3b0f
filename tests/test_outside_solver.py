"""A solver written outside the package, as a contributor would: classic Runge-Kutta (RK4) for
the 1D dumbbell, one step function and one class in this file and nothing anywhere else.

``simulate``, ``compare``, ``bench`` and the stability catalogue take the class as it is (like
scipy's ``method=``) and agree with its theory: RK4's amplification factor on the spring's
oscillation, R(i h) = 1 - h^2/2 + h^4/24 + i (h - h^3/6) at h = w*dt, has
|R|^2 = 1 - h^6/72 + h^8/576, which is 1 at h = 2 sqrt(2): the step is stable below
w*dt = 2.83 (where the explicit steps of Euler-Cromer and Verlet already blow up past 2), and
its error is fourth order in dt between impacts. While stable it loses the vibration energy
steadily, by |R|^2 per step, which the class declares (``drift``): over the 1 s of the stiff
cases at w*dt = 1.9-2.7 it loses nearly all of it, so those runs are stable but
``inaccurate``, as the catalogue's theory predicts from that declaration. At impacts the floor
is the shared driver's flip, the textbook's rule.
"""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest
from numba import njit

import dumbbell
from dumbbell.solvers import METHODS, Kernel, Stepper
from tests.conftest import SCENES, make_scene


@njit(cache=True)
def _rates(xA, vA, xB, vB, p):  # pragma: no cover - compiled
    """(xA', vA', xB', vB') of the 1D dumbbell: the spring k (xA - xB - b) and gravity."""
    f = p.k * (xA - xB - p.b)
    return vA, -f / p.mA - p.g, vB, f / p.mB - p.g


def rk4_step(s, p):  # pragma: no cover - compiled by the package's driver
    """One classic Runge-Kutta step of length p.dt from the state s = (xA, vA, xB, vB)."""
    h = p.dt
    xA, vA, xB, vB = s
    a1, b1, c1, d1 = _rates(xA, vA, xB, vB, p)
    a2, b2, c2, d2 = _rates(xA + 0.5 * h * a1, vA + 0.5 * h * b1, xB + 0.5 * h * c1,
                            vB + 0.5 * h * d1, p)
    a3, b3, c3, d3 = _rates(xA + 0.5 * h * a2, vA + 0.5 * h * b2, xB + 0.5 * h * c2,
                            vB + 0.5 * h * d2, p)
    a4, b4, c4, d4 = _rates(xA + h * a3, vA + h * b3, xB + h * c3, vB + h * d3, p)
    return (xA + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4),
            vA + h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4),
            xB + h / 6.0 * (c1 + 2.0 * c2 + 2.0 * c3 + c4),
            vB + h / 6.0 * (d1 + 2.0 * d2 + 2.0 * d3 + d4))


class RK4(Stepper):
    """Classic Runge-Kutta in 1D; the floor is the driver's flip."""

    name = "rk4-trial"
    order = 4
    step_limit = 2.0 * math.sqrt(2.0)
    relative_cost = 4.0

    @staticmethod
    def kernel(dimensions):
        return Kernel(rk4_step) if dimensions == 1 else None

    @classmethod
    def drift(cls, ratio, steps):
        """The vibration energy lost after ``steps`` stable steps: 1 - |R|^(2 steps)."""
        return 1.0 - _amplification(ratio) ** steps if ratio < cls.step_limit else None


def _amplification(h: float) -> float:
    """|R(i h)|^2 of RK4 on an undamped oscillator at w*dt = h."""
    return 1.0 - h**6 / 72.0 + h**8 / 576.0


def _stiff(w_dt: float):
    """The catalogue's stiff case (w = 1000 rad/s, no floor, no gravity, 1 cm stretched,
    unstable_energy 100) at w*dt = ``w_dt``."""
    scene = dumbbell.load_scene(SCENES / "extreme" / "stiff-wdt-2.1.toml")
    return scene.with_values({"run.dt": w_dt / scene.system.omega})


def _free():
    """The textbook dumbbell without a floor, its spring 5 cm stretched: no impacts in 1 s,
    so the error is the method's own between impacts."""
    return make_scene({"bodies.A.height": 1.25, "run.t_end": 1.0}, drop=("floor",))


def test_the_theory_of_rk4_puts_the_limit_at_2_sqrt_2():
    assert _amplification(RK4.step_limit) == pytest.approx(1.0, abs=1e-12)
    assert _amplification(2.7) < 1.0 < _amplification(2.9)
    assert RK4 not in METHODS.values() and "rk4-trial" not in dumbbell.available_solvers()


def test_simulate_runs_the_class_and_its_verdicts_follow_its_limit():
    # Stable (decaying) at w*dt = 2.7, where Euler-Cromer blows up; unstable past 2.83. Its
    # vibration decays away: the run reaches its end, inaccurate, and the step it suggests
    # ends ok.
    calm = dumbbell.simulate(_stiff(2.7), RK4)
    assert calm.solver == "rk4-trial" and calm.verdict.complete and len(calm) == len(calm.t)
    assert calm.verdict.status == "inaccurate" and "try dt = " in calm.verdict.reason
    hint = float(calm.verdict.reason.split("try dt = ")[1].split()[0])
    assert dumbbell.simulate(_stiff(2.7), RK4, dt=hint).verdict.ok
    assert dumbbell.simulate(_stiff(2.7), "euler-cromer").verdict.status == "unstable"
    wild = dumbbell.simulate(_stiff(2.9), RK4)
    assert wild.verdict.status == "unstable"
    assert wild.scene.system.omega == pytest.approx(1000.0)
    assert "w*dt = 2.90 > 2.83" in wild.verdict.reason
    assert "stable only for dt < 2.83e-3 s" in wild.verdict.reason  # 2 sqrt(2) / w
    # The vibration energy shrinks by |R|^2 per step while stable: measured over 10 steps.
    K = calm["K_int"] + calm["U_spring"]
    assert K[10] / K[0] == pytest.approx(_amplification(2.7) ** 10, rel=0.05)


def test_its_error_between_impacts_is_fourth_order():
    scene = _free()
    exact = dumbbell.simulate(scene, "exact", dt=4e-3, every=1)  # samples every 4 ms
    errors = []
    for dt in (4e-3, 2e-3, 1e-3):
        run = dumbbell.simulate(scene, RK4, dt=dt, every=round(4e-3 / dt))
        assert np.allclose(run.t, exact.t) and not run.events
        errors.append(np.max(np.abs(run["xA"] - exact["xA"])))
    ratios = [errors[i] / errors[i + 1] for i in range(2)]
    assert all(2**3.7 < r < 2**4.3 for r in ratios), ratios


def test_bench_fits_its_order_and_draws_the_class_s_own():
    result = dumbbell.bench(_free(), solvers=[RK4, "verlet"], dts=[4e-3, 2e-3, 1e-3, 5e-4],
                            window=1.0, repeat=1)
    fit = result.fits["rk4-trial"]
    assert fit.expected == 4 and fit.order == pytest.approx(4.0, abs=0.3)
    assert result.fits["verlet"].expected == 2
    assert all(p.ok for p in result.points if p.solver == "rk4-trial")


def test_compare_measures_it_against_the_truth():
    result = dumbbell.compare(_free(), solvers=[RK4, "euler-cromer"], dts=[1e-3], t_end=1.0,
                              window=1.0)
    rows = {row.label: row for row in result.rows}
    assert result.truth.solver == "exact" and set(rows) == {"rk4-trial", "euler-cromer"}
    assert 0 < rows["rk4-trial"].window_error < rows["euler-cromer"].window_error / 1000
    assert result.to_pandas().loc["rk4-trial", "dt"] == 1e-3


def test_the_stability_catalogue_agrees_with_its_theory(tmp_path):
    for w_dt in (1.9, 2.1, 2.7, 2.9):
        text = (SCENES / "extreme" / "stiff-wdt-2.1.toml").read_text()
        (tmp_path / f"wdt-{w_dt}.toml").write_text(
            text.replace("dt = 2.1e-3", f"dt = {w_dt / 1000.0!r}"))
    shutil.copy(SCENES / "extreme" / "high-drop.toml", tmp_path)  # a floor, the driver's flip
    report = dumbbell.stability(tmp_path, solvers=[RK4, "euler-cromer"], workers=2)
    verdicts = {(r.case, r.solver): (r.verdict, r.predicted) for r in report.rows}
    assert report.disagreements == [], [(r.case, r.solver, r.agreement) for r in report.rows]
    assert verdicts[("wdt-2.7", "rk4-trial")] == ("inaccurate", "inaccurate")
    assert verdicts[("wdt-2.7", "euler-cromer")] == ("unstable", "unstable")
    assert verdicts[("wdt-2.9", "rk4-trial")] == ("unstable", "unstable")
    theory = {r.case: r.theory for r in report.rows if r.solver == "rk4-trial"}
    assert theory["wdt-2.7"].startswith("w*dt = 2.7 < 2.83: stable, but the step moves the "
                                        "energy by up to 1 of its scale")
    assert theory["wdt-2.9"] == "w*dt = 2.90 >= 2.83"
