"""What watching a machine of the ORIGINAL smach costs it, against what smach_ros's
IntrospectionServer costs it, with fsm's own machines side by side, in one run.

The two-state loop and the 3-level nested machine of bench/runtime.py, each state adding one to the
userdata's ``count`` (the machine also holds a pose of 7 floats and a name, as a task's userdata
would), run on the original smach (noetic-devel core from ../shared/reference) and on fsm:

- bare: no observer;
- smach_ros: what smach_ros's IntrospectionServer does in the machine's thread at each start,
  transition and termination of every container (its ``_publish_status``): the base64 of a
  protocol-2 pickle of the container's userdata, before publishing (the publishing itself, rospy's
  serialisation and socket write, is not counted, which favours smach_ros);
- smach_ros publishing: the real smach_ros IntrospectionServer (../shared/reference) started on the
  machine as a user starts it, this process a node of a private rosmaster, the real ``rostopic hz``
  subscribed to its status in another process as smach_viewer is (bench/smach_ros_publishing.py):
  all it costs, publishing included (skipped, saying why, without ROS 1);
- fsmscope: watched by fsmscope's in-process hook, the recorder and the dashboard's hub (a real
  server in the process, no page open).

The cost of a watcher is the time it adds per transition (1/watched - 1/bare rate). Target: fsmscope's
cost on an original machine is no more than smach_ros's (its pickle); it is also given as a ratio of
smach_ros's publishing. The rounds are interleaved (round r runs every case once, in turn, so the
drift of this shared computer's speed hits every case alike; a short round first warms up): each
cost is the median of the rounds' costs, with their range; fsmscope's ratio to smach_ros's is that of
their medians.

The speed of this shared computer drifts by half between runs of seconds, so ``--instructions``
adds what does not: the instructions a transition costs (valgrind's callgrind, every thread of the
process, the server's and rospy's included; not the subscriber's, in its own process), runs of
``COUNTED`` transitions less runs of none (15–25 minutes; smach_ros publishing runs about 100 s each).

    .venv/bin/python bench/original_smach.py [--runs 7] [--instructions]
"""

from __future__ import annotations

import argparse
import gc
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))

import fsm  # noqa: E402
import runtime  # noqa: E402
from fsm.observation import delivery  # noqa: E402
from fsmscope.server import fanout  # noqa: E402
from fsmscope.server.http_server import ServerThread  # noqa: E402
from fsmscope.server.testing.ros1 import missing_ros1  # noqa: E402
from smach_ros_publishing import Introspected, Master, Node  # noqa: E402
from table import print_table, verdict  # noqa: E402
from watchers import USERDATA, Watched, load_original, smach_ros_cost  # noqa: E402

TRANSITIONS = 20_000  # per run, for each machine (the nested one counts steps)
WARM_UP = 10  # the warm-up round's runs are this many times shorter
COUNTED = 10_000  # transitions of a run under callgrind
SLOWED = 50  # callgrind runs about this many times slower: what batches by time waits as much longer
WORKLOADS = {"two-state loop": runtime.two_state_loop, "3-level nested": runtime.nested_machine}
# Watchers: none; smach_ros's pickle; smach_ros's real IntrospectionServer, publishing; fsmscope's recorder + hub.
BARE, SMACH_ROS, PUBLISHING, FSMSCOPE = "bare", "smach_ros", "smach_ros_publishing", "fsmscope"
CASES = [("smach", BARE), ("smach", SMACH_ROS), ("smach", PUBLISHING), ("smach", FSMSCOPE), ("fsm", BARE),
         ("fsm", FSMSCOPE)]


def machine_run(smach: Any, factory: Callable, watcher: str, server: ServerThread | None, node: Node | None,
                slowed: int = 1) -> tuple[Callable, Watched | Introspected | None]:
    """A fresh machine's run, watched by ``watcher`` (one of CASES's, or "noop": fsmscope's hooks with a
    no-op observer, for ``--once``), and the watch to close."""
    machine, run = factory(smach, dict(USERDATA))
    watch = None
    if watcher == SMACH_ROS:
        smach_ros_cost(machine)
    elif watcher == PUBLISHING:
        watch = node.introspect(machine)
    elif watcher == FSMSCOPE:
        watch = Watched(server, slowed)
        watch.attach(machine)
    elif watcher == "noop":  # fsmscope's hooks alone, a no-op observer: what --once counts of them
        fsm.attach(machine, lambda event: None)
    return run, watch


