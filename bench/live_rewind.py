"""Live rewind (issue 9): does a page looking back slow the live machine down? Target: while one page looks
back on a live machine at 1,000 events/s, its transition rate drops <= 5 %.

Two machines, each a two-state loop at about 1,000 transitions (= events) a second, measured in turn:
one whose states *wait* about 1 ms (as a robot's states wait on hardware, a timer or an action server),
and one whose states *compute* about 1 ms (a Python loop of a fixed length, no sleeping), so that any CPU
or GIL taken from it shows as a lower rate: the strictest case, not a robot's usual one. Each runs under
``fsmscope run`` (a real server, a real recording, the history beyond the ring read from it), in its own
process. In rounds, each a window of ``--seconds``: no page; one Chromium page showing the machine live;
one page looking back (a click on the timeline's axis into the past, then playing from there at 1x,
again every second); and, as a control, the same page looking back at another run, served by another
process (``fsmscope replay --serve``), which nothing links to the machine but the computer's cores. The
rates are counted afterwards in the recording, over each window; medians of the rounds. The pages are
ones Playwright does not follow (bench/quiet_page.py): it would have Chromium report it every websocket
frame.

On this 2-core machine the page's Chromium, the benchmark's driver and the machine's process share the
cores: the drop includes Chromium's own CPU, the server answering the page (status at an instant,
history pages, the timeline every second) and streaming it the live events. The control row says how
much of it a browser costs the machine on these cores whatever it shows, and the last row compares
looking back with it: what looking back itself costs. ``--own-core`` keeps
the browser and this driver on the last core (as a page on the operator's own computer would be), so
what is left is what serving the page costs the machine. Run it under the browser lock:

    flock /tmp/fsmscope-browser.lock .venv/bin/python bench/live_rewind.py [--rounds 3] [--seconds 5] [--own-core]
        [--machine waiting|computing]
"""

import argparse
import contextlib
import json
import os
import random
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable

# The repository first: run as a script, this folder comes first and its server.py would shadow the package.
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from demo_cpu import TICKS, cpu_seconds  # noqa: E402
from quiet_page import QuietPage  # noqa: E402
from fsmscope.server.testing.browser import launch_chromium  # noqa: E402
from table import print_table, verdict  # noqa: E402
from replay import generate  # noqa: E402  (bench/replay.py: the two-state loop, recorded)
from timetravel_browser import axis, page_of, served  # noqa: E402

WORK_SECONDS = 0.001  # of computing per state
WARM_UP = 2.0  # s after the machine starts, and after a page opens
OTHER_RUN = 100_000  # events of the control's recorded run
SCRIPT = '''"""Two states that wait argv[3] s, or compute for argv[3] steps, back and forth, until the file argv[1]
exists."""
import os
import sys
import time

import fsm

STOP, KIND, AMOUNT = sys.argv[1], sys.argv[2], float(sys.argv[3])
fsm.set_loggers(*[lambda message: None] * 4)  # no line printed per transition


def compute(ud):
    if KIND == "waiting":
        time.sleep(AMOUNT)
    else:
        total = 0
        for i in range(int(AMOUNT)):
            total += i
    return "stop" if os.path.exists(STOP) else "go"


sm = fsm.StateMachine(outcomes=["done"])
with sm:
    fsm.StateMachine.add("A", fsm.CBState(compute, outcomes=["go", "stop"]), {"go": "B", "stop": "done"})
    fsm.StateMachine.add("B", fsm.CBState(compute, outcomes=["go", "stop"]), {"go": "A", "stop": "done"})
sm.execute()
'''


def steps_for(seconds: float) -> int:
    """How many steps of the script's loop take ``seconds`` here (the fastest of 21 timings of 100,000: the
    machine unhindered)."""
    def once() -> float:
        start = time.perf_counter()
        total = 0
        for i in range(100_000):
            total += i
        return time.perf_counter() - start
    return int(100_000 * seconds / min(once() for _ in range(21)))


