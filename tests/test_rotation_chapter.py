"""The rotation chapter's preview against closed forms: apparent restitution of a tilted rigid
dumbbell (impulse law), the toppling dumbbell (energy conservation and one quadrature)."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from dumbbell.analysis.restitution import (
    bounce,
    drop_duration,
    e_eff_rigid,
    k_rot_share_rigid,
    rigid_q,
    sign_change_deg,
    tilted,
    truth_for,
)
from dumbbell.analysis.topple import closed_form, measure
from dumbbell.model.scene import load_scene, scene_from_dict
from dumbbell.solvers import simulate

from .conftest import DROP_ANGLES, ROOT, SCENES, rotation_table

ANGLES = DROP_ANGLES


@pytest.fixture(scope="module")
def tilted_scene():
    return load_scene(SCENES / "tilted-2d.toml")


@pytest.fixture(scope="module")
def topple_scene():
    return load_scene(SCENES / "topple-2d.toml")


def drop(scene, theta, e, solver, **kw):
    s = tilted(scene.with_values({"floor.elasticity": e}), theta)
    return s, simulate(s, solver, t_end=drop_duration(s), every=1, **kw)


def test_formula_by_hand():
    # Two equal point masses: q = 1; e_eff(30 degrees, e = 1) = (1 - 1/4) / (1 + 1/4) = 0.6.
    assert e_eff_rigid(30.0, 1.0) == pytest.approx(0.6, abs=1e-15)
    assert sign_change_deg(0.5) == pytest.approx(45.0, abs=1e-12)
    assert sign_change_deg(1.0) == pytest.approx(90.0, abs=1e-12)
    # At the sign change e_eff is zero, and the rotational share is (1+e)^2 e/(1+e)^2 = e.
    assert e_eff_rigid(sign_change_deg(0.3, 2.0), 0.3, 2.0) == pytest.approx(0.0, abs=1e-15)
    assert k_rot_share_rigid(45.0, 0.5) == pytest.approx(0.5, abs=1e-15)


@pytest.mark.parametrize("e", [1.0, 0.5])
def test_rigid_truth_against_impulse_law(tilted_scene, e):
    for theta in ANGLES:
        s, traj = drop(tilted_scene, theta, e, truth_for(tilted(tilted_scene, theta)))
        b = bounce(traj)
        assert b.e_first == pytest.approx(float(e_eff_rigid(theta, e, rigid_q(s))), abs=1e-9)
        assert b.share_first == pytest.approx(float(k_rot_share_rigid(theta, e)), abs=1e-9)


@pytest.mark.parametrize("e", [1.0, 0.5])
def test_rigid_pymunk_against_impulse_law(tilted_scene, e):
    # Each tilt's drop in pymunk at dt = 1e-5 s, every step kept, for the drop's run time:
    # bounce(drop(tilted_scene, theta, e, "pymunk")).e_first, as restitution() measures it
    # for the rotation page's table (its pymunk column; those runs, made once).
    table = rotation_table(e)
    assert list(table.theta) == list(ANGLES) and table.pymunk_dt == 1e-5
    for theta, e_first in zip(ANGLES, table.pymunk, strict=True):
        s = tilted(tilted_scene.with_values({"floor.elasticity": e}), theta)
        assert e_first == pytest.approx(float(e_eff_rigid(theta, e, rigid_q(s))), abs=1e-3)


def test_unequal_masses_use_q(tilted_scene):
    # mA = 3 mB: a_B = 3L/4 and I = mu L^2 = 3/16 M L^2, so q = M a_B^2 / I = 3.
    heavy = tilted_scene.with_values({"bodies.A.mass": 0.3})
    assert rigid_q(heavy) == pytest.approx(3.0, rel=1e-12)
    _, traj = drop(heavy, 35.0, 0.8, truth_for(tilted(heavy, 35.0)))
    s2 = math.sin(math.radians(35.0)) ** 2
    assert bounce(traj).e_first == pytest.approx((0.8 - 3 * s2) / (1 + 3 * s2), abs=1e-9)


def test_topple_closed_form_by_quadrature_and_ode(topple_scene):
    from scipy.integrate import solve_ivp

    cf = closed_form(topple_scene)
    # Started near upright, the landing speeds approach sqrt(g a) and sqrt(2 g L).
    assert cf.landing_speeds()[1] == pytest.approx(math.sqrt(2 * 9.8 * 0.2), rel=3e-3)
    # Independent check of the quadrature: integrate the equation of motion itself.
    def rhs(t, y):
        return [y[1], float(cf.alpha(y[0]))]

    land = lambda t, y: y[0] - math.pi / 2
    land.terminal = True
    sol = solve_ivp(rhs, (0, 2), [cf.theta0, 0.0], events=land, rtol=1e-12, atol=1e-13)
    assert sol.t_events[0][0] == pytest.approx(cf.fall_time(), rel=1e-8)
    assert sol.y_events[0][0][1] == pytest.approx(cf.landing_omega(), rel=1e-8)
    t, theta = cf.angle_curve(50)
    assert t[-1] == pytest.approx(cf.fall_time(), rel=1e-10)
    assert np.all(np.diff(theta) > 0) and np.all(cf.normal_force(theta) > 0)


def test_topple_in_pymunk(topple_scene):
    """The scene's run to 0.5 s instead of its 1 s: the same samples up to there (the fall,
    the landing at 0.41 s and 0.09 s of both ends lying on the floor, a lasting contact to the
    end), without the half second more of lying still."""
    cf = closed_form(topple_scene)
    traj = simulate(topple_scene, "pymunk", t_end=0.5)
    m = measure(traj)
    assert m.v_top == pytest.approx(math.sqrt(2 * cf.g * cf.L), rel=0.01)
    assert m.v_top == pytest.approx(cf.landing_speeds()[1], rel=0.01)
    assert m.cm_drift < 1e-6
    assert m.fall_time == pytest.approx(cf.fall_time(), rel=0.01)
    # B rests on the floor throughout: contact, not impacts. The one impact is A's landing,
    # at the closed form's time and top speed (the contact point's, straight down).
    assert [e.body for e in traj.events] == ["A"]
    landing = traj.events[0]
    assert landing.t == pytest.approx(cf.fall_time(), rel=1e-4)
    assert -landing.v_before == pytest.approx(cf.landing_speeds()[1], rel=1e-3)
    assert abs(landing.v_after) < 1e-9           # e = 0: the landing ends the motion
    t_end = float(traj.t[-1])
    spans = {c.body: (c.t_start, c.t_end) for c in traj.contacts}
    assert len(traj.contacts) == 2 and set(spans) == {"A", "B"}
    assert spans["B"][0] <= topple_scene.run.dt and spans["B"][1] == t_end
    assert spans["A"] == (landing.t, t_end)
    assert "1 impact, 2 contacts" in repr(traj)


def test_topple_refuses_what_it_cannot_describe(topple_scene):
    from dumbbell.errors import UsageError

    with pytest.raises(UsageError, match="frictionless"):
        closed_form(topple_scene.with_values({"floor.friction": 0.3}))
    raw = dict(topple_scene.to_dict(), tilt=0.0)
    with pytest.raises(UsageError, match="strictly between 0 and 90"):
        closed_form(scene_from_dict(raw, "upright.toml"))


@pytest.mark.parametrize("bad", ["0:100:3", "60:0:3", "0:60:0", "0:60", "a:b:c", "0:60:2.5",
                                 "-5:60:3", "nan:60:3", "0:60:1", "30,0", "0,,30", "0,95"])
def test_restitution_refuses_bad_ranges(tmp_path, bad):
    out = tmp_path / "out"
    proc = subprocess.run(
        [sys.executable, "-m", "dumbbell.cli", "restitution", str(SCENES / "tilted-2d.toml"),
         "--theta", bad, "--out", str(out), "-q"],
        capture_output=True, text=True, cwd=ROOT, check=False)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "--theta" in proc.stderr
    assert not out.exists()


def test_restitution_command_writes_csv(tmp_path):
    """pymunk's step is 1e-4 s here (the command's --dt; its default is 1e-5 s): the columns
    checked are the tilts, the formula and the truth, which do not depend on it."""
    from dumbbell.cli import main

    assert main(["restitution", str(SCENES / "tilted-2d.toml"), "--theta", "0:60:3",
                 "--stiffness", "2000", "--dt", "1e-4", "--out", str(tmp_path), "-q"]) == 0
    rows = np.genfromtxt(tmp_path / "tilted-2d-restitution.csv", delimiter=",", names=True)
    assert list(rows["theta"]) == [0.0, 30.0, 60.0]
    assert main(["restitution", str(SCENES / "tilted-2d.toml"), "--theta", "10,50",
                 "--elasticity", "0.5", "--stiffness", "2000", "--dt", "1e-4", "--out",
                 str(tmp_path), "-q"]) == 0
    rows = np.genfromtxt(tmp_path / "tilted-2d-restitution.csv", delimiter=",", names=True)
    assert list(rows["theta"]) == [10.0, 50.0]
    assert np.allclose(rows["formula"], e_eff_rigid(rows["theta"], 0.5), atol=1e-15)
    assert np.allclose(rows["truth"], rows["formula"], atol=1e-9)
    assert (tmp_path / "tilted-2d-restitution.png").stat().st_size > 10_000


def test_truth_solvers_decline_resting_contact(topple_scene):
    from dumbbell.solvers import solver_class

    assert "resting contact" in solver_class("reference").supports(topple_scene)
    assert solver_class("pymunk").supports(topple_scene) is None
    # The same dumbbell a millimetre above the floor is an ordinary drop.
    assert solver_class("reference").supports(
        topple_scene.with_values({"bodies.B.height": 1e-3})) is None


@pytest.mark.parametrize("solver,tol", [("exact", 1e-12), ("pymunk", 1e-9)])
def test_angular_momentum_about_the_contact_point(solver, tol):
    from dumbbell.analysis.contact import about_contact

    scene = load_scene(SCENES / "rigid-2d.toml")
    traj = simulate(scene, solver, t_end=0.6, every=1, dt=1e-5 if solver == "pymunk" else 1e-4)
    c = about_contact(traj)
    assert abs(c.change) < tol
    # L_cm jumps from 0 to I*omega with the impulse law's omega (rigid, e = 1, 30 degrees):
    # omega = J a sin(theta) / I, J = (1 + e) m_eff v, 1/m_eff = 1/M + (a sin theta)^2 / I.
    M, L, g, h = scene.system.M, 0.2, scene.system.g, scene.system.B.height
    I, a, s = scene.system.mu * L**2, L / 2, math.sin(math.radians(30.0))
    v = math.sqrt(2 * g * h)
    omega = -(1 + 1.0) * v / (1 / M + (a * s) ** 2 / I) * a * s / I
    assert c.L_cm_before == pytest.approx(0.0, abs=1e-12)
    assert c.L_cm_after == pytest.approx(I * omega, rel=1e-9 if solver == "exact" else 1e-4)


def test_run_draws_the_contact_figure(tmp_path):
    from dumbbell.cli import main

    scene = load_scene(SCENES / "rigid-2d.toml")
    assert "contact" in scene.outputs.figures
    short = tmp_path / "rigid.toml"
    text = (SCENES / "rigid-2d.toml").read_text().replace("t_end = 10.0", "t_end = 0.6")
    short.write_text(text.replace("gif = {", "# gif = {"))
    assert main(["run", str(short), "--out", str(tmp_path / "out"), "-q"]) == 0
    assert (tmp_path / "out" / "rigid-contact.png").stat().st_size > 10_000
