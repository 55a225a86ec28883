"""One dashboard following a fleet (issue 13): 20 machines in 5 robot processes, each machine at 100
events/s, published on Zenoh (loopback, explicit tcp endpoints, no multicast) into one real
``fsmscope serve --zenoh`` process, watched by real Chromium. Two views: an operator's (the fleet
overview open, and the dashboard page of one machine, whose events are timed), then the heaviest
(the streams of all 20 machines into one page, every event timed). The pages are ones Playwright
does not follow (bench/quiet_page.py): it would have Chromium report it every websocket frame.

Measured in the page: event-to-browser latency, from the event's ``t`` (the robot's clock, when the
machine emitted it) to its arrival in the page (``Date.now()``, the same host's clock). Measured on
the dashboard process: its CPU time (user + system, all threads, /proc) over the window, as a share
of one core. Targets: p99 <= 20 ms; <= 25 % of one core. Medians of several windows. Last, the
same 20 streams read by websocket clients of this process with the browser closed: what the
dashboard does when Chromium is not also on the machine's cores.

    .venv/bin/python bench/fleet_dashboard.py [--windows 3] [--seconds 10]
    .venv/bin/python bench/fleet_dashboard.py --robot r1 --connect tcp/127.0.0.1:PORT  (one robot: used by the bench)
"""

import argparse
import json
import os
import re
import signal
import statistics
import subprocess
import sys
import threading
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, ROOT)

from fsmscope.server.testing.demo_process import free_endpoint  # noqa: E402
from quiet_page import QuietPage  # noqa: E402
from table import print_table, verdict  # noqa: E402

ROBOTS = 5
MACHINES = 4  # per robot
RATE = 100  # events/s per machine
TICKS = os.sysconf("SC_CLK_TCK")

# In the page: one stream per machine; each event's delay from its t to its arrival.
PAGE_STREAMS = """
(names) => {
  const token = sessionStorage.getItem("fsmscope.token");
  window.benchLatencies = [];
  window.benchSince = performance.now();
  for (const name of names) {
    const ws = new WebSocket(`ws://${location.host}/api/machines/${encodeURIComponent(name)}/stream`,
                             ["fsmscope", "fsmscope.token." + token]);
    ws.onmessage = (message) => {
      const now = Date.now();
      const frame = JSON.parse(message.data);
      if (frame.type !== "events") return;
      for (const event of frame.events) {
        window.benchLatencies.push(now - event.t * 1000);
      }
    };
  }
}
"""
PAGE_WINDOW = """
() => {
  const all = window.benchLatencies.slice().sort((a, b) => a - b);
  const seconds = (performance.now() - window.benchSince) / 1000;
  window.benchLatencies = [];
  window.benchSince = performance.now();
  const at = (q) => all[Math.min(all.length - 1, Math.floor(q * all.length))];
  return { rate: all.length / seconds, p50: at(0.5), p99: at(0.99), max: all[all.length - 1] };
}
"""


def robot(name: str, connect: str) -> None:
    """A robot process: ``MACHINES`` machines, each A -> B -> A ... one transition every 1/RATE s."""
    import fsm
    from fsmscope.fleet.robot import ZenohRobot

    fsm.set_loggers(*[lambda msg: None] * 4)
    published = ZenohRobot(name, connect=[connect], token="bench")
    period = 1.0 / RATE

    class Tick(fsm.State):
        def __init__(self, clock: list[float]) -> None:
            fsm.State.__init__(self, ["go"])
            self.clock = clock  # the machine's next tick, shared by its two states

        def execute(self, ud):
            clock = self.clock
            clock[0] = max(clock[0] + period, time.monotonic())  # late: no burst to catch up
            pause = clock[0] - time.monotonic()
            if pause > 0:
                time.sleep(pause)
            return "go"

    def run(index: int) -> None:
        sm = fsm.StateMachine(["done"])
        clock = [time.monotonic()]
        with sm:
            fsm.StateMachine.add("A", Tick(clock), {"go": "B"})
            fsm.StateMachine.add("B", Tick(clock), {"go": "A"})
        fsm.attach(sm, published, name="m%d" % index)
        sm.execute()

    for index in range(MACHINES):
        threading.Thread(target=run, args=(index,), daemon=True).start()
    signal.sigwait([signal.SIGTERM, signal.SIGINT])


