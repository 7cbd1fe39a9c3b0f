"""The documentation's links resolve, and no file cites a document outside the repository."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _doclinks():
    spec = importlib.util.spec_from_file_location("doclinks", ROOT / "tools" / "doclinks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_link_and_image_in_the_docs_resolves():
    doclinks = _doclinks()
    assert len(doclinks.doc_files()) >= 10
    assert doclinks.broken() == []


def test_a_broken_link_image_or_anchor_fails(tmp_path):
    doclinks = _doclinks()
    (tmp_path / "docs").mkdir()
    (tmp_path / "pic.png").write_bytes(b"png")
    (tmp_path / "README.md").write_text(
        "# Title\n\n## A `code` heading: here\n\n"
        "[ok](docs/page.md) [ok anchor](docs/page.md#second-part) [self](#a-code-heading-here)\n"
        "![ok](pic.png) [web](https://example.org/missing)\n"
        "```\n[in a code block](nowhere.md)\n```\n"
        "`[inline code](nowhere.md)`\n"
        "[gone](docs/missing.md) ![gone](renders/missing.png)\n"
        '<img src="missing.gif"> [outside](../outside.md)\n', encoding="utf-8")
    (tmp_path / "docs" / "page.md").write_text(
        "# Page\n\n## Second part\n\n[back](../README.md) [bad anchor](../README.md#nope)\n",
        encoding="utf-8")
    problems = doclinks.broken(tmp_path)
    assert [p.split(": ")[0] for p in problems] == [
        "README.md:11", "README.md:11", "README.md:12", "README.md:12", "docs/page.md:5"]
    assert "docs/missing.md: no such file" in problems[0]
    assert "renders/missing.png: no such file" in problems[1]
    assert "../outside.md: points outside the repository" in problems[2]
    assert "missing.gif: no such file" in problems[3]
    assert "#nope" in problems[4]
    assert doclinks.main([str(tmp_path)]) == 1
    (tmp_path / "README.md").write_text("[fine](docs/page.md#second-part)\n", encoding="utf-8")
    (tmp_path / "docs" / "page.md").write_text("## Second part\n", encoding="utf-8")
    assert doclinks.main([str(tmp_path)]) == 0


def test_no_file_cites_a_document_outside_the_repository():
    outside = ("PHYSICS" + ".md", "../" + "shared", "/" + "work/")
    folders = ["src", "tests", "docs", "scenes", "benchmarks", "tools", "examples"]
    files = [ROOT / "README.md", ROOT / "pyproject.toml"]
    for folder in folders:
        files += [p for p in (ROOT / folder).rglob("*")
                  if p.is_file() and p.suffix in {".py", ".md", ".toml", ".ipynb", ".txt"}]
    cited = [f"{p.relative_to(ROOT)}: {s}" for p in files
             for s in outside if s in p.read_text(encoding="utf-8", errors="replace")]
    assert cited == []


def test_the_readme_is_a_front_door():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(readme.encode()) <= 10 * 1024
    # Its first screen says who it is for, each reader with where to start.
    first_screen = "\n".join(readme.splitlines()[:25])
    assert "teachers, students and textbook authors" in first_screen
    assert "pymunk users" in first_screen and "`dumbbell run`" in first_screen
    # Exactly two quick-start commands; .ci/run runs the second verbatim.
    quick = readme.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    commands = [line for line in quick.split("```sh", 1)[1].split("```", 1)[0].splitlines()
                if line.strip() and not line.lstrip().startswith("#")]
    assert len(commands) == 2, commands
    assert "pip install . && dumbbell run" in commands[0]
    assert "pip install '.[test]' && pytest" in commands[1]
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert commands[1].strip() in ci
    # One picture, and a start-here section for each reader.
    assert len(re.findall(r"!\[[^\]]*\]\(", readme)) + readme.count("<img") == 1
    assert "### For teachers" in readme and "### For pymunk users" in readme


def _blocks(page: str):
    from tests.conftest import load_tool

    return load_tool("docblocks").blocks(ROOT / page, ROOT)


def test_the_readme_s_pymunk_recipe_is_the_one_the_spaces_page_opens_with():
    readme = next(b for b in _blocks("README.md") if b.lang == "python" and "pymunk" in b.code)
    first = _blocks("docs/spaces.md")[0]
    assert first.lang == "python" and first.code == readme.code
    code = first.code
    # A pygame-style space: pixels, y down, units unnamed; the four tools on it.
    assert "space.gravity = (0, 900)" in code and "units=" not in code
    for tool in ("spaces.report(", "spaces.Ledger(", "spaces.Recorder(", "spaces.energy("):
        assert tool in code
    assert len([line for line in code.splitlines() if line.strip()]) <= 20


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?")


def _same_to_rounding(shown: str, printed: str) -> bool:
    """The text of both the same, and each number the same as printed, or both below 1e-6
    (a rounding residue, whose digits depend on the CPU's summation order)."""
    if _NUMBER.sub("#", shown) != _NUMBER.sub("#", printed):
        return False
    pairs = zip(_NUMBER.findall(shown), _NUMBER.findall(printed), strict=True)
    return all(a == b or (abs(float(a)) < 1e-6 and abs(float(b)) < 1e-6) for a, b in pairs)


def test_the_spaces_page_s_recipe_passes_its_own_guard_and_prints_what_the_page_shows(
        tmp_path, monkeypatch):
    import contextlib
    import io

    recipe, listing = _blocks("docs/spaces.md")[:2]
    assert (recipe.lang, listing.lang) == ("python", "text")
    monkeypatch.chdir(tmp_path)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        # The page's own code, run as the docs' runner runs it (tools/docblocks.py).
        exec(compile(recipe.code, "docs/spaces.md", "exec"), {"__name__": "__main__"})  # noqa: S102
    printed = out.getvalue()
    report = printed.split("\nSpaceEnergy(", 1)[0]
    assert "FAIL" not in report and report.rstrip().endswith("nothing to fix")
    assert "complete: True" in printed and (tmp_path / "ball.gif").stat().st_size > 0
    shown, got = listing.code.splitlines(), printed.splitlines()
    assert len(shown) == len(got)
    assert [(a, b) for a, b in zip(shown, got, strict=True) if not _same_to_rounding(a, b)] == []
    # The numbers the page's prose quotes from the run are the listing's.
    prose = (ROOT / "docs/spaces.md").read_text(encoding="utf-8").split("How to read it:", 1)[1]
    prose = prose.split("**Units.**", 1)[0]
    for number in ("10.49 units", "25", "193725", "134.141"):
        assert number in prose and number.split()[0] in listing.code, number


def test_the_comparison_sees_what_differs():
    assert _same_to_rounding("a = -4.44089e-16 b", "a = 3.1e-17 b")
    assert not _same_to_rounding("a = 134.141", "a = 134.142")
    assert not _same_to_rounding("ok 1 units", "FAIL 1 units")
