"""The one real ``fsmscope demo`` the demo's tests share (SharedDemo, started by tests/demo/conftest.py),
a page watching it, an operator's client of it, and its episodes' timing."""

from __future__ import annotations

import contextlib
import time
from pathlib import Path

import httpx
from browser_support import page_at
from fsmscope.server.testing.demo_process import DemoProcess
from fsmscope.server.testing.polling import wait_for

DEMO_MACHINE = "pick_place"
FRESH_EPISODE = 1.5  # s: an episode (about 6 s at real time) begun this recently has seconds of it ahead


class SharedDemo:
    """One real ``fsmscope demo`` (real time, its default deadman) for the demo's tests of several
    modules: started when a test first needs it (``process()``), stopped by tests/demo/conftest.py after
    the folder's last test (``stop()``). Whoever uses it leaves it as it was found:
    ``let_go()`` after every test (no breakpoint, nothing held, no lease, the loop running)."""

    PAGE = "tests-let-go"  # the page id of the requests that let the machine go

    def __init__(self, directory: Path) -> None:
        self.directory = directory
        self.demo: DemoProcess | None = None
        self.started = 0

    def process(self) -> DemoProcess:
        """The demo, started if it is not running; a demo that died is an error, never restarted quietly."""
        if self.demo is None:
            self.started += 1
            self.demo = DemoProcess(self.directory / ("demo-%d.jsonl" % self.started))
        elif self.demo.proc.poll() is not None:
            raise RuntimeError("the shared demo exited with %s" % self.demo.proc.returncode)
        return self.demo

    def stop(self) -> int | None:
        """Stop the demo as Ctrl-C does; its exit code (130: interrupted cleanly), None when none ran."""
        demo, self.demo = self.demo, None
        return None if demo is None else demo.stop()

    def let_go(self, timeout: float = 30.0) -> None:
        """Leave the demo as a fresh one is: no breakpoint, no hold, no lease (a lease left held would
        make the deadman pause the machine for the next test), the episode loop running."""
        if self.demo is None:
            return
        http = demo_client(self.demo, page=self.PAGE)
        base = "/api/machines/" + DEMO_MACHINE
        assert http.post(base + "/lease", json={"takeover": True}).status_code == 200
        assert http.put(base + "/breakpoints", json={"breakpoints": []}).status_code == 200
        assert http.post(base + "/resume").status_code == 202
        assert http.delete(base + "/lease").status_code == 200

        def running_free() -> bool:
            machine = demo_machine(http)
            if machine["running"]:
                return not machine["held"]  # held: it stops after this episode; started again below
            if machine["held"] or machine["outcome"] == "preempted":  # the loop waits for Start
                http.post(base + "/start")
                http.delete(base + "/lease")  # a start takes a free lease
            return False

        wait_for(running_free, timeout, interval=0.1, what="the shared demo to run its episodes again")
        http.close()


@contextlib.contextmanager
def watching_demo(browser, shared_demo: SharedDemo, scene: bool = False):
    """A page watching the shared demo at 1600 x 900, its stream live, the 3D view beside the graph
    drawn only when ``scene`` (open_page says why not by default); at the end the demo is let go first
    (a page closed holding the lease would leave the deadman to pause the machine for the next test),
    then the page, which must have had no script error, closed."""
    with page_at(browser, shared_demo.process().url, "#badge.live", 1600, 900, scene) as page:
        try:
            yield page
        finally:
            shared_demo.let_go()


def demo_client(demo: DemoProcess, page: str | None = None) -> httpx.Client:
    """An operator's client of ``demo`` (sending ``page`` as its page id, when given)."""
    headers = {"Authorization": "Bearer " + demo.token}
    if page is not None:
        headers["X-Fsmscope-Page"] = page
    return httpx.Client(base_url="http://127.0.0.1:%d" % demo.port, headers=headers, timeout=10)


def demo_machine(http: httpx.Client) -> dict:
    """The demo's machine as GET /api/machines lists it."""
    return {m["name"]: m for m in http.get("/api/machines").json()}[DEMO_MACHINE]


def episode_age(demo: DemoProcess) -> float | None:
    """Seconds since the demo's running episode began (its first event); None between two episodes."""
    with demo_client(demo) as http:
        status = http.get("/api/machines/%s/status" % DEMO_MACHINE).json()
        if not status["running"]:
            return None
        began = http.get("/api/machines/%s/status" % DEMO_MACHINE, params={"seq": status["run_seq"]}).json()
        return time.time() - began["last_t"]


def wait_for_a_fresh_episode(demo: DemoProcess, timeout: float = 30.0) -> None:
    """Until the demo runs an episode begun less than FRESH_EPISODE s ago: seconds of it ahead, for a
    control to land in."""
    def fresh() -> bool:
        age = episode_age(demo)
        return age is not None and age <= FRESH_EPISODE

    wait_for(fresh, timeout, interval=0.1, what="the demo to begin an episode")
