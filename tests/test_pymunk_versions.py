"""The pymunk range: the version check (with the installed version faked) and the 7.0.x way
of telling a spring's custom force function from pymunk's own, run on the installed pymunk
with 7.0.x's properties put back in place.

The real releases are run by ``benchmarks/pymunk_versions.py`` (one venv each)."""

from __future__ import annotations

import contextlib
import re
import tomllib
import types
from importlib.metadata import version as dist_version

import pymunk
import pytest

import dumbbell
from dumbbell import _pymunk, spaces
from dumbbell.cli import main
from dumbbell.errors import DumbbellError, PymunkVersionError

from .conftest import ROOT, SCENES

IN_RANGE = ["7.0.0", "7.0.1", "7.1.0", "7.2.0", "7.3.0", "7.3.1", "7.0", "7", "7.99.99",
            "7.3.1+local.build", "7.0.0.post1", "7.0.0-1", "v7.1.0", " 7.2.0 ", "7.3.2.dev4",
            "7.0.0.post1.dev0", "7.1.0rc1", "7.0.0\n"]
OUT_OF_RANGE = ["6.11.1", "6.8.1", "6.99", "2.0.0", "8.0.0", "8", "8.0.0a1", "8.0.0.dev0",
                "10.0", "7.0.0rc1", "7.0.0a1", "7.0.0.dev3", "7.0rc2", "0", "", "unknown",
                "7.x", "seven", "7..0", "7.0.", ".7", "7.0.0 extra", "7\n8", "6.11.1\n",
                "9" * 5000, "7." * 3000 + "0"]


def test_the_range_is_pyproject_s():
    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    assert [d for d in deps if re.match(r"pymunk\b", d)] == [_pymunk.RANGE]


@pytest.mark.parametrize("version", IN_RANGE)
def test_in_range(version):
    assert _pymunk.supported(version)
    _pymunk.check(version)


@pytest.mark.parametrize("version", OUT_OF_RANGE)
def test_out_of_range_is_one_line_naming_version_and_range(version):
    assert not _pymunk.supported(version)
    with pytest.raises(PymunkVersionError) as info:
        _pymunk.check(version)
    text = str(info.value)
    assert isinstance(info.value, DumbbellError) and "\n" not in text and len(text) < 200
    assert "pymunk>=7.0,<8" in text and info.value.supported == "pymunk>=7.0,<8"
    assert info.value.version == version
    shown = text.split(" is installed")[0].removeprefix("pymunk ")
    assert shown == version.strip() if len(version) < 40 and (
        _pymunk.release(version) is not None) else shown.startswith(repr(version)[:20])


def test_not_a_string_is_not_a_version():
    for value in (None, 7, 7.0, b"7.0.0", ["7.0.0"]):
        assert _pymunk.release(value) is None and not _pymunk.supported(value)


def test_the_installed_version_is_the_distribution_s():
    """pymunk 7.0.0 says ``pymunk.version == '2.0.0'``: the distribution's metadata is read
    when it is the package imported, the module's own string only otherwise."""
    assert _pymunk.installed_version(pymunk) == dist_version("pymunk")
    elsewhere = types.SimpleNamespace(__file__="/nowhere/pymunk/__init__.py", version="6.8.1")
    assert _pymunk.installed_version(elsewhere) == "6.8.1"
    assert _pymunk.installed_version(types.SimpleNamespace(__file__="/x/y.py")) == "unknown"


@pytest.fixture
def installed(monkeypatch):
    """Fake the installed pymunk's version: ``installed("6.11.1")``; the check's cache is
    cleared before and after."""
    def fake(version):
        monkeypatch.setattr(_pymunk, "installed_version", lambda module: version)
        _pymunk.require.cache_clear()

    yield fake
    monkeypatch.undo()
    _pymunk.require.cache_clear()


def ball_space():
    space = pymunk.Space()
    space.gravity = (0.0, -9.8)
    ball = pymunk.Body(1.0, 1.0)
    ball.position = (0.0, 1.0)
    space.add(ball, pymunk.Circle(ball, 0.1))
    return space


