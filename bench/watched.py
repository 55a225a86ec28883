"""Issue 30's table: a watched machine of fsm against the original SMACH watched by its
IntrospectionServer, measured side by side in one process.

The machines of bench/runtime.py, with the userdata of bench/watchers.py (a count each state adds
one to, a pose of 7 floats, a name), on the original core from ../shared/reference (skipped, saying
why, without it) and on fsm:

- the two-state loop: the original bare; the original with the callback smach_ros's
  IntrospectionServer runs at every start, transition and termination of every container (the base64
  of a protocol-2 pickle of the container's userdata; its publishing not counted, which favours it):
  **the reference**; fsm bare; fsm watched as ``fsmscope run`` watches it (a recorder and the
  dashboard's hub of a running server, target >= 1.5x the reference); fsm watched as ``fsmscope run
  --zenoh --foxglove`` (also a Zenoh robot publishing what the hub encodes, on a real session on the
  loopback, multicast scouting off, listening on a free tcp port, and the Foxglove live server fed
  from the hub, on a free port; target >= 1.0x the reference);
- the 3-level nested machine and a Concurrence of 4: fsm watched by the recorder and the hub against
  the original with the callback on every container (target >= 1.5x).

The process switches threads as ``fsmscope run`` makes it (``SWITCH_INTERVAL``), for every case.
A watched run's clock stops when the recorder has every event the machine made (what an observer
leaves queued at the end counts); each watched log is then read back (fsm.logfiles.log_reader) and
"events lost" counts the events the machine made, by their seq, that it does not hold, in order.

The rounds are interleaved: round r runs every case once, in turn, so the drift of this shared
computer's speed hits every case alike; each case is measured by its median rate over the rounds and
each ratio is the median of the rounds' ratios. A short round first warms up, not counted.

    .venv/bin/python bench/watched.py [--runs 7]
"""

from __future__ import annotations

import argparse
import gc
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE))

import fsm  # noqa: E402
import runtime  # noqa: E402
from fsm.logfiles.log_reader import read_events  # noqa: E402
from fsmscope.fleet.robot import ZenohRobot  # noqa: E402
from fsmscope.server.cli.foxglove_bridge import start_foxglove  # noqa: E402
from fsmscope.server.cli.serving import SWITCH_INTERVAL  # noqa: E402
from fsmscope.server.http_server import ServerThread  # noqa: E402
from fsmscope.server.testing.demo_process import free_endpoint  # noqa: E402
from table import print_table, verdict  # noqa: E402
from watchers import USERDATA, Watched, load_original, smach_ros_cost  # noqa: E402

SIZES = {"LOOP_TRANSITIONS": 100_000, "NESTED_STEPS": 50_000, "CONCURRENCE_RUNS": 500}  # of bench/runtime.py, per run
WARM_UP = 20  # the warm-up round's runs are this many times shorter
WRITTEN_TIMEOUT = 30.0  # s a watched run's recorder is given to hold every event the machine made


@dataclass(frozen=True)
class Workload:
    name: str
    build: Callable[[Any, dict], tuple]  # (smach module, userdata) -> (machine, run)
    unit: str


LOOP = Workload("two-state loop", runtime.two_state_loop, "transitions/s")
NESTED = Workload("3-level nested", runtime.nested_machine, "steps/s")
CONCURRENCE = Workload("Concurrence of 4", runtime.concurrence, "executions/s")

# Watchers: nothing; smach_ros's callback; fsmscope run's recorder + hub; and also its Zenoh robot + Foxglove.
BARE, SMACH_ROS, RUN, RUN_FLEET = "bare", "smach_ros", "recorder + hub", "recorder + hub + Zenoh + Foxglove"


@dataclass(frozen=True)
class Case:
    label: str
    workload: Workload
    original: bool  # the original SMACH's machine, else fsm's
    watcher: str
    reference: Case | None = None  # the case its ratio is taken to
    target: float | None = None  # the ratio it must reach


LOOP_BARE = Case("two-state loop: original SMACH, bare", LOOP, True, BARE)
LOOP_REFERENCE = Case("two-state loop: original SMACH + smach_ros's callback (the reference)", LOOP, True, SMACH_ROS)
NESTED_REFERENCE = Case("3-level nested: original SMACH + smach_ros's callback on every container", NESTED, True,
                        SMACH_ROS)
CONCURRENCE_REFERENCE = Case("Concurrence of 4: original SMACH + smach_ros's callback", CONCURRENCE, True, SMACH_ROS)
CASES = [
    LOOP_BARE,
    LOOP_REFERENCE,
    Case("two-state loop: fsm, bare", LOOP, False, BARE, LOOP_BARE),
    Case("two-state loop: fsm + recorder + hub (fsmscope run)", LOOP, False, RUN, LOOP_REFERENCE, 1.5),
    Case("two-state loop: fsm + recorder + hub + Zenoh robot + Foxglove (run --zenoh --foxglove)", LOOP, False,
         RUN_FLEET, LOOP_REFERENCE, 1.0),
    NESTED_REFERENCE,
    Case("3-level nested: fsm + recorder + hub", NESTED, False, RUN, NESTED_REFERENCE, 1.5),
    CONCURRENCE_REFERENCE,
    Case("Concurrence of 4: fsm + recorder + hub", CONCURRENCE, False, RUN, CONCURRENCE_REFERENCE, 1.5),
]


