"""Debian's Chromium (``/usr/bin/chromium``) driven by the playwright pip package: no browser
download, no GPU. Playwright is imported by the caller (``sync_playwright()``), never here."""

from __future__ import annotations

from typing import Any
from urllib.parse import urlsplit

CHROMIUM = "/usr/bin/chromium"
# No downloads and no GPU here: software WebGL (for viser's scene) and no background networking.
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--enable-unsafe-swiftshader"]


def launch_chromium(playwright: Any) -> Any:
    """A headless Chromium from the Debian package, with a fresh temporary profile."""
    return playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)


# How long a test's page waits for what it expects before it fails: a bound, not a figure (a waited-for
# selector costs only the time it takes), generous because the suite runs in parallel on two cores.
PAGE_WAIT_MS = 30000


def open_page(browser: Any, url: str, width: int = 1280, height: int = 800, timeout_ms: int = PAGE_WAIT_MS,
              scene: bool = True) -> Any:
    """A new page of ``browser`` at ``width`` x ``height``, loaded from ``url`` (the dashboard's
    address with its token), showing a graph.

    ``scene=False`` refuses the page every request to another origin than the dashboard's, so the 3D
    view's frame (viser, on its own port) stays empty: with no GPU, software WebGL drawing the moving
    arm takes one and a half cores, which a page checking the dashboard's own behaviour never looks at.
    ``page.errors`` collects the page's uncaught errors."""
    page = browser.new_page(viewport={"width": width, "height": height})
    page.set_default_timeout(timeout_ms)
    page.errors = []
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    if not scene:
        origin = urlsplit(url)
        page.route(lambda asked: urlsplit(asked).netloc != origin.netloc, lambda route: route.abort())
    page.goto(url)
    page.wait_for_selector("#graph svg")
    return page
