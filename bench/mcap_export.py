"""MCAP export (issue 12): a recorded log of 1,000,000 events (a real two-state loop, as
bench/replay.py records it) written as MCAP by ``fsmscope export --mcap`` (events, active states,
transcript lines as foxglove.Log), in events/s, and read back by ``fsmscope replay``'s MCAP reader;
against the rate at which fsmscope's JSONL reader reads the same log (the reference ratio the
issue asks for). Medians of 3 runs.

    .venv/bin/python bench/mcap_export.py [--events 1000000]
"""

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from fsm.logfiles.log_reader import read_events  # noqa: E402
from fsmscope.interop.mcap_log import read_mcap, write_mcap  # noqa: E402
from replay import generate  # noqa: E402
from table import print_table, verdict  # noqa: E402

REPEATS = 3


def rate(work) -> float:
    start = time.perf_counter()
    count = work()
    return count / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--events", type=int, default=1_000_000)
    args = parser.parse_args()
    folder = tempfile.mkdtemp(prefix="fsmscope-mcap-bench-")
    try:
        log = os.path.join(folder, "loop.jsonl")
        generate(log, args.events)
        events = sum(e["kind"] != "snapshot" for e in read_events(log))
        jsonl, export, back = [], [], []
        for i in range(REPEATS):
            jsonl.append(rate(lambda: sum(1 for _ in read_events(log))))
            out = os.path.join(folder, "loop-%d.mcap" % i)
            export.append(rate(lambda: write_mcap(read_events(log), out)))
            back.append(rate(lambda: sum(1 for _ in read_mcap(out))))
        size = os.path.getsize(out) / 2**20
    finally:
        shutil.rmtree(folder)
    j, e, b = (statistics.median(x) for x in (jsonl, export, back))
    print_table("MCAP export of a %d-event log (%.0f MB of MCAP), medians of %d runs" % (events, size, REPEATS), [
        ("fsmscope's JSONL reader (reference)", "", "%.0f events/s" % j, verdict(None)),
        ("export --mcap: read the log, write the MCAP", "", "%.0f events/s" % e, verdict(None)),
        ("  its rate / the JSONL reader's", "", "%.2f" % (e / j), verdict(None)),
        ("replay OUT.mcap's reader: the events back", "", "%.0f events/s" % b, verdict(None)),
        ("  its rate / the JSONL reader's", "", "%.2f" % (b / j), verdict(None)),
    ])


if __name__ == "__main__":
    main()
