"""CPU of the whole demo process (physics at real time, 30 Hz viser view, dashboard server,
recording), with no browser connected and then with one Chromium showing the demo page.

    .venv/bin/python bench/demo_cpu.py [--seconds 60] [--runs 1]

Prints a table; the target is the demo process under 15% of one core with no browser.
"""

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

# The repository first: run as a script, this folder comes first and its server.py would shadow the package.
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from server.testing.browser import launch_chromium, open_page  # noqa: E402
from server.testing.demo_process import DemoProcess  # noqa: E402

TICKS = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid: int) -> float:
    """User + system CPU of the process and its threads, in seconds."""
    fields = Path("/proc/%d/stat" % pid).read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def share_of_one_core(pid: int, seconds: float) -> float:
    start_cpu, start = cpu_seconds(pid), time.monotonic()
    time.sleep(seconds)
    return (cpu_seconds(pid) - start_cpu) / (time.monotonic() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--runs", type=int, default=1)
    args = parser.parse_args()
    alone, watched = [], []
    for _ in range(args.runs):
        with tempfile.TemporaryDirectory() as tmp:
            demo = DemoProcess(Path(tmp) / "demo.jsonl")
            try:
                time.sleep(3)  # start-up is not the steady state
                alone.append(share_of_one_core(demo.proc.pid, args.seconds))
                from playwright.sync_api import sync_playwright
                with sync_playwright() as pw:
                    browser = launch_chromium(pw)
                    page = open_page(browser, demo.url, 1600, 900, timeout_ms=30000)
                    page.wait_for_selector("#scene-pane:not([hidden]) iframe")
                    time.sleep(3)
                    watched.append(share_of_one_core(demo.proc.pid, args.seconds))
                    browser.close()
            finally:
                demo.stop()
    print("| demo process, %.0f s each, median of %d | CPU (share of one core) | target |" % (args.seconds, args.runs))
    print("|---|---|---|")
    a = statistics.median(alone)
    print("| no browser connected | %.1f%% | < 15%% %s |" % (a * 100, "(ok)" if a < 0.15 else "(MISSED)"))
    print("| one Chromium on the demo page | %.1f%% | (reported) |" % (statistics.median(watched) * 100))


if __name__ == "__main__":
    main()
