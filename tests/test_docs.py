"""The documentation's links resolve, and no file cites a document outside the repository."""

from __future__ import annotations

import importlib.util
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
    assert len(readme.encode()) <= 12 * 1024
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    # .ci/run runs the README's second quick-start command verbatim.
    second = next(line for line in readme.splitlines() if "pip install '.[test]' && pytest" in line)
    assert second.strip() in ci
