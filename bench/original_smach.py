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
- fsmscope: watched by fsmscope's in-process hook, the recorder and the dashboard's hub (a real
  server in the process, no page open).

The cost of a watcher is the time it adds per transition (1/watched - 1/bare rate). Target: fsmscope's
cost on an original machine is no more than smach_ros's. Medians of ``--runs`` runs.

The speed of this shared computer drifts by half between runs of seconds, so ``--instructions``
adds what does not: the instructions a transition costs (valgrind's callgrind, every thread of the
process, the server's included), runs of ``COUNTED`` transitions less runs of none (about ten
minutes).

    .venv/bin/python bench/original_smach.py [--runs 5] [--instructions]
"""

from __future__ import annotations

import argparse
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
from table import print_table, verdict  # noqa: E402
from watchers import USERDATA, Watched, load_original, smach_ros_cost  # noqa: E402

TRANSITIONS = 20_000  # per run, for each machine (the nested one counts steps)
COUNTED = 10_000  # transitions of a run under callgrind
SLOWED = 50  # callgrind runs about this many times slower: what batches by time waits as much longer
WORKLOADS = {"two-state loop": runtime.two_state_loop, "3-level nested": runtime.nested_machine}


def machine_run(smach: Any, factory: Callable, watcher: str, server: ServerThread | None,
                slowed: int = 1) -> tuple[Callable, Watched | None]:
    """A fresh machine's run, watched by ``watcher`` ("bare", "smach_ros", "fsmscope" or "noop"), and the watch to close."""
    machine, run = factory(smach, dict(USERDATA))
    watch = None
    if watcher == "smach_ros":
        smach_ros_cost(machine)
    elif watcher == "fsmscope":
        watch = Watched(server, slowed)
        watch.attach(machine)
    elif watcher == "noop":  # fsmscope's hooks alone, a no-op observer: what --once counts of them
        fsm.attach(machine, lambda event: None)
    return run, watch


def rate(smach: Any, factory: Callable, watcher: str, server: ServerThread, runs: int) -> float:
    """Median transitions (or steps) per second of ``runs`` runs of a fresh machine."""
    rates = []
    for _ in range(runs):
        run, watch = machine_run(smach, factory, watcher, server)
        start = time.perf_counter()
        count = run()
        rates.append(count / (time.perf_counter() - start))
        if watch is not None:
            watch.close()
    return statistics.median(rates)


def run_once(smach_name: str, workload: str, watcher: str, transitions: int) -> None:
    """What callgrind counts: the server (for fsmscope), a warm-up run of the watched machine, then a run of
    ``transitions`` (the warm-up's instructions are in the runs of ``transitions`` and of none alike).
    The recorder's flush, the delivery's batches and the loop's drain wait ``SLOWED`` times longer, so
    that they take batches as full as at full speed."""
    smach = load_original("bench/original_smach.py") if smach_name == "smach" else fsm
    quiet = lambda msg: None  # noqa: E731
    smach.set_loggers(quiet, quiet, quiet, quiet)
    fanout.DRAIN_INTERVAL *= SLOWED
    delivery.INTERVAL *= SLOWED
    server = ServerThread().start() if watcher == "fsmscope" else None
    runtime.LOOP_TRANSITIONS = runtime.NESTED_STEPS = 640
    run, watch = machine_run(smach, WORKLOADS[workload], watcher, server, SLOWED)
    run()
    runtime.LOOP_TRANSITIONS = runtime.NESTED_STEPS = transitions
    if transitions:
        run()
    if watch is not None:
        watch.close()
        server.stop()


def instructions(case: tuple[str, str, str]) -> float:
    """Instructions per transition of ``case`` (smach, workload, watcher) under callgrind."""
    def count(transitions: int) -> int:
        out = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", sys.executable,
                              __file__, "--once", *case, str(transitions)],
                             cwd=ROOT, capture_output=True, text=True, check=True).stderr
        return int(re.search(r"Collected : (\d+)", out).group(1))
    return (count(COUNTED) - count(0)) / COUNTED


