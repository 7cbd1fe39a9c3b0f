"""Property-based tests of the command line: every subcommand, with random flags among all it
has, each with a random value (huge, subnormal, negative, NaN, inf, non-ASCII digits,
path-like, empty), gives exit 0, 2 or 3, never exit 1 nor a traceback; a refusal is one line
and leaves nothing behind; no process outlives a run; every run ends in bounded time.

The commands and their flags are read from the ``--help`` text, so a new flag is fuzzed
without editing this file (and a new metavar must be given plausible values below). Runs
happen in this process with the run budgets lowered so that an accepted run is tiny:
``FUZZ_EXAMPLES=N`` runs N examples instead of the default 60 (and random ones)."""

from __future__ import annotations

import contextlib
import importlib
import io
import os
import re
import signal
import socket
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from unittest import mock

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.hostile import cli, files_in, own_children, short_scene

FUZZ = settings(max_examples=int(os.environ.get("FUZZ_EXAMPLES", "60")), deadline=None,
                derandomize="FUZZ_EXAMPLES" not in os.environ, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])

#: Longest one fuzzed command may take (s) before the test calls it a hang: a guard against a
#: command that never ends, not a speed test (an accepted run takes a fraction of a second
#: under the tiny budgets; a 2-core machine at load 12 is ten times slower, not 600 times).
HANG = 600


@dataclass(frozen=True)
class Flag:
    """One option as ``--help`` shows it: its spellings, its metavar (None for a switch) and
    whether it takes several values."""

    names: tuple[str, ...]
    metavar: str | None
    many: bool
    required: bool = False


def _help(*argv: str) -> str:
    status, out, err = cli(*argv, "--help")
    assert status == 0 and not err, (argv, status, err)
    return out


def _section(text: str, title: str) -> list[str]:
    """The lines of the ``title:`` section of a help text."""
    lines = text.splitlines()
    start = lines.index(title) + 1
    end = next((i for i in range(start, len(lines)) if lines[i] and not lines[i][0].isspace()),
               len(lines))
    return lines[start:end]


def help_commands() -> list[str]:
    """The subcommands ``dumbbell --help`` lists (four-space indented under COMMAND)."""
    return [m.group(1) for line in _section(_help(), "positional arguments:")
            if (m := re.match(r" {4}([a-z][a-z-]*)(\s|$)", line))]


def _usage(text: str) -> str:
    """The usage paragraph of a help text, on one line."""
    return " ".join(text.split("\n\n")[0].split())


def help_flags(command: str) -> list[Flag]:
    """Every option ``dumbbell COMMAND --help`` shows, but --help itself; required ones are
    those its usage line shows without brackets."""
    text = _help(command)
    usage = _usage(text)
    flags = []
    for line in _section(text, "options:"):
        if not line.startswith("  -"):
            continue
        forms = re.split(r"\s{2,}", line.strip())[0].split(", ")
        names = tuple(f.split(" ")[0] for f in forms)
        if "--help" in names:
            continue
        words = forms[-1].split(" ")
        required = re.search(rf"(?<![\[\w-]){re.escape(names[0])}(?![\w-])", usage)
        flags.append(Flag(names, words[1] if len(words) > 1 else None, "..." in forms[-1],
                          required is not None))
    return flags


def help_positionals(command: str) -> tuple[list[str], bool]:
    """(the positional metavars of COMMAND, whether they are optional), from its usage."""
    text = _help(command)
    names = [line.split()[0] for line in _section(text, "positional arguments:")
             if line.startswith("  ") and not line.startswith("   ")] \
        if "positional arguments:" in text else []
    usage = _usage(text)
    return names, all(f"[{n}]" in usage for n in names)


COMMANDS = help_commands()
FLAGS = {c: help_flags(c) for c in COMMANDS}
POSITIONALS = {c: help_positionals(c) for c in COMMANDS}


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


