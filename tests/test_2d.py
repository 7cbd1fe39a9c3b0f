"""2D scenes: the energy partition's identities, rotation, friction, the rigid dumbbell, the
2D reference, the hand-written 2D Euler-Cromer, and `dumbbell compare`."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dumbbell.cli import main
from dumbbell.model.energy import partition_2d
from dumbbell.model.scene import load_scene, scene_from_dict
from dumbbell.solvers import simulate, solver_class
from tests.conftest import SCENES, make_scene

G = 9.8


@pytest.fixture(scope="module")
def tilted():
    return load_scene(SCENES / "tilted-2d.toml")


@pytest.fixture(scope="module")
def rigid():
    return load_scene(SCENES / "rigid-2d.toml")


@pytest.fixture(scope="module")
def friction():
    return load_scene(SCENES / "friction-2d.toml")


@pytest.fixture(scope="module")
def tilted_run(tilted):
    """2 s of the tilted dumbbell in pymunk at dt = 1e-5 (the issue's energy bar)."""
    return simulate(tilted, "pymunk", dt=1e-5, t_end=2.0, every=20)


def _sum_half_m_v2(traj) -> np.ndarray:
    mA, mB = traj.scene.system.A.mass, traj.scene.system.B.mass
    return (0.5 * mA * (traj["vxA"] ** 2 + traj["vyA"] ** 2)
            + 0.5 * mB * (traj["vxB"] ** 2 + traj["vyB"] ** 2))


def test_partition_identity_on_every_row(tilted_run):
    K = tilted_run["K_cm"] + tilted_run["K_rot"] + tilted_run["K_vib"]
    np.testing.assert_allclose(K, _sum_half_m_v2(tilted_run), rtol=1e-12, atol=1e-14)


def test_partition_identity_on_random_states():
    rng = np.random.default_rng(3)
    n = 1000
    rA, rB, vA, vB = (rng.normal(size=(n, 2)) for _ in range(4))
    mA, mB = 0.3, 0.07
    system = make_scene({"bodies.A.mass": mA, "bodies.B.mass": mB, "spring.stiffness": 50.0,
                         "spring.rest_length": 0.2, "gravity.g": G}).system
    parts = partition_2d(system, rA, vA, rB, vB)
    K = parts["K_cm"] + parts["K_rot"] + parts["K_vib"]
    expected = 0.5 * mA * (vA**2).sum(axis=1) + 0.5 * mB * (vB**2).sum(axis=1)
    np.testing.assert_allclose(K, expected, rtol=1e-12)
    # K_rot is the rotation of the axis: 1/2 mu L^2 theta'^2.
    d, w = rA - rB, vA - vB
    theta_dot = (d[:, 0] * w[:, 1] - d[:, 1] * w[:, 0]) / (d**2).sum(axis=1)
    mu = mA * mB / (mA + mB)
    np.testing.assert_allclose(parts["K_rot"], 0.5 * mu * (d**2).sum(axis=1) * theta_dot**2,
                               rtol=1e-10)


def test_2d_columns(tilted_run, friction, rigid):
    assert tilted_run.columns == ["t", "xA", "yA", "vxA", "vyA", "xB", "yB", "vxB", "vyB",
                                  "K_cm", "K_rot", "K_vib", "U_g", "U_spring", "E", "L_cm"]
    assert "U_spring" not in simulate(rigid, "pymunk", dt=1e-4, t_end=0.01).columns
    cols = simulate(friction, "pymunk", dt=1e-4, t_end=0.01).columns
    assert cols[-5:] == ["E", "E_lost", "E_heat", "E_err", "L_cm"] and "K_spin" in cols


def test_tilted_drop_produces_rotation(tilted_run):
    first = tilted_run.events[0]
    assert first.body == "B" and first.t == pytest.approx(math.sqrt(2 / G), abs=2e-5)
    before = tilted_run.t < first.t - 1e-3
    assert np.max(tilted_run["K_rot"][before]) < 1e-20
    after = (tilted_run.t > first.t + 1e-3) & (tilted_run.t < first.t + 0.04)
    assert np.max(tilted_run["K_rot"][after]) > 0.3
    # The floor is frictionless: horizontal momentum stays 0.
    px = 0.1 * tilted_run["vxA"] + 0.1 * tilted_run["vxB"]
    assert np.max(np.abs(px)) < 1e-12


def test_untilted_2d_drop_has_no_rotation(tilted):
    upright = tilted.with_values({"tilt": 0.0})
    run = simulate(upright, "pymunk", dt=1e-4, t_end=1.5, every=10)
    assert len(run.events) >= 2
    assert np.max(run["K_rot"]) < 1e-20


def test_energy_conserved_without_friction(tilted_run):
    E = tilted_run["E"]
    assert tilted_run.verdict.ok
    assert np.max(np.abs(E - E[0])) / E[0] < 1e-3


def test_friction_loses_energy_and_the_partition_adds_up(friction):
    run = simulate(friction, "pymunk", dt=1e-5, t_end=1.2, every=20)
    assert run.verdict.ok
    E0 = run["E"][0]
    total = sum(run[c] for c in ("K_cm", "K_rot", "K_vib", "K_spin", "U_g", "U_spring"))
    np.testing.assert_allclose(total + run["E_lost"], E0, rtol=1e-12)
    lost = run["E_lost"]
    assert lost[-1] > 0.05 * E0  # friction took a real share
    # It grows at the contacts and does not come back: never more than the step's energy
    # error (1e-3 of E at dt = 1e-5) below its largest value so far.
    assert np.all(lost >= np.maximum.accumulate(lost) - 1e-3 * E0)
    # Before the first contact nothing is lost.
    first = run.events[0].t
    assert np.max(np.abs(lost[run.t < first - 1e-3])) < 1e-3 * E0
    # Friction at the contact sets the particles spinning.
    assert np.max(run["K_spin"]) > 1e-3


def test_rigid_k_rot_is_half_i_omega_squared(rigid):
    run = simulate(rigid, "pymunk", dt=1e-5, t_end=1.2, every=20)
    assert run.verdict.ok
    I = 0.05 * 0.2**2
    assert run.info["moment"] == pytest.approx(I)
    np.testing.assert_allclose(run["K_rot"], 0.5 * I * run.state["omega"] ** 2,
                               rtol=1e-9, atol=1e-15)
    assert np.max(run["K_vib"]) < 1e-20
    assert "omega" not in run.columns  # kept in the state, not in the CSV contract
    # The first impact's share of rotation from the impulse law J = 2 v / (1/M + r_x^2 / I).
    v = math.sqrt(2 * G * 1.0)
    rx = 0.1 * math.sin(math.radians(30))
    J = 2 * v / (1 / 0.2 + rx**2 / I)
    k_rot = 0.5 * I * (rx * J / I) ** 2
    after = (run.t > run.events[0].t + 1e-3) & (run.t < run.events[0].t + 0.05)
    np.testing.assert_allclose(run["K_rot"][after], k_rot, rtol=1e-3)
    # The rotation figure's mean: one impact, then the whole flight to the next one.
    from dumbbell.analysis.rotation import mean_after_first_cluster

    mean, start, end = mean_after_first_cluster(run, "K_rot")
    assert (start, end) == (run.events[0].t, run.events[1].t)
    assert mean == pytest.approx(k_rot, rel=1e-3)
    E = run["E"]
    assert np.max(np.abs(E - E[0])) / E[0] < 1e-4


def test_rigid_reference_agrees_with_pymunk(rigid):
    ref = simulate(rigid, "reference", dt=1e-3, t_end=1.2, every=1)
    run = simulate(rigid, "pymunk", dt=1e-5, t_end=1.2, every=100)
    err = max(np.max(np.abs(ref[c] - run[c])) for c in ("xA", "yA", "xB", "yB"))
    assert err < 1e-3
    assert ref.info["estimated_error"]["energy_relative"] < 1e-12
    np.testing.assert_allclose(ref["K_rot"], 0.5 * ref.info["moment"] * ref.state["omega"]**2,
                               rtol=1e-9, atol=1e-15)


def test_reference_matches_exact_in_1d(textbook):
    exact = simulate(textbook, "exact", dt=1e-3, t_end=2.0, every=1)
    ref = simulate(textbook, "reference", dt=1e-3, t_end=2.0, every=1)
    err = max(np.max(np.abs(ref[c] - exact[c])) for c in ("xA", "xB"))
    assert err < 1e-8
    assert [e.body for e in ref.events] == [e.body for e in exact.events]
    assert max(abs(a.t - b.t) for a, b in zip(ref.events, exact.events, strict=True)) < 1e-10
    est = ref.info["estimated_error"]
    assert est["position_m_window"] < 1e-8 and est["window_s"] == 2.0


def test_reference_energy_and_limits(tilted):
    ref = simulate(tilted, "reference", dt=1e-3, t_end=1.0, every=1)
    E = ref["E"]
    assert np.max(np.abs(E - E[0])) / E[0] < 1e-9
    assert "estimated_error" in ref.info
    assert "friction" in solver_class("reference").supports(
        load_scene(SCENES / "friction-2d.toml"))


def _free_flight(tilted):
    raw = tilted.to_dict()
    raw.pop("floor")
    raw["bodies"]["A"]["velocity"] = [-0.4, 2.5]
    raw["bodies"]["B"]["velocity"] = [0.7, 1.0]
    return scene_from_dict(raw, "free.toml")


def test_euler_cromer_2d_matches_pymunk_in_free_flight(tilted):
    scene = _free_flight(tilted)
    a = simulate(scene, "pymunk", dt=1e-4, t_end=2.0, every=1)
    b = simulate(scene, "euler-cromer-2d", dt=1e-4, t_end=2.0, every=1)
    assert np.ptp(a["K_vib"]) > 0.01 and np.ptp(a["K_rot"]) > 0  # the spring is working
    for c in ("xA", "yA", "vxA", "vyA", "xB", "yB", "vxB", "vyB"):
        np.testing.assert_allclose(b[c], a[c], rtol=0, atol=1e-12)


def test_euler_cromer_2d_matches_pymunk_through_impacts(tilted):
    a = simulate(tilted, "pymunk", dt=1e-4, t_end=1.5, every=1)
    b = simulate(tilted, "euler-cromer-2d", dt=1e-4, t_end=1.5, every=1)
    assert len(a.events) == len(b.events) >= 3
    for c in ("xA", "yA", "vxA", "vyA", "xB", "yB", "vxB", "vyB"):
        np.testing.assert_allclose(b[c], a[c], rtol=0, atol=1e-9)


def test_euler_cromer_2d_differs_from_the_textbook_order_by_the_velocity_lag(tilted):
    """Started from v0 - a(x0) dt, the textbook's order gives pymunk's positions: the lag."""
    scene = _free_flight(tilted).with_values({"tilt": 0.0, "bodies.A.velocity": [0.0, 2.5],
                                              "bodies.B.velocity": [0.0, 1.0]})
    run = simulate(scene, "euler-cromer-2d", dt=1e-4, t_end=0.5, every=1)
    # The textbook's Euler-Cromer in 1D (vertical) from the shifted start.
    A, B = scene.system.A, scene.system.B
    k, b, dt = 200.0, 0.2, 1e-4
    f = k * (A.height - B.height - b)
    xA, xB = A.height, B.height
    vA, vB = A.vy - (-f / 0.1 - G) * dt, B.vy - (f / 0.1 - G) * dt
    ys = []
    for _ in range(5000):
        f = k * (xA - xB - b)
        vA = vA + (-f / 0.1 - G) * dt
        xA = xA + vA * dt
        vB = vB + (f / 0.1 - G) * dt
        xB = xB + vB * dt
        ys.append((xA, xB))
    ys = np.array(ys)
    np.testing.assert_allclose(run["yA"][1:], ys[:, 0], atol=1e-12)
    np.testing.assert_allclose(run["yB"][1:], ys[:, 1], atol=1e-12)


def test_euler_cromer_2d_says_what_it_cannot_run(rigid, friction, textbook):
    module = solver_class("euler-cromer-2d")
    assert "rigid" in module.supports(rigid)
    assert "friction" in module.supports(friction)
    assert "1D" in module.supports(textbook)


def test_compare_writes_table_csv_and_figures(tmp_path, capsys):
    out = tmp_path / "cmp"
    status = main(["compare", str(SCENES / "textbook-1d.toml"), "--out", str(out),
                   "--t-end", "1.0", "--dt", "1e-4", "--window", "0.8", "--quiet"])
    assert status == 0
    text = capsys.readouterr().out
    assert "exact" in text and "pymunk" in text and "[0, 0.8] s" in text
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(["textbook-1d-compare.csv", "textbook-1d-compare-impacts.csv",
                            "textbook-1d-compare-errors.csv", "textbook-1d-compare-positions.png",
                            "textbook-1d-compare-error.png", "textbook-1d-compare-energy.png"])
    rows = (out / "textbook-1d-compare.csv").read_text().splitlines()
    assert rows[0].startswith("solver,dt,run_time_s")
    pym = next(r.split(",") for r in rows if r.startswith("pymunk"))
    assert 0 < float(pym[4]) < 3e-2  # error over the window at dt = 1e-4
    impacts = (out / "textbook-1d-compare-impacts.csv").read_text().splitlines()
    first = impacts[1].split(",")
    assert first[1] == "B" and abs(float(first[2]) - math.sqrt(2 / G)) < 1e-12


def test_compare_bad_solver_writes_nothing(tmp_path, capsys):
    out = tmp_path / "cmp"
    status = main(["compare", str(SCENES / "textbook-1d.toml"), "--out", str(out),
                   "--solvers", "pymunk,nonsense", "--quiet"])
    assert status == 2
    assert "--solvers" in capsys.readouterr().err
    assert not out.exists()
    status = main(["compare", str(SCENES / "textbook-1d.toml"), "--out", str(out),
                   "--solvers", "euler-cromer-2d", "--quiet"])
    assert status == 2 and not out.exists()


def test_rotation_variants_and_the_stiff_limit(tilted):
    """A stiff spring dumbbell does not take the rigid body's share of rotation at an
    impact: B alone is reversed, so K_rot = 1/2 mu (2 v sin 30)^2 for every k."""
    from dumbbell.analysis.rotation import variants

    scenes = variants(tilted)
    springs = [s.system.spring for s in scenes.values() if s.system.spring]
    assert [spring.stiffness for spring in springs] == [200.0, 2e3, 2e4]
    assert scenes["rigid"].system.rigid.length == 0.2
    rigid_A, tilted_A = scenes["rigid"].system.A, tilted.system.A
    assert (rigid_A.x, rigid_A.height) == (tilted_A.x, tilted_A.height)
    stiff = simulate(scenes["k = 20000 N/m"], "pymunk", dt=1e-5, t_end=0.6, every=10)
    v = math.sqrt(2 * G * 1.0)
    expected = 0.5 * 0.05 * (2 * v * 0.5) ** 2
    t1 = stiff.events[0].t
    just_after = np.flatnonzero(stiff.t > t1)[0]
    assert stiff["K_rot"][just_after] == pytest.approx(expected, rel=2e-2)
    # A lands about 0.07 s after B: the figure's mean starts after that landing, and the two
    # impacts together leave far less rotation than the rigid body's 1.25 J.
    from dumbbell.analysis.rotation import CLUSTER_GAP, mean_after_first_cluster

    (b_hit, a_hit), bodies = [e.t for e in stiff.events], [e.body for e in stiff.events]
    assert bodies == ["B", "A"] and 0.05 < a_hit - b_hit < CLUSTER_GAP
    mean, start, end = mean_after_first_cluster(stiff, "K_rot")
    assert (start, end) == (a_hit, stiff.t[-1])
    assert 0 < mean < 0.5 * 1.254


def test_no_floor_and_spin_columns():
    scene = make_scene(drop=("floor",), base={
        "title": "free", "dimensions": 2, "tilt": 45.0,
        "bodies": {"A": {"mass": 0.1, "spin": 3.0}, "B": {"mass": 0.2, "height": 1.0}},
        "spring": {"stiffness": 100.0, "rest_length": 0.3}, "floor": {},
        "gravity": {"g": G}, "pymunk": {"spin": True},
        "run": {"t_end": 0.5, "dt": 1e-4}})
    run = simulate(scene, "pymunk", every=10)
    assert "K_spin" in run.columns and "E_lost" not in run.columns
    I = 0.5 * 0.1 * 0.02**2
    np.testing.assert_allclose(run["K_spin"], 0.5 * I * 9.0, rtol=1e-12)
    assert not run.events


def test_rotation_figure_needs_a_2d_scene(textbook):
    from dumbbell.errors import SceneError

    with pytest.raises(SceneError, match="outputs.figures.*2D"):
        textbook.with_values({"outputs.figures": ["rotation"]})
