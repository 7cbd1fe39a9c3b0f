"""Docs that are tests: every code block of README.md and docs/*.md runs as written, in a
fresh folder with a copy of scenes/ beside it, against the installed package
(tools/docblocks.py says how each language runs). What the blocks leave in renders/ is a
showcase file with the tracked bytes, or a file git ignores: the docs' commands write outside
renders/ unless they are the showcase's."""

from __future__ import annotations

import pytest

from tests.conftest import ROOT, load_tool

docblocks = load_tool("docblocks")
FILES = docblocks.doc_files(ROOT)
#: Most blocks that may be marked illustrative (each with its reason): the README's install
#: commands (CI runs command 2 verbatim), the development page's whole suite and ruff, and
#: a Dask cluster of one's own machines.
MAX_ILLUSTRATIVE = 3


@pytest.fixture(scope="module")
def ran():
    """Every page's blocks run, the pages shared between two processes."""
    return docblocks.run_files(FILES, ROOT)


@pytest.mark.parametrize("path", FILES, ids=[p.name for p in FILES])
def test_every_block_runs_as_written(path, ran):
    from tests.test_showcase import IN_DOCS, spellings

    results, left, written = ran[path]
    failures = [f"{r.block}: {r.error}" for r in results if r.error]
    assert failures == [], "\n\n".join(failures)
    assert left == []
    # A showcase piece this file runs wrote all of its tracked files (checked above).
    ran = docblocks.commands(ROOT, [path])
    for piece in IN_DOCS:
        if spellings(piece) & ran:
            assert set(piece.writes) <= written, piece.command


def test_nearly_every_block_runs_and_the_others_say_why():
    every = [b for path in FILES for b in docblocks.blocks(path, ROOT)]
    code = [b for b in every if b.lang in docblocks.RUN]
    illustrative = [b for b in code if not b.runs]
    assert len(code) >= 20 and len(illustrative) <= MAX_ILLUSTRATIVE
    assert all(b.illustrative and len(b.illustrative) > 10 for b in illustrative)
    assert all(b.lang in docblocks.RUN | docblocks.DATA for b in every)


def test_the_runner_fails_what_does_not_run(tmp_path):
    (tmp_path / "scenes").mkdir()
    (tmp_path / "renders").mkdir()
    (tmp_path / ".gitignore").write_text("renders/*\n!renders/*.png\n")
    doc = tmp_path / "README.md"
    doc.write_text(
        "```python\nx = 1\n```\n\n```python\nassert x == 2, 'x is 1'\n```\n\n"
        "```sh\ndumbbell simulate nowhere.toml  # exits 2\n```\n\n"
        "```console\n$ echo hello\nhallo\n```\n\n"
        "```console\n$ dumbbell --version\ndumbbell ...\n$ echo $?\n0\n```\n\n"
        "<!-- illustrative: never runs -->\n```sh\nexit 1\n```\n\n"
        "```\nno language\n```\n\n"
        "```sh\nmkdir -p renders && touch renders/stray.png renders/ok.csv\n```\n")
    results, left, written = docblocks.run_file(doc, tmp_path)
    errors = [(r.block.line, (r.error or "").split("\n")[0][:40]) for r in results]
    assert errors == [(1, ""), (5, "AssertionError: x is 1"),
                      (9, "`dumbbell simulate nowhere.toml  # exits"),
                      (13, "`echo hello` printed (exit 0):"), (18, ""), (26, ""),
                      (30, "a fence without a known language (''): l"), (34, "")]
    assert left == ["renders/stray.png: not a showcase file, and git would see it"]
    assert written == {"stray.png", "ok.csv"}


def test_a_repr_a_page_shows_is_the_code_s(tmp_path):
    """A comment showing a repr (a name and a parenthesis) is checked against the value; a
    number cut with '...' stands for its digits only, so it cannot hide a field the page
    left out (the README's Impact without heat=None was such a case)."""
    (tmp_path / "scenes").mkdir()
    doc = tmp_path / "README.md"
    doc.write_text(
        "```python\nfrom fractions import Fraction\n"
        "Fraction(1, 3)  # Fraction(1, 3)\n"
        "Fraction(2, 3)  # Fraction(2, ...)\n```\n\n"
        "```python\nFraction(1, 3)  # Fraction(1, 4)\n```\n\n"
        "```python\nclass P:\n    def __init__(self, x):\n        self.x = x\n\n"
        "    def __repr__(self):\n        return f'P(x={self.x}, y=None)'\n\n\n"
        "P(1.23456)  # P(x=1.23..., y=None)\nP(1.23456)  # P(x=1.23...)\n```\n")
    results, _, _ = docblocks.run_file(doc, tmp_path)
    errors = [(r.block.line, (r.error or "")[:60]) for r in results]
    assert errors[0] == (1, "")
    assert errors[1][0] == 7 and "shows 'Fraction(1, 4)'" in errors[1][1]
    assert errors[2][0] == 11 and "line 10: the page shows 'P(x=1.23...)'" in results[2].error


def test_a_command_two_pages_run_runs_once_and_both_pages_get_its_files(tmp_path, monkeypatch):
    """A ``dumbbell`` command line two blocks run, on the same inputs, runs once: the second
    page's folder gets the files it wrote and its block the status and output. Other
    inputs (a changed scene) run it again."""
    import dumbbell.cli
    from tests.hostile import SHORT_SCENE

    (tmp_path / "scenes").mkdir()
    (tmp_path / "scenes" / "short.toml").write_text(SHORT_SCENE)
    (tmp_path / "docs").mkdir()
    line = "dumbbell simulate scenes/short.toml -o short.csv"
    check = "```python\nfrom pathlib import Path\n" \
            "assert Path('short.csv').read_text().startswith('t,xA,vA')\n```\n"
    (tmp_path / "README.md").write_text(f"```sh\n{line}\n```\n\n{check}")
    (tmp_path / "docs" / "a.md").write_text(f"```console\n$ {line}\n$ echo $?\n0\n```\n\n{check}")
    (tmp_path / "docs" / "b.md").write_text(
        f"```sh\nsed -i s/200.0/300.0/ scenes/short.toml\n{line}\n```\n\n{check}")
    assert docblocks.repeated(tmp_path) == {line}
    calls = []
    main = dumbbell.cli.main
    monkeypatch.setattr(dumbbell.cli, "main", lambda argv: calls.append(argv) or main(argv))
    monkeypatch.setattr(docblocks, "_RAN", {})
    for page in ("README.md", "docs/a.md", "docs/b.md"):
        results, _, _ = docblocks.run_file(tmp_path / page, tmp_path)
        assert [r.error for r in results] == [None, None], page
    # README.md and a.md share the run; b.md's scene differs: it runs again.
    assert len(calls) == 2
