"""Hostile input, third sweep (issue 24's classes, variants the first two rounds left out):
empty strings given to flags that name a file, folder, solver or size, and the pymunk-facing
API on spaces whose own settings (gravity, springs, shapes) are not finite numbers."""

from __future__ import annotations

import math

import pytest

from tests.hostile import cli, refused, short_scene


def _text_flags() -> list[tuple[str, str]]:
    """Every flag of every command that takes a word (no number type of its own)."""
    from tests.test_fuzz_cli import COMMANDS, FLAGS

    skip = {"--grid", "--theta"}  # parsed by their own rules, tested elsewhere
    return [(c, f.names[-1]) for c in COMMANDS for f in FLAGS[c]
            if f.metavar and f.names[-1] not in skip]


@pytest.mark.parametrize("command,flag", _text_flags())
def test_an_empty_value_is_refused_naming_the_flag(tmp_path, monkeypatch, command, flag):
    """`-o ''` wrote to standard output, `--events ''` dropped the events, `--out ''` wrote
    into the working folder, `render --size ''` took the scene's size: an empty word is
    never what a user meant. Every flag refuses it, in one line naming the flag, before any
    work, leaving nothing behind."""
    from tests.test_fuzz_cli import SHORT_2D

    (tmp_path / "in").mkdir()
    scene = short_scene(tmp_path / "in")
    if command == "restitution":
        scene.write_text(SHORT_2D, encoding="utf-8")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    positional = [] if command == "stability" else [scene]
    extra = ["--grid", "k=1,2"] if command == "sweep" else []
    status, _, err = cli(command, *positional, *extra, flag, "")
    line = refused(status, err, work)
    names = [n for n in (flag, flag.lstrip("-")) if n in line]
    assert names, line


# --- the pymunk-facing API: a space's own settings ----------------------------------------

pymunk = pytest.importorskip("pymunk")


def _space(gravity=(0.0, -9.81), k=50.0, rest=1.0, anchor=(0.0, 0.0)):
    """Two balls over a floor, joined by a spring."""
    s = pymunk.Space()
    s.gravity = gravity
    s.add(pymunk.Segment(s.static_body, (-5, 0), (5, 0), 0.05))
    balls = []
    for x in (0.0, 1.2):
        b = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.1))
        b.position = (x, 1.0)
        s.add(b, pymunk.Circle(b, 0.1))
        balls.append(b)
    s.add(pymunk.DampedSpring(balls[0], balls[1], anchor, (0, 0), rest, k, 0.0))
    return s


NONFINITE = [math.nan, math.inf, -math.inf]


def _every_entry(space):
    from dumbbell import spaces

    return {
        "energy": lambda: spaces.energy(space),
        "Ledger": lambda: spaces.Ledger(space),
        "report": lambda: spaces.report(space, 1 / 60),
        "check": lambda: spaces.check(space, 1 / 60),
        "suggest_dt": lambda: spaces.suggest_dt(space, 1 / 60),
        "Driver": lambda: spaces.Driver(space, 1 / 60),
        "reach": lambda: spaces.reach(space, 1 / 60),
        "Recorder": lambda: spaces.Recorder(space, "never-written.gif"),
    }


def _refuses_or_flags(space, words):
    """Every entry of the API refuses the space with a DumbbellError whose message holds one
    of ``words``, or (the guard) reports it as a state no step fixes; none returns a NaN or an
    infinite energy as a number, and none suggests a step."""
    from dumbbell import DumbbellError

    for name, call in _every_entry(space).items():
        try:
            result = call()
        except DumbbellError as exc:
            assert any(w in str(exc) for w in words), (name, str(exc))
            assert len(str(exc).splitlines()) == 1, (name, str(exc))
            continue
        if name in ("check",):
            states = [f for f in result if f.kind == "state"]
            assert states and any(w in states[0].fix or w in states[0].subject for w in words), \
                (name, result)
            assert "no step fixes it" in states[0].fix, states[0].fix
            assert all(f.kind == "state" or f.dt_max is None or f.dt_max > 0 for f in result)
        elif name == "report":
            assert any(w in result for w in words) and "state" in result, (name, result)
        elif name == "suggest_dt":
            pytest.fail(f"suggest_dt suggested {result} for a space no step fixes")
        else:
            pytest.fail(f"{name} took the space: {result!r}"[:300])