#: Plausible values by metavar, so that some fuzzed runs get past parsing; anything else
#: comes from :data:`hostile_text`. A metavar missing here fails the test below.
PLAUSIBLE = {
    "SCENE": ["short.toml", "short.toml", "short.toml", "short2d.toml", "/dev/zero",
              "missing.toml", ".", "-", "", "cases"],
    "DT": ["1e-3", "5e-4", "1e-4", "2e-4", "1e-5"],
    "T": ["0.01", "0.02", "0.05", "1e-3", "0.004"],
    "N": ["1", "2", "3", "25", "5"],
    "S": ["1e-3", "0.01", "0.3", "1e-4"],
    "K": ["200", "2e3", "5e1"],
    "E": ["0", "0.5", "1", "0.9"],
    "NAME": ["euler-cromer", "exact", "verlet", "pymunk", "reference", "euler-cromer-2d",
             "exact,verlet", "nope"],
    "DIR": ["out", "sub/dir", ".", "cases", "short.toml", "/dev/null", "out/../out2",
            "dangling", "out/"],
    "FILE": ["x.csv", "y.csv", "short.toml", "-", "/dev/null", "sub/x.csv", "x.csv/",
             "dangling/x.csv", "newdir/"],
    "FILE.gif": ["a.gif", "b.GIF", "x.csv", "short.toml", "/dev/null"],
    "FILE.html": ["a.html", "b.HTM", "x.csv", "short.toml", "/dev/null", "a.gif"],
    "WxH": ["64x36", "640x360", "9x9", "0x0", "64X36", "1x99999"],
    "ADDRESS": ["tcp://127.0.0.1:{closed}", "tcp://10.255.255.1:8786", "tcp://127.0.0.1:0",
                "tcp://[::1]:{closed}", "http://127.0.0.1:{closed}", "tcp://", "127.0.0.1:1",
                "inproc://nowhere"],
    "NAME=SPEC": ["k=1,2", "dt=1e-4,2e-4", "k=log:1e2:1e3:2", "bodies.A.mass=0.1,0.2",
                  "k=lin:100:200:3", "run.every=1,2", "k=log:1e-300:1e300:3",
                  "k=lin:1:2:" + "9" * 30, "floor.elasticity=0.5,1"],
    "START:STOP:N": ["0:60:3", "0", "10,20", "0:80:9", "89.9", "30:30:1", "60:0:3"],
}

