"""Scene loading: the shipped scenes, every kind of bad input, and dotted overrides."""

from __future__ import annotations

import math

import pytest

from dumbbell import SceneError, load_scene
from dumbbell.cli import main
from dumbbell.model.scene import scene_from_dict
from dumbbell.solvers import scene_solver
from tests.conftest import SCENES

GOOD = """\
title = "ok"
dimensions = 1
[bodies.A]
mass = 0.1
height = 1.2
[bodies.B]
mass = 0.1
height = 1.0
[spring]
stiffness = 200.0
rest_length = 0.2
[floor]
elasticity = 1.0
[gravity]
g = 9.8
[run]
t_end = 0.01
dt = 1e-5
"""

#: (what is wrong, replace this, with this, the key the message must name, allowed-text part)
BAD = [
    ("unknown key", "[floor]\n", "[floor]\ncolour = 'red'\n", "floor.colour", "allowed"),
    ("unknown table", "[gravity]\n", "[wind]\nspeed = 1.0\n[gravity]\n", "wind", "allowed"),
    ("wrong type", "mass = 0.1\nheight = 1.2", "mass = '0.1'\nheight = 1.2", "bodies.A.mass",
     "finite number"),
    ("not finite", "stiffness = 200.0", "stiffness = inf", "spring.stiffness", "finite"),
    ("nan", "g = 9.8", "g = nan", "gravity.g", "finite"),
    ("mass zero", "mass = 0.1\nheight = 1.0", "mass = 0.0\nheight = 1.0", "bodies.B.mass", "> 0"),
    ("negative stiffness", "stiffness = 200.0", "stiffness = -1.0", "spring.stiffness", ">= 0"),
    ("negative rest length", "rest_length = 0.2", "rest_length = -0.2", "spring.rest_length",
     ">= 0"),
    ("dt zero", "dt = 1e-5", "dt = 0.0", "run.dt", "> 0"),
    ("dt above t_end", "dt = 1e-5", "dt = 0.5", "run.dt", "<= run.t_end"),
    ("below the floor", "height = 1.0", "height = -0.1", "bodies.B.height", ">= 0"),
    ("A below B", "height = 1.2", "height = 0.9", "bodies.A.height", "bodies.B.height"),
    ("elasticity above 1", "elasticity = 1.0", "elasticity = 1.5", "floor.elasticity", "<= 1"),
    ("unknown solver", "dt = 1e-5", "dt = 1e-5\nsolver = 'no-such-solver'", "run.solver", "one of"),
    ("bad dimensions", 'dimensions = 1', 'dimensions = 3', "dimensions", "<= 2"),
    ("missing mass", "mass = 0.1\nheight = 1.2", "height = 1.2", "bodies.A.mass", "missing"),
    ("not TOML", "[run]", "[run", "", "not valid TOML"),
    ("friction in 1D", "elasticity = 1.0", "elasticity = 1.0\nfriction = 0.3", "floor.friction",
     "1D"),
    ("bool as number", "t_end = 0.01", "t_end = true", "run.t_end", "finite number"),
]


def test_shipped_scenes_load():
    paths = sorted(SCENES.rglob("*.toml"))
    assert paths, "no scenes shipped"
    for path in paths:
        load_scene(path)


def test_every_shipped_scene_reads_back_from_its_dict():
    paths = sorted(SCENES.rglob("*.toml"))
    placed = 0
    for path in paths:
        scene = load_scene(path)
        doc = scene.to_dict()
        assert scene_from_dict(doc, scene.source) == scene, path.name
        placed += "tilt" in doc and "height" not in doc["bodies"]["A"]
        doc["bodies"]["B"]["mass"] = 99.0  # a fresh dict: the scene does not change
        assert scene.system.B.mass != 99.0 and scene.to_dict()["bodies"]["B"]["mass"] != 99.0
    assert placed >= 3  # tilt-placed scenes are among them


def test_a_scene_is_physics_plus_settings_with_no_document_kept(textbook):
    assert not hasattr(textbook, "raw") and not hasattr(textbook, "A")
    assert textbook.system.A.height == 1.2 and textbook.system.M == 0.2


def test_with_values_moves_a_tilt_placed_a_with_the_length():
    tilted = load_scene(SCENES / "tilted-2d.toml")
    tilt = tilted.system.tilt
    longer = tilted.with_values({"spring.rest_length": 0.35})
    A, B = longer.system.A, longer.system.B
    assert math.hypot(A.x - B.x, A.height - B.height) == pytest.approx(0.35, rel=1e-12)
    assert math.degrees(math.atan2(A.x - B.x, A.height - B.height)) == pytest.approx(tilt)
    with pytest.raises(SceneError, match="left out when 'tilt' places A"):
        tilted.with_values({"bodies.A.height": 1.0})