def instruction_rows() -> list[tuple[str, str, str, str]]:
    """Instructions per transition of each machine bare and watched, and the watchers' costs: the
    table's rows (two cases counted at a time, one per core)."""
    if shutil.which("valgrind") is None:
        return [("instructions per transition (valgrind is not installed)", "", "-", verdict(None))]
    cases = [(smach, workload, watcher) for workload in WORKLOADS
             for smach, watcher in (("smach", "bare"), ("smach", "smach_ros"), ("smach", "fsmscope"),
                                    ("fsm", "bare"), ("fsm", "fsmscope"))]
    with ThreadPoolExecutor(2) as pool:
        counted = dict(zip(cases, pool.map(instructions, cases)))
    rows = []
    for workload in WORKLOADS:
        smach_bare, fsm_bare = counted[("smach", workload, "bare")], counted[("fsm", workload, "bare")]
        ros = counted[("smach", workload, "smach_ros")] - smach_bare
        watched_smach = counted[("smach", workload, "fsmscope")] - smach_bare
        watched_fsm = counted[("fsm", workload, "fsmscope")] - fsm_bare
        rows += [
            ("%s: instructions, original smach / fsm, bare" % workload, "-", "%.0f / %.0f" % (smach_bare, fsm_bare), ""),
            ("%s: instructions smach_ros's IntrospectionServer adds" % workload, "-", "+%.0f" % ros, ""),
            ("%s: instructions fsmscope adds watching smach" % workload, "<= smach_ros's",
             "+%.0f (x%.2f of smach_ros's)" % (watched_smach, watched_smach / ros), verdict(watched_smach <= ros)),
            ("%s: instructions fsmscope adds watching fsm" % workload, "-",
             "+%.0f (x%.2f of smach_ros's)" % (watched_fsm, watched_fsm / ros), ""),
        ]
    return rows


def cost_us(bare: float, watched: float) -> float:
    """Microseconds a watcher adds per transition."""
    return 1e6 * (1 / watched - 1 / bare)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--instructions", action="store_true", help="also count instructions under callgrind (minutes)")
    parser.add_argument("--once", nargs=4, metavar=("SMACH", "WORKLOAD", "WATCHER", "TRANSITIONS"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.once:
        run_once(*args.once[:3], int(args.once[3]))
        return
    original = load_original("bench/original_smach.py")
    runtime.LOOP_TRANSITIONS = runtime.NESTED_STEPS = TRANSITIONS
    quiet = lambda msg: None  # noqa: E731  (loggers off on both, as bench/runtime.py measures)
    for smach in (original, fsm):
        smach.set_loggers(quiet, quiet, quiet, quiet)
    server = ServerThread().start()
    rows = []
    try:
        for workload, factory in WORKLOADS.items():
            bare = {name: rate(smach, factory, "bare", server, args.runs) for name, smach in
                    (("smach", original), ("fsm", fsm))}
            ros = cost_us(bare["smach"], rate(original, factory, "smach_ros", server, args.runs))
            watched = cost_us(bare["smach"], rate(original, factory, "fsmscope", server, args.runs))
            fsm_watched = cost_us(bare["fsm"], rate(fsm, factory, "fsmscope", server, args.runs))
            rows += [
                ("%s: original smach, bare" % workload, "-", "%s/s" % f"{bare['smach']:,.0f}", ""),
                ("%s: fsm, bare" % workload, "-", "%s/s (x%.2f of smach)" % (f"{bare['fsm']:,.0f}", bare["fsm"] / bare["smach"]), ""),
                ("%s: smach_ros's IntrospectionServer on smach" % workload, "-", "+%.1f us/transition" % ros, ""),
                ("%s: fsmscope watching smach" % workload, "<= smach_ros's", "+%.1f us/transition (x%.2f of smach_ros's)"
                 % (watched, watched / ros), verdict(watched <= ros)),
                ("%s: fsmscope watching fsm" % workload, "-", "+%.1f us/transition (x%.2f of smach_ros's)"
                 % (fsm_watched, fsm_watched / ros), ""),
            ]
    finally:
        server.stop()
    if args.instructions:
        rows += instruction_rows()
    print_table("Watching the original smach (userdata: count, a pose, a name; medians of %d runs of %d)"
                % (args.runs, TRANSITIONS), rows)


if __name__ == "__main__":
    main()