@pytest.mark.parametrize("version", ["6.11.1", "8.0.0", "2.0.0", "weird"])
def test_an_unsupported_pymunk_is_refused_at_its_first_use(installed, version, capsys):
    installed(version)
    shown = version if _pymunk.release(version) else repr(version)
    space = ball_space()
    calls = [lambda: spaces.energy(space), lambda: spaces.report(space, 0.01),
             lambda: spaces.Ledger(space), lambda: spaces.HeatCounter(space),
             lambda: spaces.check(space, 0.01), lambda: spaces.step(space, 0.01),
             lambda: spaces.shape_size(next(iter(space.shapes))),
             lambda: dumbbell.simulate(SCENES / "textbook-1d.toml", solver="pymunk",
                                       t_end=0.01)]
    for call in calls:
        with pytest.raises(PymunkVersionError, match=re.escape(f"pymunk {shown} is "
                                                               "installed; dumbbell needs "
                                                               "pymunk>=7.0,<8")):
            call()
    # The other solvers do not use pymunk: they still run.
    traj = dumbbell.simulate(SCENES / "textbook-1d.toml", solver="exact", t_end=0.01)
    assert len(traj.t) > 1
    capsys.readouterr()
    code = main(["simulate", "--solver", "pymunk", str(SCENES / "textbook-1d.toml"),
                 "--t-end", "0.01", "-q"])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and f"pymunk {shown} is installed" in err
    assert "pymunk>=7.0,<8" in err


def test_a_supported_version_passes(installed):
    installed("7.0.0")
    assert spaces.energy(ball_space()).E == pytest.approx(9.8)


# --- pymunk 7.0.x: force_func has a setter only, torque_func a getter that raises ---------

def _setter_only(prop):
    return property(fset=prop.fset, doc=prop.__doc__)


def _unreadable(prop, name):
    def getter(self):
        raise AttributeError(f"unreadable attribute '{name}'")

    return property(getter, prop.fset, doc=prop.__doc__)


@contextlib.contextmanager
def pymunk_7_0():
    """pymunk's spring classes with their Python side as in 7.0.0/7.0.1: ``force_func``
    has no getter and DampedSpring no class-level ``_force_func`` (so reading
    ``spring._force_func`` of a spring with pymunk's own function raises AttributeError, the
    error those releases gave); ``torque_func``'s getter raises. The setters are the
    installed release's own, which keep the function as ``_force_func``/``_torque_func`` on
    the spring and hand pymunk's C side the callback, as 7.0.x's do."""
    with pytest.MonkeyPatch.context() as m:
        m.setattr(pymunk.DampedSpring, "force_func", _setter_only(pymunk.DampedSpring.force_func))
        m.delattr(pymunk.DampedSpring, "_force_func")
        m.setattr(pymunk.DampedRotarySpring, "torque_func",
                  _unreadable(pymunk.DampedRotarySpring.torque_func, "torque_func"))
        _pymunk._reader.cache_clear()
        try:
            yield
        finally:
            _pymunk._reader.cache_clear()


def springs(custom):
    """Two bodies on a DampedSpring and a DampedRotarySpring: with custom functions (the
    same laws as pymunk's own), explicitly pymunk's own, or left alone (None)."""
    space = pymunk.Space()
    a, b = pymunk.Body(1.0, 0.1), pymunk.Body(1.0, 0.1)
    b.position, b.angular_velocity = (1.0, 0.0), 1.0
    spring = pymunk.DampedSpring(a, b, (0, 0), (0, 0), 0.5, 10.0, 0.0)
    rotary = pymunk.DampedRotarySpring(a, b, 0.0, 3.0, 0.0)
    if custom is True:
        spring.force_func = lambda s, dist: -s.stiffness * (dist - s.rest_length)
        rotary.torque_func = lambda s, angle: -s.stiffness * (angle - s.rest_angle)
    elif custom is False:
        spring.force_func = pymunk.DampedSpring.spring_force
        rotary.torque_func = pymunk.DampedRotarySpring.spring_torque
    space.add(a, b, pymunk.Circle(a, 0.1), pymunk.Circle(b, 0.1), spring, rotary)
    return space, spring, rotary


