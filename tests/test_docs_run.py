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
