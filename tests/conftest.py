"""Shared fixtures: captured log lines, the runtime's globals restored after every test, a live
server, a private bus and its action servers, and Debian's Chromium for the browser tests."""

import os
import shutil

import fsm
import fsm.core.log
import pytest
from fsm.core.container import Container
from fsm.ros.actionlib import SimpleActionServer
from fsm.ros.bus import Bus


class Logs:
    """Log lines passed to the four printers, per level and in one ordered list."""

    def __init__(self) -> None:
        self.info: list[str] = []
        self.warn: list[str] = []
        self.debug: list[str] = []
        self.error: list[str] = []
        self.all: list[tuple[str, str]] = []

    def _printer(self, level: str):
        lines = getattr(self, level)

        def printer(msg: object) -> None:
            lines.append(str(msg))
            self.all.append((level, str(msg)))
        return printer

    def install(self) -> None:
        fsm.set_loggers(self._printer("info"), self._printer("warn"), self._printer("debug"), self._printer("error"))


# The runtime's own defaults, taken before any test or fixture changed them: a module-scoped
# fixture that silences the loggers must not leave them silenced for the modules after it.
_DEFAULT_PRINTERS = dict(fsm.core.log._printers)
_DEFAULT_SHUTDOWN_CHECK = fsm.core.log._shutdown_check


@pytest.fixture(autouse=True)
def _restore_runtime_globals():
    """Put back the default printers and shutdown check, and fail a test that leaves a container open."""
    yield
    fsm.core.log._printers.clear()
    fsm.core.log._printers.update(_DEFAULT_PRINTERS)
    fsm.core.log._shutdown_check = _DEFAULT_SHUTDOWN_CHECK
    left_open = list(Container._construction_stack)
    Container._construction_stack.clear()
    assert not left_open, "a test left containers open: %r" % left_open


@pytest.fixture
def logs() -> Logs:
    """Capture every log line into lists (restored to the default printers afterwards)."""
    captured = Logs()
    captured.install()
    return captured


@pytest.fixture
def live_server():
    """A real uvicorn serving a fresh Hub on a free port of 127.0.0.1, in a background thread.

    Yields the ServerThread: ``.hub``, ``.base_url`` (http://127.0.0.1:PORT), ``.port``, ``.token``.
    """
    from server.http_server import ServerThread

    srv = ServerThread().start()
    try:
        yield srv
    finally:
        srv.stop()


@pytest.fixture(scope="module")
def browser():
    """Debian's Chromium, shared by the tests of one module; skips when it, Playwright or Graphviz
    (the server draws the graph with dot) is missing. Playwright is imported here, not at collection."""
    from server.testing.browser import CHROMIUM, launch_chromium

    playwright_api = pytest.importorskip("playwright.sync_api")
    if not os.path.exists(CHROMIUM):
        pytest.skip("Debian's chromium is not installed (make apt)")
    if not shutil.which("dot"):
        pytest.skip("Graphviz's dot is not installed (make apt)")
    with playwright_api.sync_playwright() as pw:
        chromium = launch_chromium(pw)
        yield chromium
        chromium.close()


@pytest.fixture
def bus() -> Bus:
    """A private bus, so tests never see each other's topics, services or servers."""
    return Bus()


@pytest.fixture
def servers():
    """Action servers made by a test (through ``serve``), shut down after it."""
    made: list[SimpleActionServer] = []
    yield made
    for server in made:
        server.shutdown(timeout=1.0)
