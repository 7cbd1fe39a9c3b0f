"""The documentation as a site: ``mkdocs build --strict`` (mkdocs.yml, tools/docsite.py) builds
README.md, every page of docs/ and the API reference without a warning, and the site it
writes loads nothing from the network, keeps every link and anchor working, has a search
index of every page, and documents every public name."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import zlib
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

from tests.conftest import ROOT, load_tool

docsite = load_tool("docsite")

#: Tags and attributes whose URL the browser loads (a plain <a href> is only followed).
LOADS = {("script", "src"), ("img", "src"), ("iframe", "src"), ("source", "src"),
         ("video", "src"), ("audio", "src"), ("embed", "src"), ("object", "data"),
         ("link", "href")}


class Page(HTMLParser):
    """The ids, the links and the loaded URLs of one HTML page."""

    def __init__(self) -> None:
        super().__init__()
        self.ids: set[str] = set()
        self.links: list[str] = []
        self.loads: list[str] = []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if attrs.get("id"):
            self.ids.add(attrs["id"])
        for name in ("href", "src", "data"):
            value = attrs.get(name)
            if not value:
                continue
            self.links.append(value)
            if (tag, name) in LOADS and not (tag == "link" and attrs.get("rel") == "canonical"):
                self.loads.append(value)


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> Path:
    """The site, built once with the one command the docs give."""
    out = tmp_path_factory.mktemp("site")
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir",
                           str(out)], cwd=ROOT, capture_output=True, text=True, env=env,
                          timeout=300, check=False)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "WARNING" not in done.stderr, done.stderr
    return out


@pytest.fixture(scope="module")
def pages(built) -> dict[Path, Page]:
    out = {}
    for path in built.rglob("*.html"):
        page = Page()
        page.feed(path.read_text(encoding="utf-8"))
        out[path] = page
    return out


def test_every_page_of_the_docs_is_in_the_site_and_its_search(built):
    names = {p.stem for p in (ROOT / "docs").glob("*.md")}
    assert {n for n in names if not (built / f"{n}.html").is_file()} == set()
    assert (built / "readme.html").is_file()
    index = json.loads((built / "search" / "search_index.json").read_text(encoding="utf-8"))
    located = {entry["location"].split("#")[0] for entry in index["docs"]}
    assert {f"{n}.html" for n in names} | {"readme.html"} <= located
    # Search finds words of the pages' text, not only their titles.
    text = " ".join(entry["text"] for entry in index["docs"])
    assert "Euler-Cromer" in text and "w·dt" in text


def test_the_site_loads_nothing_from_the_network(built, pages):
    remote = [f"{path.relative_to(built)}: {url}" for path, page in pages.items()
              for url in page.loads if re.match(r"(https?:)?//", url)]
    assert remote == []
    for css in built.rglob("*.css"):
        text = css.read_text(encoding="utf-8")
        assert not re.search(r"@import\s+(url\()?[\"']?(https?:)?//", text), css
        assert not re.search(r"url\(\s*[\"']?(https?:)?//", text), css


def test_every_link_and_anchor_of_the_site_resolves(built, pages):
    broken = []
    for path, page in pages.items():
        for link in page.links:
            parts = urlsplit(link)
            if parts.scheme or link.startswith("//") or parts.path.startswith("/"):
                continue
            target = (path.parent / unquote(parts.path)).resolve() if parts.path else path
            if not target.is_relative_to(built.resolve()) or not target.exists():
                broken.append(f"{path.relative_to(built)}: {link}: no such file")
            elif (parts.fragment and target.suffix == ".html" and target in pages
                  and unquote(parts.fragment) not in pages[target].ids):
                broken.append(f"{path.relative_to(built)}: {link}: no such anchor")
    assert broken == []


def test_no_sphinx_role_is_left_in_a_rendered_docstring(built):
    """``:func:`energy``` in a docstring shows as a code span (linked where the reference has
    the name), never as the role's text."""
    left = [f"{path.relative_to(built)}: {m.group(0)}" for path in built.rglob("*.html")
            for m in re.finditer(r":(class|func|meth|attr|data|exc|mod|obj):<code>",
                                 path.read_text(encoding="utf-8"))]
    assert left == []


def test_the_readme_links_into_the_docs(pages, built):
    readme = pages[built / "readme.html"]
    docs = {Path(urlsplit(link).path).stem for link in readme.links
            if urlsplit(link).path.endswith(".html")}
    assert {"physics", "cli", "api", "spaces", "measurements"} <= docs


def inventory(built: Path) -> set[str]:
    """Every name and anchor of the site's objects.inv (the reference's index)."""
    _, body = (built / "objects.inv").read_bytes().split(b"zlib.\n", 1)
    out = set()
    for line in zlib.decompress(body).decode().splitlines():
        name, _, _, uri = line.split(" ", 4)[:4]
        out |= {name, uri.partition("#")[2]}
    return out


def test_every_public_name_is_in_the_reference(built):
    from tests.test_api_border import public

    documented = inventory(built)
    paths = [p for paths in docsite.public_names().values() for p in paths]
    assert len(paths) >= 100
    assert sorted(p for p in paths if p not in documented) == []
    # The border test's public callables (methods too) are each documented under their own
    # name; a solver's contract methods are the contract's (dumbbell.solvers.base.Solver).
    solvers = docsite.importlib.import_module("dumbbell.solvers")
    contracts = {f"{c.__module__}.{c.__qualname__}": c for c in solvers.METHODS.values()}
    missing = []
    for key in public():
        owner, _, method = key.rpartition(".")
        if owner in contracts:
            key = next((f"{b.__module__}.{b.__qualname__}.{method}"
                        for b in contracts[owner].__mro__ if method in vars(b)
                        and f"{b.__module__}.{b.__qualname__}" in documented), key)
        if key not in documented:
            missing.append(key)
    assert missing == [], missing
