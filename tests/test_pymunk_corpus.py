"""The corpus harness itself: pymunk's example programs, loaded from the installed package,
build and step headless, and the constraints demo splits into one box per constraint kind."""

from __future__ import annotations

import pytest

from .pymunk_corpus import CONSTRAINT_KINDS, EXAMPLES, keep_only, run_example

pytest.importorskip("pygame")

#: How each program draws, read from its source: up is against gravity, pygame_util's
#: default is y down, the cradle converts to pygame itself, pyglet draws y up.
Y_UP = {"constraints": False, "newtons_cradle": True, "planet": False, "box2d_pyramid": True,
        "box2d_vertical_stack": True, "slide_and_pinjoint": False,
        "damped_rotary_spring_pointer": False, "spiderweb": True, "tank": False,
        "flipper": False, "contact_with_friction": True, "bouncing_balls": False,
        "breakout": True, "basic_test": True}


@pytest.mark.parametrize("name", EXAMPLES)
def test_every_example_builds_and_steps_headless(name):
    seen = []
    run = run_example(name, 12, on_start=lambda s: seen.append(len(s.bodies)),
                      on_step=lambda s, dt: seen.append(dt))
    assert len(run.dts) == 12 and seen[1:] == run.dts and all(dt > 0 for dt in run.dts)
    assert run.y_up is Y_UP[name]
    assert run.space.bodies or name == "bouncing_balls"  # its balls arrive over time


def test_the_same_program_gives_the_same_space_every_time():
    a, b = (run_example("bouncing_balls", 200).space for _ in range(2))
    assert [tuple(x.position) for x in a.bodies] == [tuple(x.position) for x in b.bodies]


@pytest.mark.parametrize("kind", CONSTRAINT_KINDS)
def test_constraints_demo_isolates_one_kind(kind):
    space = run_example("constraints", 3, isolate=keep_only(kind)).space
    kinds = sorted(type(c).__name__ for c in space.constraints)
    assert len(space.bodies) == 2 and kind in kinds
    assert set(kinds) <= {kind, "PivotJoint"}


def test_a_ball_dropped_in_the_basic_program_falls_freely():
    # basic_test adds a ball at rest at y = 400 after ten ticks; g = 900 px/s^2, y up, and
    # nothing below it for a while. pymunk moves positions first, then velocities, so the
    # first step leaves the ball where it is: after n steps y = 400 - g dt^2 n(n-1)/2.
    ys = []
    run = run_example("basic_test", 30,
                      on_step=lambda s, dt: s.bodies and ys.append(next(iter(s.bodies)).position.y))
    dt, g = run.dts[0], -run.space.gravity.y
    assert len(ys) >= 15
    for n, y in enumerate(ys, start=1):
        assert y == pytest.approx(400 - g * dt * dt * n * (n - 1) / 2, abs=1e-9)