def busy_cores() -> float:
    """CPU seconds all cores have been busy so far (/proc/stat)."""
    fields = [int(f) for f in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]]
    return (sum(fields) - fields[3] - fields[4]) / TICKS


def thread_cpu(pid: int) -> float:
    """User + system CPU seconds of the process's main thread alone (the machine runs the script there)."""
    fields = Path("/proc/%d/task/%d/stat" % (pid, pid)).read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def browser_cpu(machine_pid: int) -> dict[int, float]:
    """CPU seconds of each of this process and its children but the machine's: Chromium, Playwright's
    driver and this benchmark driving them."""
    parents = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        with contextlib.suppress(OSError, IndexError):
            parents[int(stat.parent.name)] = int(stat.read_text().rsplit(")", 1)[1].split()[1])
    family, found = {os.getpid()}, True
    while found:
        found = {pid for pid, parent in parents.items() if parent in family and pid not in family | {machine_pid}}
        family |= found
    seconds = {}
    for pid in family:
        with contextlib.suppress(OSError):
            seconds[pid] = cpu_seconds(pid)
    return seconds


class Window:
    """One measured stretch: its wall-clock times, and the CPU (share of one core) of the machine's thread,
    of its process's other threads (the server), of the browser and of all cores."""

    def __init__(self, condition: str, pid: int, seconds: float, during: Callable[[float], None]) -> None:
        self.condition = condition
        meters = {"machine": lambda: {pid: thread_cpu(pid)}, "process": lambda: {pid: cpu_seconds(pid)},
                  "browser": lambda: browser_cpu(pid), "all": lambda: {0: busy_cores()}}
        before, self.t0 = {name: meter() for name, meter in meters.items()}, time.time()
        during(self.t0 + seconds)
        self.t1 = time.time()
        self.cpu = {}
        for name, meter in meters.items():  # the processes running at the end (a page closed before it is not)
            self.cpu[name] = sum(s - before[name].get(k, 0.0) for k, s in meter().items()) / (self.t1 - self.t0)
        self.cpu["server"] = self.cpu.pop("process") - self.cpu["machine"]
        self.rate = 0.0
        self.opened = self.page_seq = self.behind = None  # with a page: s it took to open, its live seq at t1


def idle_until(end: float) -> None:
    time.sleep(max(0.0, end - time.time()))


def looking_back(page: QuietPage, rng: random.Random) -> Callable[[float], None]:
    """Every second: a click on the timeline's axis at a random point of the run's first 80 %, then play."""
    def drive(end: float) -> None:
        while time.time() < end:
            x0, x1, y = axis(page)
            page.click(x0 + rng.uniform(0.05, 0.8) * (x1 - x0), y)
            page.wait_for("() => window.fsmscope.instant.past")
            page.press("Space")
            idle_until(min(end, time.time() + 1.0))
        if not page.evaluate("() => window.fsmscope.instant.past"):
            raise RuntimeError("the page went back to live while looking back")
    return drive


LOOKING_BACK = "one page looking back"
CONTROL = "control: a page looking back at another run, another process"


