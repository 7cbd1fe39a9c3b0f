"""Nothing a program does with a ledger (or a heat counter) ends the process: each case runs
in a subprocess of its own, so that an abort or a crash fails that case alone and cannot
end the pytest run. Each script prints what it measured; the test checks the exit status
and those lines."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

_PRELUDE = """
import copy, gc, pickle, sys, warnings
import pymunk
from dumbbell import spaces


def scene():
    # A ball dropped on a floor from 0.5 m: it bounces (contacts every few steps).
    space = pymunk.Space()
    space.gravity = (0.0, -10.0)
    floor = pymunk.Segment(space.static_body, (-5, 0), (5, 0), 0.1)
    floor.elasticity = 0.8
    body = pymunk.Body(1.0, 0.01)
    body.position = (0.0, 0.5)
    shape = pymunk.Circle(body, 0.2)
    shape.elasticity = 0.8
    space.add(floor, body, shape)
    return space, body
"""


def _run(script: str, timeout: float = 120.0) -> list[str]:
    """Run ``script`` (after the prelude) in a fresh interpreter; its stdout lines. Fails
    the test, with what it printed, unless it exits with status 0."""
    code = _PRELUDE + textwrap.dedent(script)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=timeout, check=False)
    assert done.returncode == 0, (f"exit status {done.returncode}\n{done.stdout}\n"
                                  f"{done.stderr[-3000:]}")
    assert "Exception ignored" not in done.stderr, done.stderr[-3000:]
    return done.stdout.split("\n")


def test_a_ledger_kept_on_its_space_is_collected_and_survives_exit():
    out = _run("""
        for _ in range(30):
            space, body = scene()
            space.ledger = spaces.Ledger(space)  # space -> ledger -> space
            space.heat = spaces.HeatCounter(space)
            for _ in range(20):
                space.step(0.01)
            del space, body
            gc.collect()
        space, body = scene()
        space.ledger = spaces.Ledger(space)
        space.heat = spaces.HeatCounter(space)
        space.step(0.01)
        print("counted", space.ledger.balance().steps)
        # The cycle is still there at interpreter exit.
    """)
    assert "counted 1" in out


def test_a_ledger_captured_by_a_collision_callback():
    out = _run("""
        seen = []

        def attach(space):
            ledger = spaces.Ledger(space)  # only the callback keeps it

            def note(arbiter, space_, data):
                seen.append(ledger.balance().steps)  # balance() inside the step

            space.on_collision(None, None, post_solve=note)  # space -> handler -> ledger

        space, body = scene()
        attach(space)
        for _ in range(60):
            space.step(0.01)
        print("calls", len(seen) > 0)
        del space, body
        gc.collect()
        print("collected")
        space, body = scene()
        attach(space)  # and one left for the interpreter's exit
        space.step(0.01)
    """)
    assert "calls True" in out and "collected" in out


@pytest.mark.parametrize("how", ["detach", "drop"])
def test_detached_or_dropped_inside_a_collision_callback(how):
    out = _run(f"""
        space, body = scene()
        holder = [spaces.Ledger(space)]
        before = [c for c in space.constraints]
        fired = []

        def off(arbiter, space_, data):
            if holder:
                fired.append(holder[0].balance().steps)
                {"holder[0].detach()" if how == "detach" else "pass"}
                holder.clear()  # the last reference goes inside the step

        space.on_collision(None, None, post_solve=off)
        for _ in range(100):
            space.step(0.01)
        from dumbbell.spaces import _hook
        print("fired", len(fired), "hooks left", len(_hook.addresses(space)),
              "constraints", list(space.constraints) == before)
    """)
    assert "fired 1 hooks left 0 constraints True" in out


def test_a_copy_of_a_ledger_dropped_leaves_the_original_counting():
    out = _run("""
        space, body = scene()
        ledger = spaces.Ledger(space)
        for _ in range(50):
            space.step(0.01)
        for other in (copy.copy(ledger), copy.deepcopy(ledger),
                      pickle.loads(pickle.dumps(ledger))):
            assert not other.attached and other.balance().steps == 50
            other.detach()  # does nothing to the original
        del other
        gc.collect()
        for _ in range(50):
            space.step(0.01)
        bal = ledger.balance()
        print("steps", bal.steps, "complete", bal.complete, "program",
              [t.source for t in bal.terms if t.kind == "program"])
        ledger.detach()
        space.step(0.01)
        print("detached", ledger.attached)
    """)
    assert "steps 100 complete True program []" in out and "detached False" in out


def test_attaching_makes_no_static_body_and_pymunk_batch_reads_the_same_rows():
    out = _run("""
        import pymunk.batch
        import numpy as np

        space = pymunk.Space()
        space.gravity = (0.0, -10.0)
        for i in range(3):
            b = pymunk.Body(1.0, 1.0)
            b.position = (i, 2.0 * i)
            space.add(b, pymunk.Circle(b, 0.1))
        ledger = spaces.Ledger(space)
        heat = spaces.HeatCounter(space)
        space.step(0.01)
        print("static body made", space._static_body is not None)
        fields = pymunk.batch.BodyFields.BODY_ID | pymunk.batch.BodyFields.POSITION
        data = pymunk.batch.Buffer()
        pymunk.batch.get_space_bodies(space, fields, data)
        print("rows", len(memoryview(data.int_buf()).cast("P")))
        positions = np.array([7.0, 8.0, 9.0, 10.0, 11.0, 12.0])
        data.set_float_buf(positions)
        pymunk.batch.set_space_bodies(space, pymunk.batch.BodyFields.POSITION, data)
        print("set", [tuple(b.position) for b in space.bodies])
        space.step(0.01)
        print("program", sorted(t.source for t in ledger.balance().terms
                                if t.kind == "program"))
    """)
    assert "static body made False" in out and "rows 3" in out
    assert "set [(7.0, 8.0), (9.0, 10.0), (11.0, 12.0)]" in out
    assert "program ['program: body 0', 'program: body 1', 'program: body 2']" in out


def test_numba_is_not_loaded_and_gc_stays_cheap():
    out = _run("""
        import time
        space, body = scene()
        ledger = spaces.Ledger(space)
        for _ in range(200):
            space.step(0.01)
        print("numba", "numba" in sys.modules, "complete", ledger.balance().complete)
    """)
    assert "numba False complete True" in out


def test_a_ledger_on_its_space_copies_and_pickles_with_it():
    out = _run("""
        space, body = scene()
        space.ledger = spaces.Ledger(space)
        for _ in range(30):
            space.step(0.01)
        for other in (space.copy(), pickle.loads(pickle.dumps(space))):
            # The copy's ledger holds the account so far and does not count (copied, it
            # names the copied space; pickled, none).
            assert other.ledger.space in (other, None) and not other.ledger.attached
            assert other.ledger.balance().steps == 30 and len(other.constraints) == 0
            for _ in range(10):
                other.step(0.01)
        for _ in range(10):
            space.step(0.01)
        print("original", space.ledger.balance().steps, space.ledger.attached)
    """)
    assert "original 40 True" in out


@pytest.mark.parametrize("ghost", ["pymunk.Body(0.0, 0.0)", "pymunk.Body(1.0, 0.0)"])
def test_a_dynamic_body_of_mass_or_moment_0_is_named_never_complete(ghost):
    # pymunk's own checks of mass and moment are asserts: under -O such a body steps
    # (velocity or spin NaN); spaces.energy refuses the space, the ledger names the body.
    code = _PRELUDE + textwrap.dedent(f"""
        space, body = scene()
        ledger = spaces.Ledger(space)
        space.step(0.01)
        ghost = {ghost}
        ghost.position = (1.0, 1.0)
        ghost.angular_velocity = 1.0
        space.add(ghost)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no numpy warnings either
            for _ in range(3):
                space.step(0.01)
            try:
                bal = ledger.balance()
                print("complete", bal.complete, dict(bal.unaccounted).get("body 1", ""))
            except Exception as e:
                print("refused", type(e).__name__, e)
        try:
            spaces.energy(space)
        except Exception as e:
            print("energy refuses", type(e).__name__)
    """)
    done = subprocess.run([sys.executable, "-O", "-c", code], capture_output=True, text=True,
                          timeout=120, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "energy refuses DumbbellError" in done.stdout
    assert ("complete False a dynamic body of mass" in done.stdout
            or "refused DumbbellError body 1: " in done.stdout and
            "(a dynamic body of mass" in done.stdout), done.stdout


def test_pymunks_own_suite_passes_with_a_ledger_and_a_heat_counter_on_every_space():
    # benchmarks/pymunk_suite.py runs pymunk's tests twice, each in a subprocess of its
    # own: bare, and with a Ledger and a HeatCounter kept on every Space pymunk makes. The
    # modules imported before the first test are frozen out of the garbage collector's way
    # (its testGC's 720 gc.collect() calls would walk numpy's and dumbbell's objects each
    # time: two thirds of the run); what the suite makes is collected as ever.
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
    try:
        import pymunk_suite
    finally:
        sys.path.pop(0)
    bare = pymunk_suite.suite_run("bare", freeze=True)
    led = pymunk_suite.suite_run("ledgers", freeze=True)
    assert "exit" not in bare and "exit" not in led, (bare, led)
    assert led["run"] == bare["run"] > 250
    newly = set(led["failed"] + led["errors"]) - set(bare["failed"] + bare["errors"])
    assert newly == set()
    assert led["spaces"] > 500 and led["stopped"] == []
