"""The command line as a user meets it: outputs, column contracts, bad flags."""

from __future__ import annotations

import csv
import math

import pytest

from dumbbell.cli import main
from tests.conftest import SCENES

TEXTBOOK = str(SCENES / "textbook-1d.toml")


def test_simulate_writes_the_contract_columns(tmp_path):
    out, events = tmp_path / "t.csv", tmp_path / "e.csv"
    assert main(["simulate", TEXTBOOK, "--t-end", "1", "--every", "1000", "-o", str(out),
                 "--events", str(events), "-q"]) == 0
    rows = list(csv.reader(out.open()))
    assert rows[0] == ["t", "xA", "vA", "xB", "vB", "K_cm", "K_int", "U_g", "U_spring", "E"]
    assert len(rows) == 1 + 101
    assert float(rows[1][9]) == pytest.approx(2.156)
    ev = list(csv.reader(events.open()))
    assert ev[0] == ["t", "body", "v_before", "v_after"]
    assert ev[1][1] == "B" and float(ev[1][0]) == pytest.approx(math.sqrt(2 / 9.8), abs=2e-5)
    assert not list(tmp_path.glob(".*part*"))


def test_simulate_exact_solver_flag(tmp_path):
    out = tmp_path / "x.csv"
    assert main(["simulate", TEXTBOOK, "--solver", "exact", "--t-end", "0.5", "--dt", "1e-3",
                 "--every", "1", "-o", str(out)]) == 0
    rows = list(csv.reader(out.open()))
    assert len(rows) == 1 + 501


def test_run_makes_the_textbook_outputs(tmp_path):
    assert main(["run", "--out", str(tmp_path), "-q"]) == 0
    names = {p.name for p in tmp_path.iterdir()}
    assert {"textbook-1d-positions.png", "textbook-1d-kinetic.png",
            "textbook-1d-potential.png", "textbook-1d.csv", "textbook-1d-impacts.csv"} <= names
    for p in tmp_path.glob("*.png"):
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def exit_code(argv: list[str]) -> int:
    """main's status, whether it returns it or argparse exits with it."""
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code)


@pytest.mark.parametrize("flags,word", [
    (["--dt", "0"], "--dt"),
    (["--dt", "-1e-5"], "--dt"),
    (["--dt", "abc"], "--dt"),
    (["--t-end", "nan"], "--t-end"),
    (["--every", "0"], "--every"),
    (["--every", "1.5"], "--every"),
    (["--solver", "no-such-solver"], "no-such-solver"),
    (["--dt", "20"], "dt"),
    (["--bogus"], "--bogus"),
])
def test_bad_flags_exit_2_with_one_line(tmp_path, capsys, flags, word):
    out = tmp_path / "o.csv"
    assert exit_code(["simulate", TEXTBOOK, "-o", str(out), *flags]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and word in err and "Traceback" not in err
    assert not out.exists()


def test_a_closed_pipe_ends_quietly():
    # `dumbbell simulate SCENE | head -1`: the reader leaves early; that is not an error.
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-m", "dumbbell.cli", "simulate", TEXTBOOK,
                             "--t-end", "2", "--every", "1"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    assert proc.stdout.readline().startswith(b"t,xA,vA,xB,vB")
    proc.stdout.close()
    err = proc.stderr.read()
    assert proc.wait(timeout=600) == 0  # a guard against a hang, not a clock
    assert err == b""


def test_clip_bounds_each_echoed_word_and_the_whole_message():
    # A message echoing a huge value stays short: each word (run without spaces) keeps its
    # first and last characters; the whole keeps its start and its end (what is allowed),
    # for an echo of many words too (a key with spaces, 'a b a b ...' as a path).
    from dumbbell.cli.app import MAX_ECHO, clip, one_line

    assert clip("fps = 0: must be from 1 to 50") == "fps = 0: must be from 1 to 50"
    word = clip("path " + "a" * 100_000 + ": must end in .gif")
    assert len(word) == len("path ") + MAX_ECHO + len(" must end in .gif")
    assert word.endswith("a" * 19 + ": must end in .gif")
    for echo in ("a b " * 25_000, "key " * 30_000 + "x" * 100_000):
        whole = clip(f"scene.toml: {echo}: unknown key; allowed: spring, bodies")
        assert len(whole) == 5 * MAX_ECHO
        assert whole.startswith("scene.toml: ") and whole.endswith("allowed: spring, bodies")
    long_but_fine = "word " * (MAX_ECHO - 1)  # 995 characters: left whole
    assert clip(long_but_fine) == long_but_fine
    assert len(one_line("line\n" * 100_000)) <= 5 * MAX_ECHO


@pytest.mark.parametrize("argv", [
    ["compare", TEXTBOOK, "--solvers", "pymunk", "pymunk"],
    ["compare", TEXTBOOK, "--solvers", "pymunk,euler-cromer,pymunk"],
    ["bench", TEXTBOOK, "--solvers", "euler-cromer", "euler-cromer"],
    ["stability", "--solvers", "euler-cromer", "pymunk", "euler-cromer"],
    ["play", TEXTBOOK, "--solvers", "pymunk", "pymunk", "-o", "PAGE"],
])
def test_a_solver_named_twice_is_refused_by_every_command(tmp_path, capsys, argv):
    """Each command's --solvers refuses a name given twice (compare once ran it once without
    a word, while play refused it), before any work: one line, exit 2, nothing written."""
    out = tmp_path / "out"
    argv = [str(out / "p.html") if a == "PAGE" else a for a in argv]
    extra = [] if argv[0] == "play" else ["--out", str(out)]
    assert exit_code([*argv, *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "named twice" in err and "Traceback" not in err
    assert not out.exists()