def told_apart():
    """What energy, the guard and the ledger say about each kind of spring."""
    seen = {}
    for custom in (True, False, None):
        space, spring, rotary = springs(custom)
        e = spaces.energy(space)
        ledger = spaces.Ledger(space)
        rows = spaces.survey(space, 0.01)
        for _ in range(10):
            space.step(0.01)
        seen[custom] = (_pymunk.spring_function(spring), _pymunk.spring_function(rotary),
                        len(e.unknown), len(e.springs), len(ledger.balance().unaccounted),
                        len(rows))
    return seen


def test_custom_spring_functions_are_told_apart():
    seen = told_apart()
    assert callable(seen[True][0]) and callable(seen[True][1])
    assert seen[True][2:4] == (2, 0) and seen[True][4] >= 2
    assert seen[False][:5] == seen[None][:5] == (None, None, 0, 2, 0)


def test_the_7_0_properties_are_what_the_stand_in_copies():
    with pymunk_7_0():
        _, spring, rotary = springs(None)
        with pytest.raises(AttributeError):
            spring.force_func  # noqa: B018 - 7.0.x: no getter
        with pytest.raises(AttributeError, match="_force_func"):
            spring._force_func  # noqa: B018 - what dumbbell read before, and failed on
        with pytest.raises(AttributeError, match="unreadable"):
            rotary.torque_func  # noqa: B018


def test_custom_spring_functions_on_7_0():
    """energy, the guard and the ledger say the same with 7.0.x's properties as with the
    installed release's getters."""
    public = told_apart()
    with pymunk_7_0():
        on_7_0 = told_apart()
    assert callable(on_7_0[True][0]) and callable(on_7_0[True][1])
    for custom in (True, False, None):
        assert on_7_0[custom][2:] == public[custom][2:]
    assert on_7_0[False][:2] == on_7_0[None][:2] == (None, None)


def test_the_7_0_route_gives_what_the_public_getter_gives():
    """Both ways of reading a spring's function agree on the installed release (whose
    setter keeps the function where 7.0.x's does)."""
    for custom in (True, False, None):
        _, spring, rotary = springs(custom)
        for c, name in ((spring, "force_func"), (rotary, "torque_func")):
            default = _pymunk._default(type(c))
            public = getattr(c, name)
            kept = vars(c).get(f"_{name}")
            assert (public is default) == (kept in (None, default))
            assert public is kept or kept is None


def test_the_pymunk_solver_on_7_0_is_bit_for_bit(tmp_path):
    """The pymunk solver's CSV on the installed release and with 7.0.x's properties: the
    same bytes (the spring uses pymunk's own force either way)."""
    scene = SCENES / "textbook-1d.toml"
    dumbbell.simulate(scene, solver="pymunk", t_end=0.5, every=100).to_csv(tmp_path / "a.csv")
    with pymunk_7_0():
        dumbbell.simulate(scene, solver="pymunk", t_end=0.5, every=100).to_csv(tmp_path / "b.csv")
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()


class _Forgetful(pymunk.DampedSpring):
    """A release whose force_func keeps nothing the ledger could read back."""

    force_func = property(fset=lambda self, func: None)


def test_an_unreadable_force_function_is_a_version_error():
    with pytest.raises(PymunkVersionError, match=r"pymunk .*: dumbbell cannot tell which "
                                                 r"force_func a _Forgetful uses"):
        _pymunk._reader(_Forgetful, "force_func")


# --- pymunk 7.0.x: a body's velocity_func and position_func have a setter only ---------------

