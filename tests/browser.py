"""Headless Chromium for the player's tests and benchmarks, driven by Playwright.

The browser is Debian's ``chromium`` (``.ci/run`` installs it on a fresh machine), never one
that Playwright would download. Without it the tests skip, saying so; where the environment
variable CI is set they fail instead, so CI cannot pass without having run them.

:func:`open_player` opens a player page with every request recorded and every request that
is not the page itself refused (the page must need no network), and every console message
and page error kept.
"""

from __future__ import annotations

import contextlib
import os
import shutil
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: Where Debian's package puts the browser, else the first ``chromium`` on the PATH.
CHROMIUM = ("/usr/bin/chromium",)
#: Flags for a quiet headless run in a container: no sandbox (root), no GPU, nothing fetched.
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]


def chromium() -> str | None:
    """The path of a Chromium to drive, or None."""
    for path in CHROMIUM:
        if os.access(path, os.X_OK):
            return path
    return shutil.which("chromium")


def unavailable() -> str | None:
    """Why the browser tests cannot run here, or None."""
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "the Python package playwright is not installed (pip install '.[test]')"
    if chromium() is None:
        return ("no Chromium found at /usr/bin/chromium or on the PATH (Debian: apt-get "
                "install chromium; .ci/run installs it)")
    return None


@contextlib.contextmanager
def launched() -> Iterator[Any]:
    """A headless Chromium (Playwright's Browser), closed on the way out, whatever
    happens."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium(), args=ARGS)
        try:
            yield browser
        finally:
            browser.close()


@dataclass
class Opened:
    """An open player page, the requests it made and the console messages and errors it
    gave."""

    page: Any
    url: str
    requests: list[str] = field(default_factory=list)
    refused: list[str] = field(default_factory=list)
    console: list[str] = field(default_factory=list)

    def state(self) -> dict[str, Any]:
        return self.page.evaluate("window.dumbbellPlayer.state()")

    def table(self) -> dict[tuple[int, str], str]:
        """The table of values: (run, name) -> the text shown."""
        cells = self.page.eval_on_selector_all(
            "#readout td", "tds => tds.map(td => [td.dataset.run, td.dataset.name, "
            "td.textContent])")
        return {(int(r), n): text for r, n, text in cells}

    def shown(self) -> str:
        """The time shown (body's data-shown, the chosen run's sample time)."""
        return self.page.get_attribute("body", "data-shown")

    def wait_shown(self, before: str | None) -> str:
        """Wait until the time shown is no longer ``before``; returns it."""
        self.page.wait_for_function("b => document.body.dataset.shown !== b", arg=before)
        return self.shown()


def open_player(browser: Any, path: Path, fragment: str = "", size: tuple[int, int] = (1280, 720)
                ) -> Opened:
    """Open the page at ``path`` (with a ``fragment`` such as '#t=0.5') in a new page of
    ``size`` (CSS px, device scale 1) and wait until it has drawn its first frame."""
    page = browser.new_page(viewport={"width": size[0], "height": size[1]},
                            device_scale_factor=1)
    url = Path(path).resolve().as_uri()
    opened = Opened(page, url)
    page.on("request", lambda r: opened.requests.append(r.url))
    page.on("console", lambda m: opened.console.append(f"{m.type}: {m.text}"))
    page.on("pageerror", lambda e: opened.console.append(f"pageerror: {e}"))

    def route(r: Any) -> None:
        if r.request.url.split("#")[0] == url:
            r.continue_()
        else:
            opened.refused.append(r.request.url)
            r.abort()

    page.route("**/*", route)
    page.goto(url + fragment)
    page.wait_for_selector("body[data-ready]")
    return opened
