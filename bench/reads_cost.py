"""What reads cost a machine (issue 32, item 9): the events/s of a fast machine under ``fsmscope run`` alone,
and while clients read it as fast as they can. Target: the machine keeps >= 90 % of its events/s with one
client asking GET .../summary back to back, and with one client asking every expensive read back to back.

The machine is the two-state loop of the other benchmarks (bench/replay.py's, with nothing to do in a
state), run by ``fsmscope run --exit --record LOG`` in its own process (a real server, a real recording).
In rounds, each a window of ``--seconds``: no client; as a control, a process burning a core (what any
busy process costs the machine on these cores); one client asking ``GET .../summary`` back to back (the
probe's "one viewer"); one client asking each expensive read in turn back to back (summary, the status
at a random seq, a page of history, the timeline, the graph, the machines' list, the structure); and
six clients seeking at once (each the status at a random seq, the history around it and the timeline,
back to back). A client is a process of its own: one keep-alive connection, which asks again as soon as
it is answered, whatever the answer (a 429 too: it does not wait the Retry-After it is told, as a script
that ignores it would not). The rates are counted afterwards in the recording, over each window; medians
of the rounds. Each row also says the CPU of the machine's thread and of the server's (the process's
other threads: what the reads cost, wherever the cores are shared), in % of a core, and the process's
RSS (read before the first window and at the end of each). This 2-core computer is shared: the control
row says what any busy process costs the machine here.

    .venv/bin/python bench/reads_cost.py [--rounds 3] [--seconds 5]
"""

import argparse
import json
import multiprocessing as mp
import os
import random
import re
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable

# The repository first: run as a script, this folder comes first and its server.py would shadow the package.
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from live_rewind import thread_cpu  # noqa: E402  (the CPU of the machine's thread)
from demo_cpu import cpu_seconds  # noqa: E402  (of the whole process)
from table import print_table, verdict  # noqa: E402
from timetravel_browser import served  # noqa: E402  (``fsmscope ...`` in its own process, its address)

WARM_UP = 2.0  # s after the machine starts, and after clients start
TARGET = 0.90  # of the machine's events/s alone, kept with one client reading back to back
SEEKERS = 6
SCRIPT = '''"""Two states that do nothing, back and forth, until the file argv[1] exists (looked at every 1,000 steps)."""
import os
import sys

import fsm

STOP = sys.argv[1]
fsm.set_loggers(*[lambda message: None] * 4)  # no line printed per transition
steps = [0]


def flip(ud):
    steps[0] += 1
    return "stop" if steps[0] % 1000 == 0 and os.path.exists(STOP) else "go"


sm = fsm.StateMachine(outcomes=["done"])
with sm:
    fsm.StateMachine.add("A", fsm.CBState(flip, outcomes=["go", "stop"]), {"go": "B", "stop": "done"})
    fsm.StateMachine.add("B", fsm.CBState(flip, outcomes=["go", "stop"]), {"go": "A", "stop": "done"})
sm.execute()
'''


# The clients (each in a process of its own).

def _summary(http, machine: str, span: Callable[[], tuple[int, int]], rng: random.Random) -> list:
    return [("GET", "/api/machines/%s/summary" % machine, {})]


def _every_read(http, machine: str, span: Callable[[], tuple[int, int]], rng: random.Random) -> list:
    first, last = span()
    base = "/api/machines/%s" % machine
    return [("GET", base + "/summary", {}), ("GET", base + "/status", {"seq": rng.randint(first, last)}),
            ("GET", base + "/history", {"since": rng.randint(first, last), "limit": 1000}),
            ("GET", base + "/timeline", {}), ("GET", base + "/graph.svg", {}), ("GET", "/api/machines", {}),
            ("GET", base + "/structure", {})]


def _seek(http, machine: str, span: Callable[[], tuple[int, int]], rng: random.Random) -> list:
    first, last = span()
    seq = rng.randint(first, last)
    base = "/api/machines/%s" % machine
    return [("GET", base + "/status", {"seq": seq}),
            ("GET", base + "/history", {"since": max(first, seq - 50), "until": seq + 50, "limit": 101}),
            ("GET", base + "/timeline", {})]


CLIENTS = {"summary": _summary, "every": _every_read, "seek": _seek}


def _client(url: str, token: str, machine: str, kind: str, seed: int, stop, out) -> None:
    """Ask back to back until ``stop`` is set; put (latencies of the answers, count of each status) in ``out``."""
    import httpx

    rng = random.Random(seed)
    latencies, statuses = [], {}
    with httpx.Client(base_url=url, headers={"Authorization": "Bearer " + token}, timeout=30) as http:
        def span() -> tuple[int, int]:
            answer = http.get("/api/machines/%s/history" % machine, params={"limit": 1, "order": "desc"})
            last = answer.json()["last_seq"] if answer.status_code == 200 else 1
            return max(1, last - 15_000), max(1, last)
        while not stop.is_set():
            for method, path, params in CLIENTS[kind](http, machine, span, rng):
                start = time.perf_counter()
                answer = http.request(method, path, params=params)
                latencies.append(time.perf_counter() - start)
                statuses[answer.status_code] = statuses.get(answer.status_code, 0) + 1
    out.put((latencies, statuses))


def _burn(stop) -> None:
    while not stop.is_set():
        sum(range(10_000))