def _body_setter_7_0(name, default_c, getter):
    """7.0.x's setter (and 7.1.0-7.3.0's): a custom function is kept as ``_<name>`` and
    pymunk's callback set; the default sets Chipmunk's own function back and leaves the kept
    function in place. ``getter``: with 7.1.0-7.3.0's getter, which gives the kept function
    (pymunk's own when none is kept); else none, as on 7.0.x."""
    from pymunk._chipmunk_cffi import ffi, lib

    installed = getattr(pymunk.Body, name).fset
    default = pymunk.Body.update_velocity if name == "velocity_func" else \
        pymunk.Body.update_position
    set_c = lib.cpBodySetVelocityUpdateFunc if name == "velocity_func" else \
        lib.cpBodySetPositionUpdateFunc

    def setter(self, func):
        if func == default:
            set_c(self._body, ffi.addressof(lib, default_c))
        else:
            installed(self, func)

    def get(self):
        kept = getattr(self, f"_{name}")
        return default if kept is None else kept

    return property(get if getter else None, setter)


@contextlib.contextmanager
def bodies_7_0(getter=False):
    with pytest.MonkeyPatch.context() as m:
        m.setattr(pymunk.Body, "velocity_func",
                  _body_setter_7_0("velocity_func", "cpBodyUpdateVelocity", getter))
        m.setattr(pymunk.Body, "position_func",
                  _body_setter_7_0("position_func", "cpBodyUpdatePosition", getter))
        yield


def pendulum_with_a_field(custom):
    """A pendulum on a PinJoint whose bob has a velocity_func of half gravity (``custom``
    True), had one and was given pymunk's own back (False), or never had one (None)."""
    space = pymunk.Space()
    space.gravity = (0.0, -9.8)
    bob = pymunk.Body(1.0, 0.01)
    bob.position = (1.0, 0.0)
    space.add(bob, pymunk.Circle(bob, 0.05),
              pymunk.PinJoint(space.static_body, bob, (0, 0), (0, 0)))

    def half(body, gravity, damping, dt):
        pymunk.Body.update_velocity(body, (gravity[0] / 2, gravity[1] / 2), damping, dt)

    if custom is not None:
        bob.velocity_func = half
    if custom is False:
        bob.velocity_func = pymunk.Body.update_velocity
    return space, bob, half


def what_the_tools_say(custom):
    from dumbbell.spaces._layout import body_function

    space, bob, half = pendulum_with_a_field(custom)
    func = body_function(bob, "velocity_func")
    report = spaces.report(space, 1 / 60)
    ledger = spaces.Ledger(space)
    for _ in range(30):
        space.step(1 / 60)
    balance = ledger.balance()
    return (func is half, func is None, report, balance.complete,
            [t.source for t in balance.terms if t.kind == "velocity_func"],
            tuple(bob.velocity),
            sum("velocity_func" in s.reason for s in spaces.energy(space).unknown))


@pytest.mark.parametrize("getter", [False, True], ids=["7.0.x", "7.1.0-7.3.0"])
def test_a_bodys_velocity_func_is_read_as_pymunk_calls_it(getter):
    """report (whose joint probe copies the bodies), energy, the ledger and the velocity
    function read the same with older releases' properties as with the installed ones, a
    function set back to pymunk's own included: 7.0.x has no getter, and up to 7.3.0 the
    setter keeps the replaced function (the getter gives it), so the body's own function
    pointer says it is not called. report stopped with an AttributeError on 7.0.0 and 7.0.1
    before, and energy named a replaced function as the body's up to 7.3.0."""
    public = {custom: what_the_tools_say(custom) for custom in (True, False, None)}
    assert public[True][:2] == (True, False) and public[True][4] and public[True][6] == 1
    assert public[False][:2] == public[None][:2] == (False, True)
    assert public[False][6] == public[None][6] == 0
    with bodies_7_0(getter):
        if not getter:
            with pytest.raises(AttributeError):
                pymunk.Body(1.0, 1.0).velocity_func  # noqa: B018 - 7.0.x: no getter
        older = {custom: what_the_tools_say(custom) for custom in (True, False, None)}
    assert older == public
