"""A page of Playwright's Chromium that Playwright does not follow, for timing what a user's browser
does. Playwright enables the DevTools Network domain on every page it knows, so Chromium reports
each websocket frame the page receives (its payload too) to Playwright's driver: a page streaming
2,000 events a second spent most of its time on that, and measured an event-to-page p99 of 220 ms
where the same page, unfollowed, measured 19 ms. A page of a browser context made over DevTools
(not by Playwright) is left alone; it is driven over Target.sendMessageToTarget with the Runtime,
Page (navigation, init scripts), Input (mouse, keys) and Emulation (viewport, focus) domains, never
Network."""

from __future__ import annotations

import itertools
import json
import time
from typing import Any


# The page's uncaught errors, kept for ``errors`` (Playwright's "pageerror" would need Runtime.enable,
# which reports every console message to the driver too).
CATCH_ERRORS = """window.__quietErrors = [];
addEventListener("error", (e) => window.__quietErrors.push(String(e.error || e.message)));
addEventListener("unhandledrejection", (e) => window.__quietErrors.push(String(e.reason)));"""
# Keys ``press`` knows, as Playwright's keyboard sends them (fsmscope/static/*.js read e.key).
KEYS = {"Space": {"key": " ", "code": "Space", "windowsVirtualKeyCode": 32, "text": " "}}