class Clients:
    """``n`` client processes of ``kind`` (or a burner), started on entering, stopped and collected on leaving."""

    def __init__(self, url: str, token: str, machine: str, kind: str, n: int) -> None:
        ctx = mp.get_context("spawn")
        self.stop, self.out = ctx.Event(), ctx.Queue()
        target = (lambda i: (_burn, (self.stop,))) if kind == "burn" else \
            (lambda i: (_client, (url, token, machine, kind, i, self.stop, self.out)))
        self.procs = [ctx.Process(target=target(i)[0], args=target(i)[1], daemon=True) for i in range(n)]
        self.kind = kind
        self.latencies: list[float] = []
        self.statuses: dict[int, int] = {}

    def __enter__(self) -> "Clients":
        for proc in self.procs:
            proc.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop.set()
        if self.kind != "burn":
            for _ in self.procs:
                latencies, statuses = self.out.get(timeout=120)
                self.latencies += latencies
                for code, count in statuses.items():
                    self.statuses[code] = self.statuses.get(code, 0) + count
        for proc in self.procs:
            proc.join(30)


# The windows.

def rss_mb(pid: int) -> float:
    for line in Path("/proc/%d/status" % pid).read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return 0.0


class Window:
    """One measured stretch under ``condition``: its wall-clock times, then (``count``) the machine's rate."""

    def __init__(self, condition: str, pid: int, seconds: float, clients: Clients | None) -> None:
        self.condition = condition
        self.clients = clients
        if clients is not None:
            clients.__enter__()
            time.sleep(WARM_UP)
        machine, process, self.t0 = thread_cpu(pid), cpu_seconds(pid), time.time()
        time.sleep(seconds)
        self.t1 = time.time()
        self.machine_cpu = (thread_cpu(pid) - machine) / (self.t1 - self.t0)
        self.server_cpu = (cpu_seconds(pid) - process) / (self.t1 - self.t0) - self.machine_cpu
        self.rss = rss_mb(pid)
        if clients is not None:
            clients.__exit__()
        self.rate = 0.0

    def count(self, times: list[float]) -> None:
        self.rate = sum(self.t0 <= t <= self.t1 for t in times) / (self.t1 - self.t0)


CONDITIONS = [("no client", None, 0), ("control: a process burning a core", "burn", 1),
              ("one client asking GET .../summary back to back", "summary", 1),
              ("one client asking every expensive read in turn, back to back", "every", 1),
              ("%d clients seeking (status at a seq, history around it, timeline), back to back" % SEEKERS,
               "seek", SEEKERS)]
TARGETED = {"summary", "every"}


def measure(rounds: int, seconds: float, tmp: str) -> tuple[list[Window], float]:
    script, log, stop = (os.path.join(tmp, name) for name in ("loop.py", "run.jsonl", "stop"))
    Path(script).write_text(SCRIPT)
    windows = []
    with served(["run", "--exit", "--record", log, script, stop], r"dashboard at (http://\S+)") as (url, proc):
        base, token = re.match(r"(http://[^/]+)/?\?token=(\S+)", url).groups()
        time.sleep(WARM_UP)
        rss_before = rss_mb(proc.pid)
        for _ in range(rounds):
            for condition, kind, n in CONDITIONS:
                clients = Clients(base, token, "loop", kind, n) if kind else None
                windows.append(Window(condition, proc.pid, seconds, clients))
        Path(stop).touch()
        proc.wait(60)
    with open(log) as recording:
        times = [json.loads(line)["t"] for line in recording]
    for w in windows:
        w.count(times)
    return windows, rss_before


def rows_of(windows: list[Window], rss_before: float) -> list[tuple[str, str, str, str]]:
    rows = []
    base = statistics.median(w.rate for w in windows if w.clients is None)
    for condition, kind, _ in CONDITIONS:
        mine = [w for w in windows if w.condition == condition]
        rate = statistics.median(w.rate for w in mine)
        detail = "; CPU %% of a core: machine %.0f, server %.1f; RSS %.0f MiB (%.0f before)" % (
            statistics.median(w.machine_cpu for w in mine) * 100, statistics.median(w.server_cpu for w in mine) * 100,
            max(w.rss for w in mine), rss_before)
        if kind not in (None, "burn"):
            latencies = sorted(x for w in mine for x in w.clients.latencies)
            statuses: dict[int, int] = {}
            for w in mine:
                for code, count in w.clients.statuses.items():
                    statuses[code] = statuses.get(code, 0) + count
            answered = sum(statuses.values()) / sum(w.t1 - w.t0 + WARM_UP for w in mine)
            detail += "; %.0f answers/s (%s), p99 %.0f ms" % (
                answered, ", ".join("%d: %d" % item for item in sorted(statuses.items())),
                latencies[int(0.99 * (len(latencies) - 1))] * 1000)
        targeted = kind in TARGETED
        rows.append(("%s%s" % (condition, detail), ">= %d %%" % (TARGET * 100) if targeted else "",
                     "%.0f/s (%.0f %%)" % (rate, rate / base * 100), verdict(rate >= TARGET * base) if targeted else ""))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=5.0, help="each window")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="fsmscope-bench-") as tmp:
        windows, rss_before = measure(args.rounds, args.seconds, tmp)
    print_table("fsmscope reads: events/s of a two-state loop under `fsmscope run` while clients read it, "
                "medians of %d rounds of %g s" % (args.rounds, args.seconds), rows_of(windows, rss_before))


if __name__ == "__main__":
    main()
