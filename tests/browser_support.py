"""Debian's Chromium driven by Playwright, and the demo as a real process: shared by the browser
tests and docs/screenshot.py (the README's screenshot is made with the same tooling)."""

from __future__ import annotations

import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.parse
from pathlib import Path

import pytest

CHROMIUM = "/usr/bin/chromium"
# No downloads and no GPU here: software WebGL (for viser's scene) and no background networking.
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--enable-unsafe-swiftshader"]
ROOT = Path(__file__).resolve().parents[1]
# The id of the deepest state the graph highlights as active (a JavaScript expression), or null.
ACTIVE_LEAF = """(() => {
    const ids = [...document.querySelectorAll('#graph g.node.active')].map(g => g.id);
    ids.sort((a, b) => b.length - a.length);
    return ids[0] || null;
})()"""
FSMSCOPE = [sys.executable, "-m", "server.cli"]


def launch_chromium(playwright):
    """A headless Chromium from the Debian package, with a fresh temporary profile."""
    return playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)


@pytest.fixture(scope="module")
def browser():
    """Debian's Chromium, shared by the tests of one module (import this fixture into the module)."""
    playwright_api = pytest.importorskip("playwright.sync_api")
    if not os.path.exists(CHROMIUM):
        pytest.skip("Debian's chromium is not installed (make apt)")
    if not shutil.which("dot"):
        pytest.skip("Graphviz's dot is not installed (make apt)")  # the server draws the graph with it
    with playwright_api.sync_playwright() as pw:
        chromium = launch_chromium(pw)
        yield chromium
        chromium.close()


def open_page(browser, url: str, width: int = 1280, height: int = 800, timeout_ms: int = 15000):
    """A new page of ``browser`` at ``width`` x ``height``, loaded from ``url``, showing a graph.

    ``page.errors`` collects the page's uncaught errors."""
    page = browser.new_page(viewport={"width": width, "height": height})
    page.set_default_timeout(timeout_ms)
    page.errors = []
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    page.goto(url)
    page.wait_for_selector("#graph svg")
    return page


def watch(browser, server, machine: str):
    """A page showing ``machine`` of ``server`` (a ServerThread) with its stream live."""
    page = open_page(browser, server.url + "#m=" + urllib.parse.quote(machine), timeout_ms=8000)
    page.wait_for_selector("#badge.live")
    assert page.input_value("#machine-picker") == machine
    return page


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class DemoProcess:
    """``fsmscope demo`` in its own process group; ``url`` is the dashboard address it printed."""

    def __init__(self, record: Path, *extra: str, token: str = "demo-test-token") -> None:
        self.token = token
        self.record = record
        self.port = free_port()
        self.proc = subprocess.Popen(
            FSMSCOPE + ["demo", "--port", str(self.port), "--token", token, "--record", str(record), *extra],
            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)
        self.url = self._wait_for_url()

    def _wait_for_url(self, timeout: float = 60.0) -> str:
        deadline = time.monotonic() + timeout
        lines = []
        while time.monotonic() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                break
            lines.append(line)
            found = re.search(r"open (http://\S+)", line)
            if found:
                return found.group(1)
        self.stop()
        raise RuntimeError("fsmscope demo printed no URL:\n" + "".join(lines))

    def stop(self, timeout: float = 20.0) -> int:
        """SIGINT, as Ctrl-C would; returns the exit code."""
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGINT)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        if self.proc.stdout is not None:
            self.rest = self.proc.stdout.read()
            self.proc.stdout.close()
        return self.proc.returncode


FIREFOX = "/usr/bin/firefox-esr"
# Nothing outside this machine is reachable: keep Firefox from trying.
_FIREFOX_PREFS = """
user_pref("app.normandy.enabled", false);
user_pref("app.update.enabled", false);
user_pref("browser.safebrowsing.malware.enabled", false);
user_pref("browser.safebrowsing.phishing.enabled", false);
user_pref("datareporting.policy.dataSubmissionEnabled", false);
user_pref("network.connectivity-service.enabled", false);
user_pref("services.settings.server", "http://127.0.0.1:9/");
user_pref("toolkit.telemetry.enabled", false);
"""


class Firefox:
    """Debian's Firefox ESR driven over WebDriver BiDi, which it speaks natively (Playwright
    drives only its own Firefox build, and Debian has no geckodriver)."""

    def __init__(self, width: int = 1280, height: int = 800, timeout: float = 30.0) -> None:
        import tempfile

        from websockets.sync.client import connect

        self._dir = tempfile.TemporaryDirectory()
        profile = Path(self._dir.name) / "profile"
        profile.mkdir()
        (profile / "user.js").write_text(_FIREFOX_PREFS)
        self._log = open(Path(self._dir.name) / "firefox.log", "w+")
        self.proc = subprocess.Popen([FIREFOX, "--headless", "--no-remote", "--profile", str(profile),
                                      "--remote-debugging-port", "0", "--window-size=%d,%d" % (width, height)],
                                     stdout=self._log, stderr=subprocess.STDOUT, start_new_session=True)
        url = self._wait_for_bidi(timeout)
        self._ws = connect(url + "/session", max_size=None, open_timeout=timeout)
        self._id = 0
        self.command("session.new", {"capabilities": {}})
        self.context = self.command("browsingContext.getTree", {})["contexts"][0]["context"]

    def _wait_for_bidi(self, timeout: float) -> str:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            self._log.seek(0)
            found = re.search(r"WebDriver BiDi listening on (ws://\S+)", self._log.read())
            if found:
                return found.group(1)
            if self.proc.poll() is not None:
                break
            time.sleep(0.1)
        self.close()
        raise RuntimeError("Firefox did not start WebDriver BiDi")

    def command(self, method: str, params: dict) -> dict:
        import json

        self._id += 1
        self._ws.send(json.dumps({"id": self._id, "method": method, "params": params}))
        while True:
            message = json.loads(self._ws.recv())
            if message.get("id") == self._id:
                if message.get("type") == "error":
                    raise RuntimeError("%s: %s" % (message.get("error"), message.get("message")))
                return message["result"]

    def goto(self, url: str) -> None:
        self.command("browsingContext.navigate", {"context": self.context, "url": url, "wait": "complete"})

    def evaluate(self, expression: str):
        """The value of a JavaScript expression (strings, numbers, booleans, null)."""
        result = self.command("script.evaluate", {"expression": expression, "awaitPromise": True,
                                                  "target": {"context": self.context}})
        if result.get("type") == "exception":
            raise RuntimeError(result["exceptionDetails"]["text"])
        return result["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 15.0):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            value = self.evaluate(expression)
            if value:
                return value
            time.sleep(0.1)
        raise TimeoutError("never true in Firefox: " + expression)

    def screenshot(self, path: Path) -> None:
        import base64

        data = self.command("browsingContext.captureScreenshot", {"context": self.context})["data"]
        Path(path).write_bytes(base64.b64decode(data))

    def close(self) -> None:
        try:
            self._ws.close()
        except Exception:
            pass
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        self._log.close()
        self._dir.cleanup()


def filter_log(page, text: str = "", kinds=None) -> None:
    """Filter the event log as a user does: ``text`` in the search box, only ``kinds`` ticked (None: all)."""
    page.fill("#log-filter", text)
    page.click("#log-kinds > summary")  # opens the popover of kinds
    page.click("#log-kinds button[data-check=%s]" % ("all" if kinds is None else "none"))
    for kind in kinds or ():
        page.check("#log-kinds input[value=%s]" % kind)
    page.keyboard.press("Escape")
