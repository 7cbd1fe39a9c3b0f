"""Every failure message says what to change, with a value that works (issue 29, item 8).

A verdict other than ``ok`` ends with ``try dt = X s (why)`` where the step is the cause, or
``run.t_end = T s`` where no step gets past the failure (a particle come to rest on an
inelastic floor). Each case here runs the failing run, reads the value from its message, runs
it again with that value, and checks that the run then ends ``ok``: the shipped failures
(``dumbbell simulate scenes/textbook-1d.toml --dt 0.01`` and ``--dt 0.1``, the catalogue's
stiff, tunnelling, resting and draining cases) and variants of them (other steps, solvers and
scenes)."""

from __future__ import annotations

import math
import re

import pytest

import dumbbell
from dumbbell.cli import main
from dumbbell.solvers import simulate
from dumbbell.solvers.advice import Bound, one_digit, seconds_below, suggest
from tests.conftest import SCENES

EXTREME = SCENES / "extreme"


def _hint(reason: str) -> tuple[float | None, float | None]:
    """The step (s) and the end time (s) a message suggests, None where it does not."""
    step = re.search(r"try dt = ([0-9.e-]+) s", reason)
    end = re.search(r"run\.t_end = ([0-9.e-]+) s", reason)
    return (float(step.group(1)) if step else None), (float(end.group(1)) if end else None)


def _scene(name: str, **values: float):
    path = EXTREME / f"{name}.toml" if (EXTREME / f"{name}.toml").exists() else (
        SCENES / f"{name}.toml")
    scene = dumbbell.load_scene(path)
    return scene.with_values({f"run.{k}": v for k, v in values.items()}) if values else scene


def _followed(scene, solver: str, dt: float | None = None) -> tuple[str, str]:
    """The failing run's status, and the status of the run that follows its advice."""
    verdict = simulate(scene, solver, dt=dt).verdict
    assert not verdict.ok, f"{solver} at dt = {dt}: expected a failure"
    step, end = _hint(verdict.reason)
    assert step is not None or end is not None, verdict.reason
    if step is not None:
        assert step < (dt or scene.run.dt)
        again = simulate(scene, solver, dt=step).verdict
    else:
        again = simulate(scene, solver, dt=dt, t_end=end).verdict
    return verdict.status, str(again)


#: (scene, its run.t_end if shortened (s), solver, dt (s; None: the scene's), the status).
CASES = [
    # The textbook scene: the two shipped failures, and other steps and solvers.
    ("textbook-1d", None, "euler-cromer", 0.1, "unstable"),
    ("textbook-1d", None, "euler-cromer", 0.02, "unstable"),
    ("textbook-1d", None, "euler-cromer", 0.01, "failed"),
    ("textbook-1d", None, "euler-cromer", 0.005, "failed"),
    ("textbook-1d", None, "euler-cromer", 1e-3, "inaccurate"),
    ("textbook-1d", None, "verlet", 0.1, "unstable"),
    ("textbook-1d", None, "verlet", 0.03, "inaccurate"),
    ("textbook-1d", 3.0, "pymunk", 0.03, "tunnelled"),
    ("textbook-1d", None, "pymunk", 0.01, "inaccurate"),
    # 2D.
    ("tilted-2d", None, "euler-cromer-2d", 0.03, "inaccurate"),
    ("tilted-2d", 3.0, "verlet", 0.03, "unstable"),
    ("tilted-2d", None, "pymunk", 0.01, "inaccurate"),
    # The catalogue: the step limit, just inside and just outside it, and tunnelling.
    ("stiff-wdt-1.9", None, "euler-cromer", None, "inaccurate"),
    ("stiff-wdt-1.9", None, "verlet", None, "inaccurate"),
    ("stiff-wdt-1.9", None, "pymunk", None, "inaccurate"),
    ("stiff-wdt-2.1", None, "euler-cromer", None, "unstable"),
    ("stiff-wdt-2.1", None, "verlet", None, "unstable"),
    ("stiff-wdt-2.1", 0.2, "pymunk", None, "unstable"),
    ("high-drop", None, "pymunk", None, "tunnelled"),
    # No step gets past a particle at rest on an inelastic floor: end before it.
    ("inelastic-floor", None, "euler-cromer", None, "failed"),
    ("inelastic-floor", None, "verlet", None, "failed"),
    ("inelastic-floor", None, "exact", None, "failed"),
]


@pytest.mark.parametrize("name,t_end,solver,dt,status", CASES,
                         ids=[f"{c[0]}-{c[2]}-{c[3]}" for c in CASES])
def test_the_value_a_failure_suggests_ends_ok(name, t_end, solver, dt, status):
    scene = _scene(name, t_end=t_end) if t_end else _scene(name)
    failed, followed = _followed(scene, solver, dt)
    assert failed == status
    assert followed == "ok", followed


@pytest.mark.slow
def test_the_long_horizon_s_drain_is_cured_by_the_step_it_suggests():
    """1000 s at dt = 1e-4 s drains Euler-Cromer's elastic dumbbell until B rests on the
    floor (959 s); the message scales the measured drain to the step that keeps it within
    a quarter of 0.1 (2e-6 s, 5e8 steps: about 10 s of Euler-Cromer)."""
    failed, followed = _followed(_scene("long-horizon"), "euler-cromer")
    assert failed == "failed" and followed == "ok", followed


def test_the_shipped_failures_print_their_value(capsys):
    """The two failures of the brief's commands end with a value (exit 3 both)."""
    for dt, value in (("0.01", "1e-4"), ("0.1", "1e-5")):
        assert main(["simulate", str(SCENES / "textbook-1d.toml"), "--dt", dt, "-o",
                     "/dev/null"]) == 3
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"; try dt = {value} s (" in err, err


def test_a_resting_run_names_the_time_and_the_solvers_that_hold_contact():
    v = simulate(_scene("inelastic-floor"), "exact").verdict
    assert v.status == "failed" and "came to rest on the floor" in v.reason
    assert v.reason.endswith("end the run before it (run.t_end = 3.6 s) or use a solver that "
                             "holds resting contact (pymunk)")


def test_the_rounding_of_a_suggestion():
    assert one_digit(4.88e-5) == 4e-5 and one_digit(1e-4) == 1e-4
    assert one_digit(9.99e-3) == 9e-3 and one_digit(2.0) == 2.0
    assert seconds_below(3.65795) == "3.6" and seconds_below(959.343) == "950"
    # The tightest bound wins, written with one digit, and only a step below the run's.
    assert suggest(1e-2, [Bound(3e-4, "a"), Bound(7.7e-4, "b")]) == (3e-4, "a")
    assert suggest(1e-4, [Bound(3e-4, "a")]) is None
    assert suggest(1e-2, [None]) is None


def test_the_spring_bound_is_the_swing_theory():
    """Without floor or gravity only the spring counts: w*dt where Euler-Cromer's stable
    swing h/(2-h) is a quarter of run.inaccurate_energy, 2 q/(1 + q) with q = 0.025."""
    from dumbbell.solvers.advice import spring_bound

    scene = _scene("stiff-wdt-1.9")
    bound = spring_bound(dumbbell.solvers.METHODS["euler-cromer"], scene)
    q = 0.25 * scene.run.inaccurate_energy
    assert bound.dt * scene.system.omega == pytest.approx(2 * q / (1 + q), rel=1e-9)
    assert math.isclose(bound.dt, 4.878e-5, rel_tol=1e-3)