def test_the_gif_length_follows_the_run_unless_given(textbook):
    gif = textbook.with_values({"outputs.gif.fps": 10})
    assert gif.outputs.gif.t_end == textbook.run.t_end
    assert gif.with_values({"run.t_end": 0.5}).outputs.gif.t_end == 0.5
    own = gif.with_values({"outputs.gif.t_end": 2.0})
    assert own.with_values({"run.t_end": 0.5}).outputs.gif.t_end == 2.0


def test_textbook_scene_holds_the_textbook_values(textbook):
    s = textbook
    sy = s.system
    assert (sy.A.mass, sy.B.mass) == (0.1, 0.1)
    assert (sy.spring.stiffness, sy.spring.rest_length) == (200.0, 0.2)
    assert (sy.B.height, sy.A.height, sy.g, s.run.t_end, s.run.dt) == (1.0, 1.2, 9.8, 10.0, 1e-5)
    assert s.system.floor.elasticity == 1.0 and s.run.solver == "euler-cromer"


@pytest.mark.parametrize("what,old,new,key,allowed", BAD, ids=[b[0] for b in BAD])
def test_bad_scene_raises_one_scene_error(tmp_path, what, old, new, key, allowed):
    assert old in GOOD
    path = tmp_path / "bad.toml"
    path.write_text(GOOD.replace(old, new, 1))
    with pytest.raises(SceneError) as info:
        # Which solver names exist is the solver registry's to say, so it checks run.solver.
        scene_solver(load_scene(path))
    message = str(info.value)
    assert str(path) in message and key in message and allowed in message
    assert "\n" not in message


@pytest.mark.parametrize("what,old,new,key,allowed", BAD, ids=[b[0] for b in BAD])
def test_bad_scene_exits_2_with_one_line_and_writes_nothing(tmp_path, capsys, what, old, new,
                                                            key, allowed):
    path = tmp_path / "bad.toml"
    path.write_text(GOOD.replace(old, new, 1))
    out = tmp_path / "out"
    for argv in (["simulate", str(path), "-o", str(out / "t.csv"), "--events",
                  str(out / "e.csv")], ["run", str(path), "--out", str(out)]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "Traceback" not in err and str(path) in err
        assert not out.exists()


def test_missing_file_is_a_scene_error(tmp_path):
    with pytest.raises(SceneError, match="no such scene file"):
        load_scene(tmp_path / "nope.toml")


def test_good_scene_loads(tmp_path):
    path = tmp_path / "good.toml"
    path.write_text(GOOD)
    scene = load_scene(path)
    assert scene.system.floor is not None and scene.system.spring.stiffness == 200.0


def test_left_out_tables_are_not_built(tmp_path):
    text = GOOD.replace("[floor]\nelasticity = 1.0\n", "").replace("[gravity]\ng = 9.8\n", "")
    path = tmp_path / "bare.toml"
    path.write_text(text)
    scene = load_scene(path)
    assert scene.system.floor is None and scene.system.g == 0.0


def test_with_values_revalidates(textbook):
    stiff = textbook.with_values({"spring.stiffness": 2e4, "run.dt": 1e-4})
    assert stiff.system.spring.stiffness == 2e4 and stiff.run.dt == 1e-4
    assert textbook.system.spring.stiffness == 200.0  # the original is untouched
    with pytest.raises(SceneError, match="spring.stiffness"):
        textbook.with_values({"spring.stiffness": -5.0})


def test_spinning_discs_are_physics_on_the_system_not_an_engine_setting():
    from dumbbell.model.energy import energy_columns
    from dumbbell.solvers import simulate

    flat = load_scene(SCENES / "tilted-2d.toml")
    discs = flat.with_values({"pymunk.spin": True})
    assert not flat.system.discs and discs.system.discs
    assert not hasattr(discs.pymunk, "spin")              # the engine settings do not hold it
    assert "K_spin" in energy_columns(discs) and "K_spin" not in energy_columns(flat)
    assert scene_from_dict(discs.to_dict(), discs.source) == discs
    # A 1D line has nothing to spin: the key is accepted and changes nothing.
    line = load_scene(SCENES / "textbook-1d.toml")
    assert line.with_values({"pymunk.spin": True}) == line
    # The solvers follow the system: pymunk gives each disc its moment 1/2 m r^2 and its own
    # spin, so K_spin starts at sum 1/4 m r^2 w^2 (J).
    spun = discs.with_values({"bodies.A.spin": 4.0, "bodies.B.spin": -2.0})
    run = simulate(spun, "pymunk", t_end=0.01, dt=1e-3)
    A, B = spun.system.A, spun.system.B
    expected = 0.25 * (A.mass * A.radius**2 * 4.0**2 + B.mass * B.radius**2 * 2.0**2)
    assert run["K_spin"][0] == pytest.approx(expected, rel=1e-12)
    # A solver of point particles declines discs, by the system's word.
    from dumbbell.solvers import METHODS

    assert "point particles" in (METHODS["euler-cromer-2d"].supports(spun) or "")
    assert METHODS["euler-cromer-2d"].supports(spun.with_values({"pymunk.spin": False})) is None
