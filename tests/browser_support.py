"""Helpers of the browser tests: the dashboard's page for a machine of a live server (or served alone), the
active state as the graph shows it, the event log's filter, Debian's Firefox over WebDriver BiDi, and
the one ``fsmscope demo`` process the demo's tests share (SharedDemo). Chromium and the demo process
are in server.testing (bench/ and docs/ use them too)."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import subprocess
import threading
import urllib.parse
from pathlib import Path

import fsm
import httpx
from fsmscope.server.testing.browser import open_page
from fsmscope.server.http_server import ServerThread
from fsmscope.server.testing.polling import wait_for

ROOT = Path(__file__).resolve().parents[1]
# The id of the deepest state the graph highlights as active (a JavaScript expression), or null.
ACTIVE_LEAF = """(() => {
    const ids = [...document.querySelectorAll('#graph g.node.active')].map(g => g.id);
    ids.sort((a, b) => b.length - a.length);
    return ids[0] || null;
})()"""

# A computed style of the first shape of the overlay's copy of a drawing element (fsmscope/static/graph_marks.js:
# the marks are drawn there), the copy found by its shape lying over the element's; null when none does.
_MARK_STYLE = """([id, property]) => {
    const shape = (g) => g.querySelector(':scope > :is(ellipse, polygon, path)');
    const at = shape(document.getElementById(id)).getBoundingClientRect();
    const over = (g) => {
        const b = shape(g)?.getBoundingClientRect();
        return b && [b.x - at.x, b.y - at.y, b.width - at.width, b.height - at.height].every((d) => Math.abs(d) < 0.75);
    };
    const copy = [...document.querySelectorAll('#graph svg.graph-marks g[class]')].find(over);
    return copy ? getComputedStyle(shape(copy))[property] : null;
}"""


def mark_style(page, element_id: str, css_property: str):
    """The computed ``css_property`` of the shape the graph draws over ``element_id`` as its mark (None: no mark)."""
    return page.evaluate(_MARK_STYLE, [element_id, css_property])


@contextlib.contextmanager
def served_page(browser, machine, name: str, **entry):
    """A page watching ``machine``, served alone by a fresh server (``entry``: add_local's options);
    the page must end without a script error. ``page.server`` is the server."""
    srv = ServerThread().start()
    srv.hub.add_local(machine, name=name, **entry)
    try:
        page = watch(browser, srv, name)
        page.server = srv
        yield page
        assert not page.errors
    finally:
        srv.stop()


@contextlib.contextmanager
def serving_while_running(machine, stop: threading.Event, name: str):
    """A fresh server showing ``machine`` (as ``name``) while it runs in a thread, until ``stop`` is set at
    the end: a machine of server.testing.big_machine, shared by the tests of a module."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    srv = ServerThread().start()
    srv.hub.add_local(machine, name=name)
    runner = threading.Thread(target=machine.execute)
    runner.start()
    try:
        yield srv
    finally:
        stop.set()
        runner.join(10)
        srv.stop()


@contextlib.contextmanager
def page_while_waiting(browser, build, name: str):
    """A page watching the machine ``build(gate)`` makes, served alone, while it runs and waits for ``gate``
    (a threading.Event, set at the end)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    gate = threading.Event()
    sm = build(gate)
    runner = threading.Thread(target=sm.execute)
    try:
        with served_page(browser, sm, name) as page:
            runner.start()
            page.wait_for_selector("#run-state.running")
            yield page
    finally:
        gate.set()
        if runner.is_alive():
            runner.join(10)


def watch(browser, server, machine: str):
    """A page showing ``machine`` of ``server`` (a ServerThread) with its stream live."""
    page = open_page(browser, server.url + "#m=" + urllib.parse.quote(machine))
    page.wait_for_selector("#badge.live")
    assert page.input_value("#machine-picker") == machine
    return page


@contextlib.contextmanager
def page_at(browser, url: str, ready: str | None = None, width: int = 1280, height: int = 800,
            scene: bool = True):
    """A page of ``browser`` at ``url`` showing a graph (and ``ready``, a selector, when given), for a
    test or a module; it must end without a script error, and is closed. ``scene``: as open_page."""
    page = open_page(browser, url, width, height, scene=scene)
    try:
        if ready is not None:
            page.wait_for_selector(ready)
        yield page
        assert not page.errors
    finally:
        page.close()


@contextlib.contextmanager
def watching(browser, server, machine: str, ready: str | None = None):
    """``watch``'s page (and ``ready``, a selector, shown) as ``page_at`` gives it: closed at the end,
    which it must reach without a script error."""
    with page_at(browser, server.url + "#m=" + urllib.parse.quote(machine), "#badge.live") as page:
        assert page.input_value("#machine-picker") == machine
        if ready is not None:
            page.wait_for_selector(ready)
        yield page


def scene_client(scene, page) -> int:
    """The viser client of ``page``'s 3D view (``scene``: the sim.scene.Scene it shows): the one that
    connected with the view id in the address of the page's frame (fsmscope/static/scene.js)."""
    view = page.eval_on_selector("#scene-pane iframe",
                                 "f => new URL(new URL(f.src).searchParams.get('websocket')).pathname.split('/').pop()")
    return wait_for(lambda: [c for c, v in scene.clients().items() if v == view], timeout=30,
                    what="the page's frame to connect to viser")[0]


def as_page(http: httpx.Client, page) -> httpx.Client:
    """``http`` sending the page's id: the operator lease (docs/debugging.md) is held by the page whose
    controls took it, so the test's own requests come from that page."""
    http.headers["X-Fsmscope-Page"] = page.evaluate("async () => (await import('/api.js')).PAGE_ID")
    return http


# The debugger banner's text, null while it is hidden.
SHOWN_BANNER = """() => document.getElementById('debug-bar').hidden
    ? null : document.querySelector('#debug-bar .debug-text').textContent"""


def banner_saying(page, words: str = "", timeout: float = 8.0) -> str:
    """The banner's text once it is shown saying ``words``; failing, what it said instead."""
    def said() -> str | None:
        text = page.evaluate(SHOWN_BANNER)
        return text if text and words in text else None

    return wait_for(said, timeout, interval=0.05,
                    what=lambda: "the banner to say %r; it says %r" % (words, page.evaluate(SHOWN_BANNER)))


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
        def listening_url() -> str | None:
            self._log.seek(0)
            found = re.search(r"WebDriver BiDi listening on (ws://\S+)", self._log.read())
            if found:
                return found.group(1)
            if self.proc.poll() is not None:
                raise ChildProcessError("Firefox exited")
            return None

        try:
            return wait_for(listening_url, timeout, interval=0.1, what="Firefox to start WebDriver BiDi")
        except (ChildProcessError, TimeoutError) as gave_up:
            self.close()
            raise RuntimeError("Firefox did not start WebDriver BiDi") from gave_up

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
        """The truthy value of a JavaScript expression, once it has one."""
        return wait_for(lambda: self.evaluate(expression), timeout, interval=0.1,
                        what="true in Firefox: " + expression)

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
