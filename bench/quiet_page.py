"""A page of Playwright's Chromium that Playwright does not follow, for timing what a user's browser
does. Playwright enables the DevTools Network domain on every page it knows, so Chromium reports
each websocket frame the page receives (its payload too) to Playwright's driver: a page streaming
2,000 events a second spent most of its time on that, and measured an event-to-page p99 of 220 ms
where the same page, unfollowed, measured 19 ms. A page of a browser context made over DevTools
(not by Playwright) is left alone; its script is run over Target.sendMessageToTarget, Runtime only."""

from __future__ import annotations

import itertools
import json
import time
from typing import Any


class QuietPage:
    """``url`` in a browser context of its own, ``width`` x ``height``."""

    def __init__(self, browser: Any, url: str, width: int = 1280, height: int = 800) -> None:
        self._cdp = browser.new_browser_cdp_session()
        self._replies: dict[int, dict] = {}
        self._ids = itertools.count(1)
        self._cdp.on("Target.receivedMessageFromTarget", self._received)
        context = self._cdp.send("Target.createBrowserContext")["browserContextId"]
        self._target = self._cdp.send("Target.createTarget", {"url": "about:blank", "browserContextId": context})[
            "targetId"]
        self._session = self._cdp.send("Target.attachToTarget", {"targetId": self._target, "flatten": False})[
            "sessionId"]
        self._call("Emulation.setDeviceMetricsOverride",
                   {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False})
        self._call("Page.navigate", {"url": url})

    def _received(self, event: dict) -> None:
        message = json.loads(event["message"])
        if "id" in message:
            self._replies[message["id"]] = message

    def _call(self, method: str, params: dict, timeout: float = 30.0) -> dict:
        call = next(self._ids)
        self._cdp.send("Target.sendMessageToTarget", {"sessionId": self._session, "message": json.dumps(
            {"id": call, "method": method, "params": params})})
        end = time.monotonic() + timeout
        while call not in self._replies:  # Playwright's sync API hands events over while it is called
            if time.monotonic() > end:
                raise TimeoutError("%s got no answer in %g s" % (method, timeout))
            time.sleep(0.01)
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

    def close(self) -> None:
        self._cdp.send("Target.closeTarget", {"targetId": self._target})