class QuietPage:
    """``url`` (or a blank page, to add init scripts before ``goto``) in a browser context of its own,
    ``width`` x ``height``."""

    def __init__(self, browser: Any, url: str | None = None, width: int = 1280, height: int = 800) -> None:
        self._cdp = browser.new_browser_cdp_session()
        self._replies: dict[int, dict] = {}
        self._ids = itertools.count(1)
        self._cdp.on("Target.receivedMessageFromTarget", self._received)
        self._context = self._cdp.send("Target.createBrowserContext")["browserContextId"]
        self._target = self._cdp.send("Target.createTarget", {"url": "about:blank", "browserContextId": self._context})[
            "targetId"]
        self._session = self._cdp.send("Target.attachToTarget", {"targetId": self._target, "flatten": False})[
            "sessionId"]
        self._call("Emulation.setDeviceMetricsOverride",
                   {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False})
        self._call("Emulation.setFocusEmulationEnabled", {"enabled": True})  # focused, as Playwright's pages are
        self._call("Page.enable", {})  # or init scripts are not run; it reports a few events a navigation
        self.add_init_script(CATCH_ERRORS)
        self._pointer, self._held = (0.0, 0.0), False  # the mouse: where it is, its left button down
        if url is not None:
            self.goto(url)

    def _received(self, event: dict) -> None:
        message = json.loads(event["message"])
        if "id" in message:
            self._replies[message["id"]] = message

    def _call(self, method: str, params: dict, timeout: float = 30.0) -> dict:
        call = next(self._ids)
        self._cdp.send("Target.sendMessageToTarget", {"sessionId": self._session, "message": json.dumps(
            {"id": call, "method": method, "params": params})})
        end, pause = time.monotonic() + timeout, 0.001
        while call not in self._replies:  # Playwright's sync API hands events over while it is called
            if time.monotonic() > end:
                raise TimeoutError("%s got no answer in %g s" % (method, timeout))
            time.sleep(pause)
            pause = min(2 * pause, 0.01)  # an input event's answer comes in ~1 ms, a page's script may take long
            self._cdp.send("Browser.getVersion")
        reply = self._replies.pop(call)
        if "error" in reply:
            raise RuntimeError("%s: %s" % (method, reply["error"]))
        return reply["result"]

    def evaluate(self, function: str, arg: Any = None) -> Any:
        """``function(arg)`` in the page (awaited when it returns a promise); its JSON value."""
        result = self._call("Runtime.evaluate", {"expression": "(%s)(%s)" % (function, json.dumps(arg)),
                                                 "awaitPromise": True, "returnByValue": True})
        if "exceptionDetails" in result:
            raise RuntimeError(result["exceptionDetails"].get("exception", {}).get("description")
                               or result["exceptionDetails"]["text"])
        return result["result"].get("value")

    def wait_for(self, function: str, arg: Any = None, timeout: float = 60.0) -> None:
        """Until ``function(arg)`` is true in the page (one that throws, or a page still loading: not yet)."""
        end = time.monotonic() + timeout
        while not self._true(function, arg):
            if time.monotonic() > end:
                raise TimeoutError("%s was not true in %g s" % (function, timeout))
            time.sleep(0.1)

    def _true(self, function: str, arg: Any) -> bool:
        try:
            return bool(self.evaluate(function, arg))
        except RuntimeError:
            return False

    def add_init_script(self, script: str) -> None:
        """``script`` run in every document this page loads from now on, before the document's own."""
        self._call("Page.addScriptToEvaluateOnNewDocument", {"source": script})

    def goto(self, url: str, timeout: float = 60.0) -> None:
        """Load ``url``; returns once the new document's readyState is "complete"."""
        self.evaluate("() => { window.__quietLeft = true; }")  # marks the document being left
        navigated = self._call("Page.navigate", {"url": url})
        if navigated.get("errorText"):
            raise RuntimeError("%s: %s" % (url, navigated["errorText"]))
        if "loaderId" not in navigated:  # a navigation within the document (another #hash)
            self.evaluate("() => { delete window.__quietLeft; }")
        self.wait_for("() => !window.__quietLeft && document.readyState === 'complete'", timeout=timeout)

    def wait_for_selector(self, selector: str, timeout: float = 60.0) -> None:
        """Until an element matching ``selector`` is shown (has a box, is not visibility: hidden), as Playwright's."""
        self.wait_for("(s) => { const e = document.querySelector(s); return e !== null && e.getClientRects().length > 0"
                      " && getComputedStyle(e).visibility !== 'hidden'; }", selector, timeout)

    def bounding_box(self, selector: str) -> dict | None:
        """The first element matching ``selector``: its x, y, width and height in the viewport, or None."""
        return self.evaluate("(s) => { const e = document.querySelector(s); if (!e) return null;"
                             " const r = e.getBoundingClientRect(); return {x: r.x, y: r.y, width: r.width,"
                             " height: r.height}; }", selector)

    @property
    def errors(self) -> list[str]:
        """The uncaught errors (and unhandled rejections) of the document shown."""
        return self.evaluate("() => window.__quietErrors || []")

    def select_option(self, selector: str, value: str) -> None:
        """The select's option ``value`` chosen, with the input and change events Playwright's sends."""
        self.evaluate("([s, v]) => { const e = document.querySelector(s); e.value = v;"
                      " for (const t of ['input', 'change']) e.dispatchEvent(new Event(t, {bubbles: true})); }",
                      [selector, value])

    def check(self, selector: str) -> None:
        """A checkbox checked by a click at its middle, if it is not already (as Playwright's)."""
        if not self.evaluate("(s) => document.querySelector(s).checked", selector):
            box = self.bounding_box(selector)
            self.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
            self.wait_for("(s) => document.querySelector(s).checked", selector, timeout=5.0)

    # The mouse and keys are dispatched as input (the page gets trusted pointer and key events) with
    # the parameters Playwright's page.mouse and page.keyboard send.
    def _mouse(self, kind: str) -> None:
        x, y = self._pointer
        self._call("Input.dispatchMouseEvent", {
            "type": kind, "x": x, "y": y, "buttons": int(self._held), "clickCount": 0 if kind == "mouseMoved" else 1,
            "button": "left" if self._held or kind == "mouseReleased" else "none"})

    def mouse_move(self, x: float, y: float, steps: int = 1) -> None:
        """``steps`` moves along the line from the last position to (x, y), the button held or not."""
        x0, y0 = self._pointer
        for i in range(1, steps + 1):
            self._pointer = (x0 + (x - x0) * i / steps, y0 + (y - y0) * i / steps)
            self._mouse("mouseMoved")

    def mouse_down(self) -> None:
        self._held = True
        self._mouse("mousePressed")

    def mouse_up(self) -> None:
        self._held = False
        self._mouse("mouseReleased")

    def click(self, x: float, y: float) -> None:
        """A left click at (x, y): a move there, a press and a release."""
        self.mouse_move(x, y)
        self.mouse_down()
        self.mouse_up()

    def press(self, key: str) -> None:
        """``key`` (a name of KEYS) pressed and released."""
        down = KEYS[key]
        up = {name: value for name, value in down.items() if name != "text"}
        self._call("Input.dispatchKeyEvent", {"type": "keyDown", "unmodifiedText": down["text"], **down})
        self._call("Input.dispatchKeyEvent", {"type": "keyUp", **up})

    def close(self) -> None:
        """The page and its browser context gone, and this DevTools session with them."""
        self._cdp.send("Target.closeTarget", {"targetId": self._target})
        self._cdp.send("Target.disposeBrowserContext", {"browserContextId": self._context})
        self._cdp.detach()
