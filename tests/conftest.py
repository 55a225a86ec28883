"""The suite's layers and shared fixtures.

Each folder is a layer, registered as a marker of the same name (``pytest -m unit``):

* ``unit/``: no server, no browser, no network: the runtime, the logs, the formats, the simulator
  (``make test-fast``);
* ``server/``: a real uvicorn, real websockets, the commands run as processes;
* ``fleet/``: real Zenoh sessions on the loopback;
* ``browser/``: real Chromium (and Firefox) against real servers;
* ``demo/``: the real ``fsmscope demo`` (MuJoCo, viser): a recorded episode, and one live process
  shared by its tests (demo/conftest.py);
* ``parity/``: fsm and the original SMACH run side by side;
* ``ros1/``: a real ROS 1 (Debian's rosmaster, rospy and rostopic) and a robot on the original SMACH
  with smach_ros, watched by fsmscope (tests/ros1_support.py);
* ``ros2/``: robot processes publishing as a ROS 2 node's rmw does, over Cyclone DDS on the loopback
  (each test on a domain id of its own), watched by fsmscope.ros2.

Shared fixtures: captured log lines, the runtime's globals restored after every test, a live server,
a private bus and its action servers, Debian's Chromium, and one recorded demo episode."""

import itertools
import os
import shutil
from pathlib import Path

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
    from fsmscope.server.http_server import ServerThread

    srv = ServerThread().start()
    try:
        yield srv
    finally:
        srv.stop()


# Each origin in a renderer process of its own. Chromium keeps a same-site iframe, such as the 3D view
# (viser, on another port of 127.0.0.1), in its page's process; with no GPU, three.js compiling its
# shaders in software then holds that process's main thread, the dashboard's too, for 6 to 9 s after
# every page load, and each test of a page with a 3D view waited that out. Origin isolation changes
# nothing a page does or shows (the iframe was cross-origin already), only which process runs it.
TEST_CHROMIUM_ARGS = ["--enable-features=StrictOriginIsolation"]


@pytest.fixture(scope="session")
def chromium():
    """Debian's Chromium, one process for the session (see ``browser``); skips when it, Playwright or
    Graphviz (the server draws the graph with dot) is missing. Playwright is imported here, not at
    collection."""
    from fsmscope.server.testing.browser import CHROMIUM, CHROMIUM_ARGS

    playwright_api = pytest.importorskip("playwright.sync_api")
    if not os.path.exists(CHROMIUM):
        pytest.skip("Debian's chromium is not installed (make apt)")
    if not shutil.which("dot"):
        pytest.skip("Graphviz's dot is not installed (make apt)")
    with playwright_api.sync_playwright() as pw:
        # server.testing.browser.launch_chromium, with TEST_CHROMIUM_ARGS (bench/ measures without them).
        launched = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS + TEST_CHROMIUM_ARGS, headless=True)
        yield launched
        launched.close()


@pytest.fixture(scope="module")
def browser(chromium):
    """Debian's Chromium for the tests of one module: every page it opens has a context of its own,
    and whatever the module left open is closed at its end (one launch serves the whole session)."""
    yield chromium
    for context in chromium.contexts:
        context.close()


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


@pytest.fixture(scope="session")
def headless_demo_log(tmp_path_factory):
    """The log of one real-time episode of ``fsmscope demo --headless --episodes 1``, the arm's pose
    recorded with it; recorded once for the whole run (none may write it): xdist's workers share the
    run's temporary directory, and the first to need the log records it under a lock the others wait on."""
    import fcntl
    import subprocess
    import sys

    shared = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        shared = shared.parent  # the run's directory, above each worker's own
    path = shared / "headless-demo.jsonl"
    with open(shared / "headless-demo.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        recorded = shared / "headless-demo.recorded"  # touched once the log is whole: a failed one is recorded again
        if not recorded.exists():
            path.unlink(missing_ok=True)
            done = subprocess.run([sys.executable, "-m", "fsmscope", "demo", "--headless", "--episodes", "1",
                                   "--record", str(path)], cwd=TESTS.parent,
                                  capture_output=True, text=True, timeout=240)
            assert done.returncode == 0, done.stdout + done.stderr
            recorded.touch()
    return path


LAYERS = ("unit", "server", "fleet", "browser", "demo", "parity", "ros1", "ros2")
TESTS = Path(__file__).resolve().parent


def layer_of(item: pytest.Item) -> str | None:
    """The layer a test belongs to: the folder under tests/ it lives in."""
    folder = item.path.relative_to(TESTS).parts[0]
    return folder if folder in LAYERS else None


def pytest_itemcollected(item: pytest.Item) -> None:
    """Mark every test with its layer."""
    layer = layer_of(item)
    if layer is not None:
        item.add_marker(layer)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The demo's tests first (its real-time episodes are the longest chain), then the modules of the
    other layers in turns, the unit layer's last: under xdist (make test) a worker whose browser is
    busy runs beside one that waits on a robot's network, and the short unit tests fill the end.
    Within a layer, the modules with the most tests first (xdist's own measure of a module's length)."""
    modules: dict[str, list[pytest.Item]] = {}
    for item in items:
        modules.setdefault(str(item.path), []).append(item)
    layers: dict[str | None, list[list[pytest.Item]]] = {}
    for tests in sorted(modules.values(), key=len, reverse=True):
        layers.setdefault(layer_of(tests[0]), []).append(tests)
    in_turns = itertools.zip_longest(*(layers.pop(layer, [])
                                       for layer in ("browser", "fleet", "server", "parity", "ros1")))
    ordered = layers.pop("demo", []) + [tests for turn in in_turns for tests in turn if tests]
    ordered += [tests for rest in layers.values() for tests in rest]  # the unit layer
    items[:] = [item for tests in ordered for item in tests]


def pytest_xdist_make_scheduler(config: pytest.Config, log):
    """xdist (make test) sends each worker a whole module at a time (its module-scoped servers and
    pages start once), and the whole demo layer to one worker (one demo process), in the order above."""
    from xdist.scheduler import LoadScopeScheduling

    class ModulesAndTheDemo(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            module = nodeid.split("::", 1)[0]
            return "tests/demo" if module.startswith("tests/demo/") else module

    config.option.loadscopereorder = False  # keep the order above, not the biggest module first
    return ModulesAndTheDemo(config, log)


@pytest.fixture(autouse=True)
def _machine_lines_kept_with_the_test(request):
    """In the layers that serve machines, they run in threads of their own (a server's, a robot's), and a line
    they print while pytest switches between a test's phases (its capture off for an instant) landed
    among the dots. Their lines are kept with the test instead, and shown when it fails."""
    if layer_of(request.node) not in ("server", "fleet", "browser", "demo"):
        yield
        return
    lines: list[str] = []
    fsm.set_loggers(*[(lambda msg, prefix=prefix: lines.append(prefix + str(msg)))
                      for prefix in ("[  INFO ] : ", "[  WARN ] : ", "[ DEBUG ] : ", "[ ERROR ] : ")])
    yield
    if lines:
        request.node.add_report_section("call", "fsm log", "\n".join(lines))