class Servers:
    """What the watched cases attach to: one server for ``fsmscope run``'s watch, and one with the
    Foxglove server fed from its hub and a Zenoh robot for ``run --zenoh --foxglove``'s."""

    def __init__(self) -> None:
        self.server = ServerThread().start()
        self.fleet_server = ServerThread().start()
        self.foxglove = start_foxglove(argparse.Namespace(foxglove=0, foxglove_origin=None, foxglove_host=None),
                                       self.fleet_server.hub)
        self.robot = ZenohRobot("bench", listen=[free_endpoint()], token="bench")

    def watch(self, watcher: str) -> Watched:
        if watcher == RUN:
            return Watched(self.server)
        return Watched(self.fleet_server, robot=self.robot)

    def close(self) -> None:
        self.robot.close()
        self.server.stop()
        self.fleet_server.stop()
        self.foxglove.stop()


def written(watch: Watched) -> None:
    """Wait until the recorder holds every event the machine made (or ``WRITTEN_TIMEOUT``), then write them."""
    deadline = time.monotonic() + WRITTEN_TIMEOUT
    while watch.recorder.events < watch.reporter.last_seq and time.monotonic() < deadline:
        time.sleep(0.0005)
    watch.recorder.flush()


def lost(watch: Watched) -> tuple[int, int, bool]:
    """(events made, of them not in the log, whether the log has them out of order)."""
    made = watch.reporter.last_seq
    seqs = [event["seq"] for event in read_events(watch.path) if event["kind"] != "snapshot"]
    return made, made - len(set(seqs) & set(range(1, made + 1))), seqs != sorted(seqs)


def run_case(case: Case, smach: Any, servers: Servers) -> tuple[float, tuple[int, int, bool] | None]:
    """One run of a fresh machine: its rate, and for a watched one what its log lost."""
    machine, run = case.workload.build(smach, dict(USERDATA))
    watch = None
    if case.watcher == SMACH_ROS:
        smach_ros_cost(machine)
    elif case.watcher != BARE:
        watch = servers.watch(case.watcher)
        watch.attach(machine)
    gc.collect()
    start = time.perf_counter()
    count = run()
    if watch is not None:
        written(watch)
    rate = count / (time.perf_counter() - start)
    if watch is None:
        return rate, None
    try:
        return rate, lost(watch)
    finally:
        watch.close()


def measured(case: Case, rate: float, ratio: float | None) -> str:
    """The rate, and its ratio to the case it is compared with (the original, bare or watched)."""
    text = "%s %s" % (f"{rate:,.0f}", case.workload.unit)
    if ratio is None:
        return text
    return "%s (%.2fx the original %s)" % (text, ratio, "bare" if case.reference.watcher == BARE else "watched")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=7, help="interleaved rounds (default 7)")
    args = parser.parse_args()
    original = load_original("bench/watched.py")
    quiet = lambda msg: None  # noqa: E731  (loggers off on both, as bench/runtime.py measures)
    for smach in (original, fsm):
        smach.set_loggers(quiet, quiet, quiet, quiet)
    sys.setswitchinterval(SWITCH_INTERVAL)
    servers = Servers()
    rates: dict[str, list[float]] = {case.label: [] for case in CASES}
    made = missing = disordered = watched_runs = 0
    try:
        for round_ in range(args.runs + 1):
            warming = round_ == 0
            for name, size in SIZES.items():
                setattr(runtime, name, size // WARM_UP if warming else size)
            for case in CASES:
                rate, check = run_case(case, original if case.original else fsm, servers)
                if not warming:
                    rates[case.label].append(rate)
                if check is not None:
                    made, missing, disordered = made + check[0], missing + check[1], disordered + check[2]
                    watched_runs += 1
            print("bench/watched.py: %s" % ("warmed up" if warming else "round %d of %d" % (round_, args.runs)),
                  file=sys.stderr, flush=True)
    finally:
        servers.close()
    rows = []
    for case in CASES:
        rate = statistics.median(rates[case.label])
        ratio = None
        if case.reference is not None:
            ratio = statistics.median(r / ref for r, ref in zip(rates[case.label], rates[case.reference.label]))
        rows.append((case.label, "-" if case.target is None else ">= %.1fx the reference" % case.target,
                     measured(case, rate, ratio),
                     verdict(None if case.target is None else ratio >= case.target)))
    rows.append(("events lost: made by the watched machines, not in their logs in order (%d runs)" % watched_runs,
                 "0", "%d of %s%s" % (missing, f"{made:,}", ", out of order" if disordered else ""),
                 verdict(missing == 0 and not disordered)))
    print_table("Issue 30: watched machines against the original SMACH watched by smach_ros's callback, side by side "
                "(userdata: count, a pose, a name; runs of %s transitions / %s steps / %s executions; medians of %d "
                "interleaved rounds)" % (f"{SIZES['LOOP_TRANSITIONS']:,}", f"{SIZES['NESTED_STEPS']:,}",
                                         f"{SIZES['CONCURRENCE_RUNS']:,}", args.runs), rows)


if __name__ == "__main__":
    main()
