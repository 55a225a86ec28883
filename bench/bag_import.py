"""ROS bag import (issue 12): a ROS 1 bag of 100,000 SMACH status messages (a loop of two states in
/SM_ROOT, its userdata changing at every transition, as smach_ros publishes it: base64 of a
protocol 2 pickle), read with rosbags and turned into fsmscope events (interop/), in events/s;
against the rate at which fsmscope's JSONL reader reads the same events back from the log
``fsmscope import`` writes (the reference ratio the issue asks for). Medians of 3 runs.

Then (issue 32) the import's time against the number of children of one container (a chain of
states S0 -> S1 -> ..., its structure and three statuses): it was the square of that number (2,500
children 2.3 s, 10,000 27 s, 20,000 over 120 s); the target is linear, each row within twice the
time per child of the smallest, and 20,000 children in under 5 s.

    .venv/bin/python bench/bag_import.py [--messages 100000] [--children 2500,5000,10000,20000,40000]
"""

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from fsm.logfiles.log_reader import read_events  # noqa: E402
from fsmscope.interop.bag_reader import read_bag  # noqa: E402
from fsmscope.interop.smach_events import events  # noqa: E402
from fsmscope.interop.testing import wide_run, write_bag  # noqa: E402
from fsmscope.interop.to_log import write_log  # noqa: E402
from table import print_table, verdict  # noqa: E402

REPEATS = 3
TOPIC = "/loop/smach/container_%s"


def loop_run(messages: int) -> list:
    """(t, topic, kind, fields): the structure, then ``messages`` statuses of A -> B -> A ..."""
    structure = {"path": "/SM_ROOT", "children": ["A", "B"], "internal_outcomes": ["go", "go", "stop"],
                 "outcomes_from": ["A", "B", "B"], "outcomes_to": ["B", "A", "done"], "container_outcomes": ["done"]}
    run = [(1.7e9, TOPIC % "structure", "structure", structure)]
    for i in range(messages):
        run.append((1.7e9 + 0.01 * (i + 1), TOPIC % "status", "status", {
            "path": "/SM_ROOT", "initial_states": ["A"], "active_states": ["B" if i % 2 == 0 else "A"],
            "userdata": {"count": i, "pose": [0.1 * i, 0.2, 0.3], "label": "step %d" % i}, "info": "HEARTBEAT"}))
    return run


def timed(work) -> tuple[float, int]:
    start = time.perf_counter()
    count = work()
    return time.perf_counter() - start, count


def children_table(folder: Path, sizes: list[int]) -> None:
    """Seconds to import a bag of one container with each number of children (medians of REPEATS)."""
    seconds = {}
    for n in sizes:
        bag = write_bag(folder / ("wide-%d.bag" % n), "ros1", wide_run(n))
        runs = []
        for i in range(REPEATS):
            log = str(folder / ("wide-%d-%d.jsonl" % (n, i)))
            runs.append(timed(lambda: write_log(events(read_bag(str(bag))), log))[0])
        seconds[n] = statistics.median(runs)
    smallest = sizes[0]
    per_child = seconds[smallest] / smallest
    rows = []
    for n in sizes:
        limit = 2 * per_child * n
        if n == 20_000:
            limit = min(limit, 5.0)
        rows.append(("%d children" % n, "< %.2f s" % limit, "%.2f s" % seconds[n], verdict(seconds[n] < limit)))
    print_table("ROS bag import against a container's children (fsmscope import), medians of %d runs" % REPEATS, rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--messages", type=int, default=100_000)
    parser.add_argument("--children", default="2500,5000,10000,20000,40000",
                        help="the numbers of children of the container, smallest first")
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="fsmscope-bag-bench-"))
    bag = write_bag(folder / "loop.bag", "ros1", loop_run(args.messages))
    converted, imported, read = [], [], []
    for i in range(REPEATS):
        seconds, count = timed(lambda: sum(1 for _ in events(read_bag(str(bag)))))
        converted.append(count / seconds)
        log = str(folder / ("loop-%d.jsonl" % i))
        seconds, written = timed(lambda: write_log(events(read_bag(str(bag))), log))
        imported.append(written / seconds)
        seconds, back = timed(lambda: sum(1 for _ in read_events(log)))
        read.append(back / seconds)
    convert, imp, jsonl = (statistics.median(x) for x in (converted, imported, read))
    print_table("ROS bag import, %d status messages (%d events), medians of %d runs" % (args.messages, count, REPEATS), [
        ("bag -> fsmscope events (rosbags read + interop.smach_events)", "", "%.0f events/s" % convert, verdict(None)),
        ("bag -> fsmscope log (fsmscope import)", "", "%.0f events/s" % imp, verdict(None)),
        ("fsmscope's JSONL reader, the same events (reference)", "", "%.0f events/s" % jsonl, verdict(None)),
        ("import's rate / the JSONL reader's", "", "%.2f" % (imp / jsonl), verdict(None)),
    ])
    print()
    children_table(folder, [int(n) for n in args.children.split(",")])


if __name__ == "__main__":
    main()