@pytest.mark.parametrize("bad", NONFINITE, ids=["nan", "inf", "-inf"])
@pytest.mark.parametrize("axis", [0, 1])
def test_a_non_finite_gravity_is_refused_naming_it(bad, axis):
    """`space.gravity = (0, nan)` gave E = nan as a number, and the guard a tunnelling speed
    of inf units/s."""
    g = [0.0, -9.81]
    g[axis] = bad
    _refuses_or_flags(_space(gravity=tuple(g)), ["gravity"])


@pytest.mark.parametrize("field,value", [
    ("k", math.nan), ("k", math.inf), ("rest", math.nan), ("rest", math.inf),
    ("anchor", (math.nan, 0.0)), ("anchor", (0.0, math.inf)),
])
def test_a_spring_that_is_not_finite_is_refused_naming_it(field, value):
    """A DampedSpring of stiffness nan gave U_spring = nan as a number, and the guard
    `dt < 0 s keeps the swing under 1 %`, a step that does not exist."""
    words = {"k": "stiffness", "rest": "rest_length", "anchor": "anchor"}[field]
    _refuses_or_flags(_space(**{field: value}), [words])


@pytest.mark.parametrize("value", [math.nan, math.inf])
def test_a_rotary_spring_that_is_not_finite_is_refused(value):
    s = _space()
    a, b = [x for x in s.bodies]
    s.add(pymunk.DampedRotarySpring(a, b, value, 5.0, 0.0))
    _refuses_or_flags(s, ["rest_angle"])
    s = _space()
    a, b = [x for x in s.bodies]
    s.add(pymunk.DampedRotarySpring(a, b, 0.0, value, 0.0))
    _refuses_or_flags(s, ["stiffness"])


@pytest.mark.parametrize("speed", [1e200, 1e300])
def test_an_energy_past_the_floats_is_refused_naming_the_body(speed):
    """A dynamic body at 1e300 m/s: its kinetic energy, 1/2 m v^2, is inf; energy() returned
    it as a number (with an overflow warning)."""
    import warnings

    from dumbbell import DumbbellError, spaces

    for attr, value in (("velocity", (speed, 0.0)), ("angular_velocity", speed)):
        s = _space()
        body = list(s.bodies)[1]
        setattr(body, attr, value)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with pytest.raises(DumbbellError, match=r"body 1.*overflow") as info:
                spaces.energy(s)
            assert len(str(info.value).splitlines()) == 1
            with pytest.raises(DumbbellError, match=r"body 1.*overflow"):
                spaces.Ledger(s)


def test_a_finite_space_still_counts():
    """The checks leave an ordinary space alone: E is its hand-computed energy."""
    from dumbbell import spaces

    s = _space(k=50.0, rest=1.0)
    e = spaces.energy(s)
    # two 1 kg balls at height 1 m, at rest, the spring stretched by 0.2 m
    assert e.E == pytest.approx(2 * 9.81 * 1.0 + 0.5 * 50.0 * 0.2 ** 2, rel=1e-12)


@pytest.mark.parametrize("how", ["no shapes' mass", "mass 0 set"])
def test_stepping_a_body_pymunk_cannot_step_is_a_dumbbell_error(how):
    """spaces.step and Driver.step on a dynamic body of mass 0 let pymunk's AssertionError
    out; they name the body instead, and step nothing."""
    from dumbbell import DumbbellError, spaces

    s = _space()
    body = pymunk.Body()
    shape = pymunk.Circle(body, 0.1)
    if how == "mass 0 set":
        shape.mass = 0
    s.add(body, shape)
    before = [tuple(b.position) for b in s.bodies]
    for call in (lambda: spaces.step(s, 1 / 60, 4),
                 lambda: spaces.Driver(s, 1 / 60, substeps=4).step(2)):
        with pytest.raises(DumbbellError, match=r"space: .*mass") as info:
            call()
        assert len(str(info.value).splitlines()) == 1
    assert [tuple(b.position) for b in s.bodies] == before


