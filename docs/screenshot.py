"""Make docs/demo.png, the README's picture: the demo page mid-episode (graph beside the arm).

    .venv/bin/python docs/screenshot.py

Runs `fsmscope demo` as a real process and drives Debian's Chromium with Playwright, the
same tooling as the browser tests (server.testing).
"""

import sys
import tempfile
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

from fsmscope.server.testing.browser import launch_chromium, open_page
from fsmscope.server.testing.demo_process import DemoProcess

OUT = Path(__file__).resolve().parent / "demo.png"
# Mid-episode: the arm carries the cube.
WANTED = "s:/SM_ROOT/TASK/PLACE/TRANSPORT"


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        demo = DemoProcess(Path(tmp) / "demo.jsonl")
        try:
            with sync_playwright() as pw:
                browser = launch_chromium(pw)
                page = open_page(browser, demo.url, 1440, 900, timeout_ms=30000)
                page.wait_for_selector("#scene-pane:not([hidden]) iframe")
                scene = page.frame_locator("#scene-pane iframe")
                scene.locator("canvas").first.wait_for(state="visible")
                # viser warns that WebGL runs in software: true here (no GPU), not on a user's desk.
                close = scene.locator(".mantine-Notification-closeButton")
                try:
                    close.first.click(timeout=5000)
                except Exception:
                    pass
                page.wait_for_selector('[id="%s"].active' % WANTED, timeout=60000)
                time.sleep(0.3)  # let the 3D view draw the arm where the graph says it is
                page.screenshot(path=str(OUT))
                browser.close()
        finally:
            demo.stop()
    print("wrote", OUT)
    return 0


if __name__ == "__main__":
    sys.exit(main())