def cpu_seconds(pid: int) -> float:
    fields = open("/proc/%d/stat" % pid).read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS  # utime, stime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--windows", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--robot", help=argparse.SUPPRESS)
    parser.add_argument("--connect", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.robot:
        robot(args.robot, args.connect)
        return
    from playwright.sync_api import sync_playwright

    from fsmscope.server.testing.browser import launch_chromium

    endpoint = free_endpoint()
    env = dict(os.environ, PYTHONPATH=ROOT)
    dash = subprocess.Popen([sys.executable, "-m", "fsmscope", "serve", "--port", "0", "--zenoh", "--zenoh-listen",
                             endpoint, "--zenoh-token", "bench"], cwd=ROOT, stderr=subprocess.PIPE, text=True, env=env)
    robots: list[subprocess.Popen] = []
    try:
        for line in dash.stderr:
            found = re.search(r"the fleet overview at (http://\S+)", line)
            if found:
                break
        threading.Thread(target=dash.stderr.read, daemon=True).start()
        robots = [subprocess.Popen([sys.executable, __file__, "--robot", "r%d" % i, "--connect", endpoint], cwd=ROOT,
                                   env=env) for i in range(1, ROBOTS + 1)]
        names = ["r%d:m%d" % (r, m) for r in range(1, ROBOTS + 1) for m in range(MACHINES)]
        with sync_playwright() as pw:
            browser = launch_chromium(pw)
            page = QuietPage(browser, found.group(1))
            page.wait_for("(n) => window.fsmscopeFleet.tiles.filter((t) => t.state === 'running').length === n",
                          len(names))
            shown = QuietPage(browser, found.group(1).replace("/fleet?", "/?") + "#m=" + names[0])
            shown.wait_for("() => document.querySelector('#badge.live') !== null")
            shown.evaluate(PAGE_STREAMS, names[:1])  # timed in the machine's own page, busy drawing them
            operator = windows(shown, dash.pid, args)
            shown.close()
            page.evaluate(PAGE_STREAMS, names)
            heaviest = windows(page, dash.pid, args)
            browser.close()
        without = [clients(found.group(1), names, dash.pid, args.seconds) for _ in range(args.windows)]
    finally:
        for proc in [*robots, dash]:  # SIGTERM: a SIGINT is ignored by a process started in the background
            proc.terminate()
        for proc in [*robots, dash]:
            proc.wait(20)
    rows = []
    for view, measured, streams in (("fleet page + one machine's page", operator, 1),
                                    ("all 20 machines streamed to a page", heaviest, len(names)),
                                    ("all 20 streamed to Python clients, no browser", without, len(names))):
        median = lambda key: statistics.median(w[key] for w in measured)  # noqa: E731
        rows += [
            ("%s: events timed" % view, "%d/s" % (streams * RATE), "%.0f/s" % median("rate"), ""),
            ("%s: event-to-browser p50" % view, "", "%.1f ms" % median("p50"), ""),
            ("%s: event-to-browser p99" % view, "<= 20 ms", "%.1f ms" % median("p99"), verdict(median("p99") <= 20)),
            ("%s: event-to-browser max" % view, "", "%.1f ms" % median("max"), ""),
            ("%s: the dashboard process's CPU" % view, "<= 25 % of a core", "%.1f %%" % (100 * median("cpu")),
             verdict(median("cpu") <= 0.25)),
        ]
    print_table("One dashboard, %d machines in %d robot processes at %d events/s each (medians of %d windows of %g s)"
                % (len(names), ROBOTS, RATE, args.windows, args.seconds), rows)


def clients(fleet_url: str, names: list[str], pid: int, seconds: float) -> dict:
    """One window of the 20 streams read by websocket clients in this process (no browser on the
    machine's two cores): where the time goes when the browser is not there."""
    from websockets.sync.client import connect

    base, token = fleet_url.split("/fleet?token=")
    latencies: list[float] = []
    stop = time.time() + 2.0 + seconds

    def follow(name: str) -> None:
        url = "%s/api/machines/%s/stream?token=%s" % (base.replace("http", "ws", 1), name, token)
        with connect(url, open_timeout=10) as ws:
            while time.time() < stop:
                frame = json.loads(ws.recv(timeout=5))
                now = time.time()
                if frame["type"] == "events":
                    latencies.extend((now - event["t"]) * 1000 for event in frame["events"])

    readers = [threading.Thread(target=follow, args=(name,)) for name in names]
    for reader in readers:
        reader.start()
    time.sleep(2.0)  # the snapshots and the first events
    del latencies[:]
    cpu, start = cpu_seconds(pid), time.monotonic()
    for reader in readers:
        reader.join()
    elapsed = time.monotonic() - start
    share = (cpu_seconds(pid) - cpu) / elapsed
    ordered = sorted(latencies)
    at = lambda q: ordered[min(len(ordered) - 1, int(q * len(ordered)))]  # noqa: E731
    return {"rate": len(ordered) / elapsed, "p50": at(0.5), "p99": at(0.99), "max": ordered[-1], "cpu": share}


def windows(page: QuietPage, pid: int, args: argparse.Namespace) -> list[dict]:
    """``args.windows`` windows of ``args.seconds``: each the page's latencies and the dashboard's CPU share."""
    time.sleep(3.0)  # the new streams' snapshots and first events
    page.evaluate(PAGE_WINDOW)
    measured = []
    for _ in range(args.windows):
        cpu, start = cpu_seconds(pid), time.monotonic()
        time.sleep(args.seconds)
        share = (cpu_seconds(pid) - cpu) / (time.monotonic() - start)
        measured.append(dict(page.evaluate(PAGE_WINDOW), cpu=share))
    return measured


if __name__ == "__main__":
    main()