hostile_text = st.one_of(
    st.sampled_from([
        "0", "-0", "1", "-1", "0.01", "2", "25", "1e-4", "5e-324", "4.9e-324", "2.2e-308",
        "1e300", "1.7976931348623157e308", "1e999", "-1e999", "nan", "NaN", "-nan", "inf",
        "-inf", "Infinity", "9" * 25, "9" * 5000, "1_000", "0x10", " 7 ", "\u0661\u0660",
        "\u0661\u0662", "\u00b2", "\u0663.\u0665", "\uff11\uff10", "1e-4\n", "", " ", "-", "--",
        "x.csv", "sub/y.csv", "a.gif", "/dev/null", "/dev/zero", "/dev/full", ".", "..", "~",
        "a\x00b", "\u00e9.csv", "/", "//", "../escape", "nope/deeper/x.csv", "/proc/version",
        "k=1,2", "exact", "nope", "640x360", "local",
        # second round: huge values to echo, names of folders, links to nowhere
        "9" * 5000, ",".join(str(i % 90) for i in range(10_000)), "x" * 5000,
        "d/" * 2100 + "x.csv", "newdir/", "sub/", "out/.", "dangling/x.csv", "dangling",
    ]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(min_value=0, max_value=1e-300, allow_subnormal=True).map(repr),
    st.integers(min_value=-10**30, max_value=10**30).map(str),
    st.text(max_size=8),
)


def _value(metavar: str, plausible_share: int = 2) -> st.SearchStrategy[str]:
    """Values for a flag of ``metavar``: plausible ones ``plausible_share`` times as often as
    hostile ones."""
    plausible = st.sampled_from(PLAUSIBLE[metavar]).map(
        lambda v: v.format(closed=_closed_port()) if "{closed}" in v else v)
    return st.one_of(*[plausible] * plausible_share, hostile_text)


def _scene(command: str) -> st.SearchStrategy[str]:
    """Scene paths, mostly one the command can run."""
    fits = "short2d.toml" if command == "restitution" else "short.toml"
    return st.one_of(st.just(fits), st.just(fits), st.sampled_from(PLAUSIBLE["SCENE"]))


@st.composite
def argv(draw) -> list[str]:
    command = draw(st.sampled_from(COMMANDS))
    args = [command]
    names, optional = POSITIONALS[command]
    for name in names:
        if not optional or draw(st.booleans()):
            args.append(draw(_scene(command) if name == "SCENE" else _value(name)))
    drawn = draw(st.lists(st.sampled_from(FLAGS[command]), max_size=4))
    for flag in [f for f in FLAGS[command] if f.required] + drawn:
        args.append(draw(st.sampled_from(flag.names)))
        if flag.metavar is not None:
            count = draw(st.integers(1, 2)) if flag.many else 1
            share = 8 if flag.required else 2  # a required flag's value should mostly pass
            args.extend(draw(_value(flag.metavar, share)) for _ in range(count))
    if "--scheduler" in args:
        # Whatever --connect-timeout was drawn (still parsed and checked), wait little: an
        # unroutable address waits the whole timeout. 'local' would start a real cluster.
        args = [a if a.strip() != "local" else "tcp://127.0.0.1:1" for a in args]
        args += ["--connect-timeout", "0.3"]
    if command == "render":
        args += ["--max-frames", "5"]  # the last one given wins
    return args


def _patch(monkeypatch, module: str, **values) -> None:
    mod = importlib.import_module(module)
    for name, value in values.items():
        monkeypatch.setattr(mod, name, value)


@pytest.fixture
def tiny_budgets(monkeypatch):
    """Budgets so low that any accepted run is instant, whatever its flags."""
    _patch(monkeypatch, "dumbbell.solvers.base", MAX_STEPS=2_000)
    _patch(monkeypatch, "dumbbell.cli.simulate", MAX_STEPS=2_000)
    _patch(monkeypatch, "dumbbell.analysis.sweep", MAX_STEPS_TOTAL=6_000)
    _patch(monkeypatch, "dumbbell.analysis.bench", MIN_TIMED=0.0, MAX_REPEAT=2,
           DEFAULT_REPEAT=1, DEFAULT_WINDOW=0.02, DEFAULT_DTS=(1e-3, 5e-4))
    for module in ("dumbbell.analysis.stability", "dumbbell.plot.maps"):
        _patch(monkeypatch, module, MAP_WDT=(0.5, 2.1), MAP_RATIOS=(1.0, 10.0), MAP_STEPS=50)
    _patch(monkeypatch, "dumbbell.animation.render", MAX_FRAMES=5)
    _patch(monkeypatch, "dumbbell.cli.render", MAX_FRAMES=5)
    monkeypatch.setattr(os, "cpu_count", lambda: 1)  # pools and sweeps run in this process
    monkeypatch.setenv("CI", "1")


def _folder(root: Path) -> list[str]:
    """Lay out the inputs a fuzzed command may name: short 1D and 2D scenes, a catalogue."""
    short_scene(root, "short.toml")
    (root / "short2d.toml").write_text(SHORT_2D, encoding="utf-8")
    (root / "cases").mkdir()
    short_scene(root / "cases", "short.toml")
    (root / "dangling").symlink_to(root / "nowhere")
    return files_in(root)


#: A 2D dumbbell tilted 30 degrees, 1 cm above the floor: restitution and 2D runs stay short.
SHORT_2D = """\
title = "short 2d"
dimensions = 2
tilt = 30.0
[bodies.A]
mass = 0.1
[bodies.B]
mass = 0.1
height = 0.03
[spring]
stiffness = 200.0
rest_length = 0.2
[floor]
elasticity = 1.0
[gravity]
g = 9.8
[run]
t_end = 0.05
dt = 1e-4
solver = "pymunk"
every = 10
"""


class Hang(BaseException):
    """A fuzzed command ran past :data:`HANG` s."""


def _hang(signum, frame):
    raise Hang


@FUZZ
@given(args=argv())
def test_random_flags_never_give_a_traceback(tiny_budgets, args):
    before = {p.pid for p in own_children()}
    with tempfile.TemporaryDirectory(prefix="dumbbell-fuzz-") as tmp:
        root = Path(tmp)
        (root / "cwd").mkdir()  # ../x stays inside the temporary folder
        inputs = _folder(root / "cwd")
        previous = signal.signal(signal.SIGALRM, _hang)
        signal.alarm(HANG)
        t0 = time.monotonic()
        try:
            # SCENE '-' reads standard input: give it the short scene.
            stdin = io.TextIOWrapper(io.BytesIO((root / "cwd" / "short.toml").read_bytes()))
            with contextlib.chdir(root / "cwd"), mock.patch("sys.stdin", stdin):
                status, _, err = cli(*args)
        except Hang:
            pytest.fail(f"{args} ran past {HANG} s")
        finally:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, previous)
        assert time.monotonic() - t0 < HANG, args
        assert "Traceback" not in err, (args, err)
        assert status in (0, 2, 3), (args, status, err)
        # No value echoed past 200 characters, no temporary file left, whatever the outcome.
        assert all(len(w) <= 200 for line in err.splitlines() for w in line.split(" ")), \
            (args, err[:300])
        assert not [n for n in files_in(root) if ".part" in n or n.endswith(".old")], args
        if status == 2:
            assert len(err.strip().splitlines()) == 1, (args, err)
            assert files_in(root) == ["cwd"] + [f"cwd/{p}" for p in inputs], (args, err)
    assert {p.pid for p in own_children()} <= before, args


def test_the_fuzz_reaches_every_command_and_flag():
    """The help texts are read right: every subcommand, and on each the flags its usage line
    names; every metavar has plausible values."""
    assert set(COMMANDS) == {"run", "simulate", "compare", "render", "play", "bench",
                             "stability", "sweep", "restitution"}
    for command in COMMANDS:
        usage = _usage(_help(command))
        used = set(re.findall(r"(?<![\w-])(--?[a-z][a-z-]*)", usage)) - {"-h"}
        assert used == {f.names[0] for f in FLAGS[command]}, command
        for flag in FLAGS[command]:
            assert flag.metavar is None or flag.metavar in PLAUSIBLE, (command, flag)
    assert POSITIONALS["run"] == (["SCENE"], True)
    assert POSITIONALS["stability"] == ([], True)
    assert POSITIONALS["simulate"] == (["SCENE"], False)
    assert [f.names for f in FLAGS["sweep"] if f.many and f.required] == [("--grid",)]
    assert any("--scheduler" in f.names for f in FLAGS["sweep"])
