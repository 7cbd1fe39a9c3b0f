"""Property-based tests of the command line: random flags of each command with random values
(huge, subnormal, negative, NaN, non-ASCII digits, path-like strings) give exit 0, 2 or 3 with
no traceback, never exit 1; a refusal is one line. Runs in this process, with the run budgets
lowered so that an accepted run is tiny."""

from __future__ import annotations

import argparse
import importlib
import os

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from dumbbell.cli import build_parser
from tests.hostile import cli, short_scene

FUZZ = settings(max_examples=int(os.environ.get("FUZZ_EXAMPLES", "40")), deadline=None,
                derandomize="FUZZ_EXAMPLES" not in os.environ, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])

#: Commands fuzzed; bench and stability run fixed, long batteries by design.
COMMANDS = ("simulate", "render", "sweep", "compare", "run")
#: Flags left out: the Dask scheduler would be contacted for real.
SKIP = {"--scheduler", "--connect-timeout", "-h", "--help", "--all"}


def _flags(command: str) -> list[argparse.Action]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return [a for a in sub.choices[command]._actions
            if a.option_strings and not set(a.option_strings) & SKIP]


FLAGS = {c: _flags(c) for c in COMMANDS}

hostile_text = st.one_of(
    st.sampled_from([
        "0", "-0", "1", "-1", "0.01", "0.02", "2", "3", "25", "1e-4", "5e-324", "4.9e-324",
        "2.2e-308", "1e300", "1.7976931348623157e308", "1e999", "-1e999", "nan", "NaN", "inf",
        "-inf", "9" * 25, "9" * 5000, "1_000", "0x10", " 7 ", "١٢", "²", "٣.٥", "1e-4\n",
        "", "-", "--", "x.csv", "sub/y.csv", "a.gif", "/dev/null", "/dev/zero", ".", "~",
        "a\x00b", "é.csv", "k=1,2", "dt=log:1e-5:1e-3:3", "k=lin:1:2:" + "9" * 30,
        "exact", "pymunk", "euler-cromer", "verlet", "reference", "nope", "640x360", "9x9",
        "k=log:1e-300:1e300:3", "bodies.A.mass=0.1,0.2", "run.every=1,2",
    ]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(min_value=-10**30, max_value=10**30).map(str),
    st.text(max_size=8),
)


@st.composite
def argv(draw) -> list[str]:
    command = draw(st.sampled_from(COMMANDS))
    scene = draw(st.sampled_from(["short.toml", "short.toml", "short.toml", "/dev/zero",
                                  "missing.toml", ".", "-"]))
    args = [command, scene]
    for action in draw(st.lists(st.sampled_from(FLAGS[command]), max_size=4)):
        args.append(draw(st.sampled_from(action.option_strings)))
        if action.nargs == 0:
            continue
        count = draw(st.integers(1, 2)) if action.nargs in ("+", "*") else 1
        args.extend(draw(hostile_text) for _ in range(count))
    return args


@pytest.fixture
def tiny_budgets(monkeypatch, tmp_path):
    """Run in an empty folder with budgets so low that any accepted run is instant."""
    monkeypatch.chdir(tmp_path)
    short_scene(tmp_path, "short.toml")
    monkeypatch.setattr(importlib.import_module("dumbbell.solvers.base"), "MAX_STEPS", 2_000)
    monkeypatch.setattr(importlib.import_module("dumbbell.analysis.sweep"), "MAX_STEPS_TOTAL",
                        6_000)
    monkeypatch.setattr(os, "cpu_count", lambda: 1)  # sweeps run in this process
    monkeypatch.setenv("CI", "1")


@FUZZ
@given(args=argv())
def test_random_flags_never_give_a_traceback(tiny_budgets, args):
    if args[0] == "render":
        args += ["--max-frames", "5"]  # the last one given wins
    status, _, err = cli(*args)
    assert "Traceback" not in err, (args, err)
    assert status in (0, 2, 3), (args, status, err)
    if status == 2:
        assert len(err.strip().splitlines()) == 1, (args, err)