def rounds(cores: dict[str, Any], server: ServerThread, node: Node | None, runs: int) -> dict[tuple, list[float]]:
    """Transitions (or steps) per second of every case of every workload, ``runs`` interleaved
    rounds of a fresh machine's run each, after a shorter round that warms up."""
    rates: dict[tuple, list[float]] = {}
    cases = [case for case in CASES if node is not None or case[1] != PUBLISHING]
    for round_ in range(runs + 1):
        warming = round_ == 0
        runtime.LOOP_TRANSITIONS = runtime.NESTED_STEPS = TRANSITIONS // WARM_UP if warming else TRANSITIONS
        for workload, factory in WORKLOADS.items():
            for smach_name, watcher in cases:
                run, watch = machine_run(cores[smach_name], factory, watcher, server, node)
                gc.collect()
                start = time.perf_counter()
                count = run()
                rate = count / (time.perf_counter() - start)
                if watch is not None:
                    watch.close()
                if not warming:
                    rates.setdefault((workload, smach_name, watcher), []).append(rate)
        print("bench/original_smach.py: %s" % ("warmed up" if warming else "round %d of %d" % (round_, runs)),
              file=sys.stderr, flush=True)
    return rates


def run_once(smach_name: str, workload: str, watcher: str, transitions: int) -> None:
    """What callgrind counts: the server (for fsmscope) or this process as a ROS node (for smach_ros
    publishing, the master's environment given), a warm-up run of the watched machine, then a run of
    ``transitions`` (the warm-up's instructions are in the runs of ``transitions`` and of none alike).
    The recorder's flush, the delivery's batches and the loop's drain wait ``SLOWED`` times longer, so
    that they take batches as full as at full speed."""
    smach = load_original("bench/original_smach.py") if smach_name == "smach" else fsm
    quiet = lambda msg: None  # noqa: E731
    smach.set_loggers(quiet, quiet, quiet, quiet)
    fanout.DRAIN_INTERVAL *= SLOWED
    delivery.INTERVAL *= SLOWED
    server = ServerThread().start() if watcher == FSMSCOPE else None
    node = Node(dict(os.environ)) if watcher == PUBLISHING else None
    runtime.LOOP_TRANSITIONS = runtime.NESTED_STEPS = 640
    run, watch = machine_run(smach, WORKLOADS[workload], watcher, server, node, SLOWED)
    run()
    runtime.LOOP_TRANSITIONS = runtime.NESTED_STEPS = transitions
    if transitions:
        run()
    if watch is not None:
        watch.close()
    if server is not None:
        server.stop()
    if node is not None:
        node.close()


def instructions(case: tuple[str, str, str], env: dict[str, str] | None) -> float:
    """Instructions per transition of ``case`` (smach, workload, watcher) under callgrind, in ``env``."""
    def count(transitions: int) -> int:
        out = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", sys.executable,
                              __file__, "--once", *case, str(transitions)],
                             cwd=ROOT, env=env, capture_output=True, text=True, check=True).stderr
        return int(re.search(r"Collected : (\d+)", out).group(1))
    return (count(COUNTED) - count(0)) / COUNTED


def instruction_rows(master: Master | None, skipped: str | None) -> list[tuple[str, str, str, str]]:
    """Instructions per transition of each machine bare and watched, and the watchers' costs: the
    table's rows (two cases counted at a time, one per core). smach_ros publishing's processes are
    nodes of ``master`` (none: ``skipped`` says why)."""
    if shutil.which("valgrind") is None:
        return [("instructions per transition (valgrind is not installed)", "", "-", verdict(None))]
    cases = [(smach, workload, watcher) for workload in WORKLOADS for smach, watcher in CASES
             if master is not None or watcher != PUBLISHING]
    with ThreadPoolExecutor(2) as pool:
        counted = dict(zip(cases, pool.map(lambda case: instructions(case, master.env if case[2] == PUBLISHING
                                                                     else None), cases)))
    rows = []
    for workload in WORKLOADS:
        smach_bare, fsm_bare = counted[("smach", workload, BARE)], counted[("fsm", workload, BARE)]
        ros = counted[("smach", workload, SMACH_ROS)] - smach_bare
        watched_smach = counted[("smach", workload, FSMSCOPE)] - smach_bare
        watched_fsm = counted[("fsm", workload, FSMSCOPE)] - fsm_bare
        publishing = None
        if master is not None:
            publishing = counted[("smach", workload, PUBLISHING)] - smach_bare
        rows += [
            ("%s: instructions, original smach / fsm, bare" % workload, "-", "%.0f / %.0f" % (smach_bare, fsm_bare), ""),
            ("%s: instructions smach_ros's IntrospectionServer adds" % workload, "-", "+%.0f" % ros, ""),
            ("%s: instructions smach_ros's IntrospectionServer adds, publishing to a subscriber (real rospy, "
             "rosmaster)" % workload, "-", "skipped: %s" % skipped if publishing is None else "+%.0f" % publishing, ""),
            ("%s: instructions fsmscope adds watching smach" % workload, "<= smach_ros's",
             "+%.0f (%s)" % (watched_smach, of_smach_ros(watched_smach / ros, publishing and watched_smach / publishing)),
             verdict(watched_smach <= ros)),
            ("%s: instructions fsmscope adds watching fsm" % workload, "-",
             "+%.0f (%s)" % (watched_fsm, of_smach_ros(watched_fsm / ros, publishing and watched_fsm / publishing)), ""),
        ]
    return rows


