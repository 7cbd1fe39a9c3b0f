"""One source for the showcase: every file tracked in renders/ is written by one piece of
``dumbbell run --all`` (dumbbell.cli.showcase), and each piece, run afresh, writes the
tracked bytes again. The files that hold run times (the benchmark's table and its
work-precision figure) are rewritten, and everything in them but the times is checked.

The pieces run here one by one, in this process (``run --all`` runs the same pieces, in one
go), except those a code block of the docs runs as written: tests/test_docs_run.py checks
what those leave in renders/ against the tracked bytes. The slowest are marked ``slow``
(``pytest -m "not slow"`` leaves them out; CI runs them)."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest

from dumbbell.cli import main
from dumbbell.cli.showcase import PIECES, Piece, measured, parse, tracked
from tests.conftest import ROOT, drops_made_once, load_tool

RENDERS = ROOT / "renders"
#: What the commands also write beside the tracked files; .gitignore keeps them out of git.
UNTRACKED = (".csv", ".json", "stability.md")
#: Pieces that take more than about 10 s on a 2-core machine.
SLOW = {"bench"}


def _docs_commands() -> set[str]:
    return load_tool("docblocks").commands(ROOT)


def spellings(piece: Piece) -> set[str]:
    """The command lines that make ``piece`` into renders/ (``dumbbell run`` with no scene is
    the textbook's)."""
    out = {piece.command}
    if piece.argv == ("run", "textbook-1d"):
        out.add("dumbbell run")
    return out


#: Pieces a runnable block of the docs makes into renders/, and the rest.
IN_DOCS = [p for p in PIECES if spellings(p) & _docs_commands()]
HERE = [p for p in PIECES if p not in IN_DOCS]


def test_every_piece_is_checked_by_the_docs_or_here():
    assert set(IN_DOCS) | set(HERE) == set(PIECES) and not set(IN_DOCS) & set(HERE)
    # The README's first command is checked by the docs' run.
    assert PIECES[0] in IN_DOCS


def tracked_renders() -> set[str]:
    """The files git tracks in renders/ (the folder's files when this is not a git clone)."""
    git = shutil.which("git")
    if git and (ROOT / ".git").exists():
        done = subprocess.run([git, "ls-files", "renders"], cwd=ROOT, capture_output=True,
                              text=True, check=False)
        if done.returncode == 0 and done.stdout.strip():
            return {line.split("/", 1)[1] for line in done.stdout.split()}
    return {p.name for p in RENDERS.iterdir() if p.is_file()}


def test_the_showcase_is_every_tracked_render():
    assert tracked() == tracked_renders()
    assert measured() <= tracked()
    assert sum((RENDERS / name).stat().st_size for name in tracked()) <= 10 * 2**20
    # Each file comes from one piece only.
    names = [name for piece in PIECES for name in piece.writes]
    assert len(names) == len(set(names))
    # --all runs every piece; its help names them.
    assert main(["run", "--all", "--max-frames", "1"]) == 2
    from dumbbell.cli.app import build_parser, subcommands

    help_text = " ".join(subcommands(build_parser())["run"].format_help().split())
    for piece in PIECES:
        if piece.argv[0] != "run":
            assert " ".join(piece.command.split()) in help_text


def test_what_the_commands_write_beside_the_showcase_is_ignored_by_git():
    gitignore = (ROOT / ".gitignore").read_text()
    assert "renders/*" in gitignore.splitlines()
    kept = [re.escape(line[len("!renders/"):]).replace(r"\*", ".*")
            for line in gitignore.splitlines() if line.startswith("!renders/")]
    assert kept and all(any(re.fullmatch(k, name) for k in kept) for name in tracked())
    for name in ("textbook-1d.csv", "bench-textbook-1d.json", "stability.md",
                 "stability.csv", "textbook-1d-compare.csv"):
        assert name.endswith(UNTRACKED) and not any(re.fullmatch(k, name) for k in kept)


#: Rows whose errors are rounding: the truths against the exact solution. scipy's DOP853 (the
#: reference) adds its stages with BLAS, whose kernels OpenBLAS picks by CPU, so these errors
#: differ in their leading digits from one machine to another (1.68e-11 and 2.95e-11 m here);
#: they are compared to within a factor of 10, the other rows digit for digit.
ROUNDING_ROWS = ("| reference |", "| exact |")


def _untimed(markdown: str) -> str:
    """The benchmark's table without what depends on the clock (the run-time column, the
    count of timed runs, the interpolated times and the compile times) or on the CPU (the
    error cells of :data:`ROUNDING_ROWS`, checked by :func:`_rounding_errors`)."""
    lines = []
    for line in markdown.splitlines():
        if line.startswith(("Run time to reach", "JIT compile")):
            continue
        line = re.sub(r"at least \d+ runs?\b", "at least N runs", line)
        line = re.sub(r"until [\d.]+ s are timed", "until T s are timed", line)
        cells = line.split(" | ")
        if line.startswith("| ") and len(cells) == 8:
            cells[3] = "-"
            if line.startswith(ROUNDING_ROWS):
                cells[4:7] = [re.sub(r"\d\.\d+e[-+]\d+", "E", c) for c in cells[4:7]]
        lines.append(" | ".join(cells))
    return "\n".join(lines)


def _rounding_errors(markdown: str) -> list[float]:
    """The error cells of :data:`ROUNDING_ROWS`, as numbers."""
    return [float(x) for line in markdown.splitlines() if line.startswith(ROUNDING_ROWS)
            for x in re.findall(r"\d\.\d+e[-+]\d+", " | ".join(line.split(" | ")[4:7]))]


class _Once:
    """A solver class whose ``_solve`` (what the benchmark's ``_measure`` calls, for its
    warm-up run and each timed run) runs once and then returns that run again."""

    def __init__(self, cls):
        self.cls, self.last = cls, None

    def _solve(self, scene, options, **keywords):
        if self.last is None:
            self.last = self.cls._solve(scene, options, **keywords)
        return self.last

    def __getattr__(self, name):
        return getattr(self.cls, name)


def _run(piece: Piece, out, monkeypatch) -> int:
    args = parse(piece, out, quiet=True)
    if piece.argv[0] == "bench":
        # No timed runs: each point's warm-up run stands in for them. The errors, the
        # convergence figure and the table's other columns do not depend on the clock.
        from dumbbell.analysis import bench

        args.repeat = 1
        monkeypatch.setattr(bench, "MIN_TIMED", 0.0)
        measure = bench._measure
        monkeypatch.setattr(bench, "_measure", lambda cls, *a, **k: measure(_Once(cls), *a, **k))
    if piece.argv[0] == "stability":
        # Its tracked file is the map; the catalogue's table (stability.md, ignored by git)
        # takes three times as long and is checked by the goldens.
        from dumbbell.cli.stability import write_map

        write_map(None, out)
        return 0
    if piece.argv[0] == "restitution":
        # Its drops at the tilts the rotation page's tables also make (0, 30, 60 and 80
        # degrees, e = 0.5; the same scenes and options) are the runs those made, when they
        # ran before in this process (conftest's SHARED_SCOPE puts them in one).
        with drops_made_once():
            return int(args.func(args) or 0)
    return int(args.func(args) or 0)


@pytest.mark.parametrize("piece", [
    pytest.param(p, id=" ".join(p.argv[:2]),
                 marks=[pytest.mark.slow] if p.argv[0] in SLOW else [])
    for p in HERE])
def test_each_piece_writes_the_tracked_bytes_again(tmp_path, piece, monkeypatch):
    assert _run(piece, tmp_path, monkeypatch) == 0
    written = {p.name for p in tmp_path.iterdir()}
    assert set(piece.writes) <= written
    # Nothing else that git would see: the rest is CSV or JSON, which renders/ ignores.
    assert all(name.endswith(UNTRACKED) for name in written - set(piece.writes))
    for name in piece.writes:
        new, old = (tmp_path / name).read_bytes(), (RENDERS / name).read_bytes()
        if name in piece.measured:
            if name.endswith(".md"):
                assert _untimed(new.decode()) == _untimed(old.decode())
                pairs = list(zip(_rounding_errors(new.decode()),
                                 _rounding_errors(old.decode()), strict=True))
                assert pairs and all(0.1 < a / b < 10 for a, b in pairs), pairs
            else:
                assert new[:8] == b"\x89PNG\r\n\x1a\n"
        else:
            assert new == old, f"{name}: {piece.command} no longer writes the tracked bytes"


def test_the_untimed_bench_table_still_sees_a_changed_error():
    table = (RENDERS / "bench-textbook-1d.md").read_text()
    changed = table.replace("| 1.95e-03 |", "| 1.96e-03 |", 1)
    assert changed != table and _untimed(changed) != _untimed(table)
    retimed = re.sub(r"\| [\d.]+ (µs|ms|s) \([\d.]+ (µs|ms|s)\) \|", "| 1 s (2 s) |", table)
    assert retimed != table and _untimed(retimed) == _untimed(table)
    # The reference row's error, whatever this machine's BLAS made of it, as another CPU's.
    tracked = re.search(r"^\| reference \|(?:[^|]*\|){3} ([\d.]+e-\d+) \|", table, re.MULTILINE)
    assert tracked, "the reference row lost its error column"
    other = "9.99e-12" if tracked.group(1) != "9.99e-12" else "1.11e-11"
    other_cpu = table.replace(f"| {tracked.group(1)} |", f"| {other} |", 1)
    assert other_cpu != table and _untimed(other_cpu) == _untimed(table)
    assert _rounding_errors(other_cpu) != _rounding_errors(table)
