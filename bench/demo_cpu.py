"""CPU of the whole demo process (physics at real time, recording with the arm's pose at 30 Hz), with
no browser connected: with the dashboard and the 30 Hz viser view, and headless (no server, no view,
the pose still recorded). ``--browser`` adds a run with one Chromium showing the demo page (run it
under the browser lock: flock /tmp/fsmscope-browser.lock ...).

    .venv/bin/python bench/demo_cpu.py [--seconds 30] [--runs 3] [--browser]

Prints a table of medians; the target is the demo process under 15% of one core with no browser.
Each row also says how many pose events a second the log holds over the measured window.
"""

import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# The repository first: run as a script, this folder comes first and its server.py would shadow the package.
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from fsmscope.server.testing.demo_process import FSMSCOPE, DemoProcess  # noqa: E402
from fsmscope.server.testing.polling import wait_for  # noqa: E402

TICKS = os.sysconf("SC_CLK_TCK")
WARM_UP = 3.0  # seconds: start-up is not the steady state
TARGET = 0.15


def cpu_seconds(pid: int) -> float:
    """User + system CPU of the process and its threads, in seconds."""
    fields = Path("/proc/%d/stat" % pid).read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def share_of_one_core(pid: int, seconds: float) -> tuple[float, float, float]:
    """(CPU share of one core, wall-clock start, end) over the next ``seconds``."""
    start_cpu, start, t0 = cpu_seconds(pid), time.monotonic(), time.time()
    time.sleep(seconds)
    return (cpu_seconds(pid) - start_cpu) / (time.monotonic() - start), t0, time.time()


def pose_rate(record: Path, t0: float, t1: float) -> float:
    """Pose events a second that the log holds between wall-clock times t0 and t1."""
    with open(record) as log:
        times = [e["t"] for e in map(json.loads, log) if e.get("kind") == "pose"]
    return sum(t0 <= t <= t1 for t in times) / (t1 - t0)


class HeadlessDemo:
    """``fsmscope demo --headless`` in its own process group, recording to ``record``."""

    def __init__(self, record: Path) -> None:
        self.record = record
        self.proc = subprocess.Popen(FSMSCOPE + ["demo", "--headless", "--record", str(record)], cwd=ROOT,
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        wait_for(lambda: record.exists() and '"kind":"pose"' in record.read_text(), 60, interval=0.2,
                 what="the headless demo to record a pose")

    def stop(self) -> None:
        os.killpg(self.proc.pid, signal.SIGINT)
        self.proc.wait(20)


def measure(start, seconds: float, browser: bool) -> tuple[float, float]:
    """(CPU share, pose events/s) of one demo process started by ``start(record)``."""
    with tempfile.TemporaryDirectory() as tmp:
        record = Path(tmp) / "demo.jsonl"
        demo = start(record)
        try:
            time.sleep(WARM_UP)
            if not browser:
                share, t0, t1 = share_of_one_core(demo.proc.pid, seconds)
            else:
                from playwright.sync_api import sync_playwright

                from fsmscope.server.testing.browser import launch_chromium, open_page

                with sync_playwright() as pw:
                    chromium = launch_chromium(pw)
                    page = open_page(chromium, demo.url, 1600, 900, timeout_ms=30000)
                    page.wait_for_selector("#scene-pane:not([hidden]) iframe")
                    time.sleep(WARM_UP)
                    share, t0, t1 = share_of_one_core(demo.proc.pid, seconds)
                    chromium.close()
        finally:
            demo.stop()
        return share, pose_rate(record, t0, t1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--browser", action="store_true", help="also measure with one Chromium on the page")
    args = parser.parse_args()
    rows = [("dashboard + 3D view, no browser", DemoProcess, False, True),
            ("headless (no server, no view)", HeadlessDemo, False, True)]
    if args.browser:
        rows.append(("dashboard + 3D view, one Chromium on the page", DemoProcess, True, False))
    print("| demo process with pose recording, %.0f s each, median of %d | CPU (share of one core) "
          "| pose events/s in the log | target |" % (args.seconds, args.runs))
    print("|---|---|---|---|")
    for label, start, browser, targeted in rows:
        results = [measure(start, args.seconds, browser) for _ in range(args.runs)]
        share = statistics.median(r[0] for r in results)
        rate = statistics.median(r[1] for r in results)
        verdict = ("< 15%% %s" % ("(ok)" if share < TARGET else "(MISSED)")) if targeted else "(reported)"
        print("| %s | %.1f%% | %.1f | %s |" % (label, share * 100, rate, verdict), flush=True)


if __name__ == "__main__":
    main()