def _shape_space(kind, bad):
    import pymunk

    s = pymunk.Space()
    s.gravity = (0.0, -9.81)
    s.add(pymunk.Segment(s.static_body, (-5, 0), (5, 0), 0.05))
    b = pymunk.Body(2.0, 3.0)
    b.position, b.velocity = (0.5, 1.5), (0.25, -1.0)
    shape = {"radius": lambda: pymunk.Circle(b, bad),
             "offset": lambda: pymunk.Circle(b, 0.1, (bad, 0.0)),
             "end": lambda: pymunk.Segment(b, (0.0, 0.0), (0.0, bad), 0.02),
             "seg-radius": lambda: pymunk.Segment(b, (0.0, 0.0), (0.3, 0.0), bad)}[kind]()
    s.add(b, shape)
    return s


@pytest.mark.parametrize("bad", NONFINITE, ids=["nan", "inf", "-inf"])
@pytest.mark.parametrize("kind", ["radius", "offset", "end", "seg-radius"])
def test_a_shape_that_is_not_finite_is_named_by_the_guard(kind, bad):
    """A Circle of radius nan gave `tunnelling at up to nan units/s` (or a Reach of now =
    nan), one of radius inf a numpy warning: the guard names the shape and its field as a
    state no step fixes. The energy does not depend on the shapes and still counts, to the
    hand computation: 1/2 m v^2 + 1/2 I w^2 + m g y."""
    import warnings

    from dumbbell import DumbbellError, spaces

    word = {"radius": "radius", "offset": "offset", "end": "b =", "seg-radius": "radius"}[kind]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        space = _shape_space(kind, bad)
        found = [f for f in spaces.check(space, 1 / 60) if f.kind == "state"]
        assert found and "shape 1" in found[0].subject and word in found[0].fix, found
        assert "no step fixes it" in found[0].fix
        text = spaces.report(space, 1 / 60)
        assert "shape 1" in text and "nan units" not in text
        for call in (lambda: spaces.suggest_dt(space, 1 / 60),
                     lambda: spaces.Driver(space, 1 / 60),
                     lambda: spaces.reach(space, 1 / 60)):
            with pytest.raises(DumbbellError, match="shape 1"):
                call()
        e = spaces.energy(space)
    assert e.E == pytest.approx(0.5 * 2.0 * (0.25**2 + 1.0) + 2.0 * 9.81 * 1.5, rel=1e-12)


def test_a_bad_spring_is_named_by_its_place_among_the_constraints():
    """Every part of dumbbell.spaces names a constraint by its place in space.constraints
    ('DampedSpring 1' after a PinJoint): the refusal of a spring that is not finite too, in
    spaces.energy (which reads the settings its inventory took), the guard and the recorder.
    A custom force function leaves the spring out of the energy, not out of the check."""
    from dumbbell import DumbbellError, spaces

    s = _space(k=math.nan)
    a, b = [x for x in s.bodies]
    spring = next(iter(s.constraints))
    s.remove(spring)
    s.add(pymunk.PinJoint(a, b), spring)
    assert spaces.energy(_space()).springs[0].subject == "DampedSpring 0"
    for call in (lambda: spaces.energy(s), lambda: spaces.reach(s, 1 / 60),
                 lambda: spaces.Recorder(s, "never-written.gif")):
        with pytest.raises(DumbbellError, match=r"DampedSpring 1: stiffness = nan"):
            call()
    found = [f for f in spaces.check(s, 1 / 60) if f.kind == "state"]
    assert found[0].subject == "DampedSpring 1", found
    spring.force_func = lambda c, d: 0.0
    with pytest.raises(DumbbellError, match=r"DampedSpring 1: stiffness = nan"):
        spaces.energy(s)