def cost_us(bare: float, watched: float) -> float:
    """Microseconds a watcher adds per transition."""
    return 1e6 * (1 / watched - 1 / bare)


def of_smach_ros(ratio: float, publishing_ratio: float | None) -> str:
    """A cost as ratios of smach_ros's (its pickle) and, where measured, of smach_ros's publishing."""
    text = "x%.2f of smach_ros's" % ratio
    return text if publishing_ratio is None else text + ", x%.2f of its publishing" % publishing_ratio


def spread(costs: list[float]) -> str:
    """The median cost of the rounds, and their range."""
    return "%+.1f us/transition (%+.1f to %+.1f)" % (statistics.median(costs), min(costs), max(costs))


def rate_rows(rates: dict[tuple, list[float]], skipped: str | None) -> list[tuple[str, str, str, str]]:
    """The wall-clock rows of each workload: rates of the bare machines (fsm's as the median of the
    rounds' ratios to the original's), each watcher's cost per transition (the rounds' median and
    range) and fsmscope's costs as ratios of smach_ros's median costs (a cost of a few microseconds
    is within a round's noise: a ratio per round would divide by it)."""
    def costs(workload: str, smach: str, watcher: str) -> list[float]:
        return [cost_us(bare, watched) for bare, watched in zip(rates[(workload, smach, BARE)],
                                                                 rates[(workload, smach, watcher)])]

    rows = []
    for workload in WORKLOADS:
        smach_bare, fsm_bare = rates[(workload, "smach", BARE)], rates[(workload, "fsm", BARE)]
        ros = statistics.median(costs(workload, "smach", SMACH_ROS))
        publishing = None if skipped else costs(workload, "smach", PUBLISHING)
        published = publishing and statistics.median(publishing)
        watched, fsm_watched = costs(workload, "smach", FSMSCOPE), costs(workload, "fsm", FSMSCOPE)
        watched_cost, fsm_watched_cost = statistics.median(watched), statistics.median(fsm_watched)
        rows += [
            ("%s: original smach, bare" % workload, "-", "%s/s" % f"{statistics.median(smach_bare):,.0f}", ""),
            ("%s: fsm, bare" % workload, "-", "%s/s (x%.2f of smach)" % (
                f"{statistics.median(fsm_bare):,.0f}",
                statistics.median(fsm / smach for fsm, smach in zip(fsm_bare, smach_bare))), ""),
            ("%s: smach_ros's IntrospectionServer on smach" % workload, "-",
             spread(costs(workload, "smach", SMACH_ROS)), ""),
            ("%s: smach_ros's IntrospectionServer, publishing to a subscriber (real rospy, rosmaster)" % workload, "-",
             "skipped: %s" % skipped if publishing is None else spread(publishing), ""),
            ("%s: fsmscope watching smach" % workload, "<= smach_ros's", "%s (%s)" % (spread(watched), of_smach_ros(
                watched_cost / ros, published and watched_cost / published)), verdict(watched_cost <= ros)),
            ("%s: fsmscope watching fsm" % workload, "-", "%s (%s)" % (spread(fsm_watched), of_smach_ros(
                fsm_watched_cost / ros, published and fsm_watched_cost / published)), ""),
        ]
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=7, help="interleaved rounds (default 7)")
    parser.add_argument("--instructions", action="store_true", help="also count instructions under callgrind (minutes)")
    parser.add_argument("--once", nargs=4, metavar=("SMACH", "WORKLOAD", "WATCHER", "TRANSITIONS"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.once:
        run_once(*args.once[:3], int(args.once[3]))
        return
    original = load_original("bench/original_smach.py")
    quiet = lambda msg: None  # noqa: E731  (loggers off on both, as bench/runtime.py measures)
    for smach in (original, fsm):
        smach.set_loggers(quiet, quiet, quiet, quiet)
    skipped = missing_ros1()
    if skipped is not None:
        print("bench/original_smach.py: smach_ros publishing skipped: %s" % skipped, file=sys.stderr, flush=True)
    server = ServerThread().start()
    master = node = None
    try:
        if skipped is None:
            master = Master()
            node = Node(master.env)
        rows = rate_rows(rounds({"smach": original, "fsm": fsm}, server, node, args.runs), skipped)
        if args.instructions:
            rows += instruction_rows(master, skipped)
    finally:
        server.stop()
        if node is not None:
            node.close()
        if master is not None:
            master.close()
    print_table("Watching the original smach (userdata: count, a pose, a name; medians of %d interleaved rounds of "
                "runs of %d)" % (args.runs, TRANSITIONS), rows)


if __name__ == "__main__":
    main()