def measure(rounds: int, seconds: float, kind: str, amount: float, tmp: str, own_core: bool) -> list[Window]:
    from playwright.sync_api import sync_playwright

    script, log, stop, other = (os.path.join(tmp, name)
                                for name in ("loop.py", "run.jsonl", "stop", "other.jsonl"))
    Path(script).write_text(SCRIPT)
    generate(other, OTHER_RUN)
    rng = random.Random(9)
    windows = []
    with served(["run", "--exit", "--record", log, script, stop, kind, str(amount)], r"dashboard at (http://\S+)") \
            as (url, proc), served(["replay", other, "--serve"], r"replaying \S+ at (http://\S+)") as (other_url, _):
        cores = os.sched_getaffinity(0)
        if own_core:  # Playwright's driver and Chromium, started after this, inherit it
            os.sched_setaffinity(0, {max(cores)})
        with sync_playwright() as pw:
            browser = launch_chromium(pw)
            time.sleep(WARM_UP)
            for _ in range(rounds):
                windows.append(Window("no page", proc.pid, seconds, idle_until))
                for condition, address in (("one page, live", url), (LOOKING_BACK, url), (CONTROL, other_url)):
                    opening = time.monotonic()
                    with page_of(browser, address) as page:
                        opened = time.monotonic() - opening
                        time.sleep(WARM_UP)
                        during = idle_until if condition == "one page, live" else looking_back(page, rng)
                        windows.append(Window(condition, proc.pid, seconds, during))
                        if address == url:
                            windows[-1].opened = opened
                            windows[-1].page_seq = page.evaluate("() => window.fsmscope.liveStatus.last_seq")
            browser.close()
        os.sched_setaffinity(0, cores)  # the next machine's process must not inherit the browser's core
        Path(stop).touch()
        proc.wait(60)
    with open(log) as recording:
        events = [(e["seq"], e["t"], e["kind"]) for e in map(json.loads, recording)]
    for w in windows:
        w.rate = sum(w.t0 <= t <= w.t1 and kind == "transition" for _, t, kind in events) / (w.t1 - w.t0)
        if w.page_seq is not None:
            w.behind = max(seq for seq, t, _ in events if t <= w.t1) - w.page_seq
    return windows


def rows_of(windows: list[Window]) -> list[tuple[str, str, str, str]]:
    """One row per condition, in the order measured, its rate against the first's (no page)."""
    rows = []
    base = None
    for c in dict.fromkeys(w.condition for w in windows):
        mine = [w for w in windows if w.condition == c]
        rate = statistics.median(w.rate for w in mine)
        cpu = {name: statistics.median(w.cpu[name] for w in mine) * 100 for name in mine[0].cpu}
        base = base or rate
        targeted = c == LOOKING_BACK
        page = "" if mine[0].opened is None else " (page opened in %.1f s, its live view %d events behind)" % (
            statistics.median(w.opened for w in mine), statistics.median(w.behind for w in mine))
        rows.append(("%s%s: CPU %% of a core: machine %.0f, server %.0f, browser %.0f; all %d cores %.0f"
                     % (c, page, cpu["machine"], cpu["server"], cpu["browser"], os.cpu_count(), cpu["all"]),
                     "<= 5 % lower" if targeted else "", "%.0f/s (%+.1f %%)" % (rate, (rate / base - 1) * 100),
                     verdict(rate >= 0.95 * base) if targeted else ""))
    back, control = (statistics.median(w.rate for w in windows if w.condition == c) for c in (LOOKING_BACK, CONTROL))
    rows.append(("looking back against the control: what looking back costs beyond a browser on these cores",
                 "<= 5 % lower", "%+.1f %%" % ((back / control - 1) * 100), verdict(back >= 0.95 * control)))
    return rows


MACHINES = ("waiting", "computing")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=5.0, help="each window")
    parser.add_argument("--own-core", action="store_true",
                        help="keep the browser and this driver on the last core, off the machine's")
    parser.add_argument("--machine", choices=MACHINES, action="append",
                        help="measure this machine only (again for another); default: both")
    args = parser.parse_args()
    for kind in args.machine or MACHINES:
        amount = WORK_SECONDS if kind == "waiting" else steps_for(WORK_SECONDS)
        with tempfile.TemporaryDirectory(prefix="fsmscope-bench-") as tmp:
            windows = measure(args.rounds, args.seconds, kind, amount, tmp, args.own_core)
        print_table("fsmscope live rewind: transitions/s of a machine %s ~%g ms a state, %d rounds of %g s%s"
                    % (kind, WORK_SECONDS * 1000, args.rounds, args.seconds,
                       ", the browser on a core of its own" if args.own_core else ""), rows_of(windows))


if __name__ == "__main__":
    main()
