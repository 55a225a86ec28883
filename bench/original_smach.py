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

    .venv/bin/python bench/original_smach.py [--runs 5]
"""

from __future__ import annotations

import argparse
import base64
import os
import pickle
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
ORIGINAL_SRC = ROOT.parent / "shared/reference/executive_smach/noetic/smach/src"
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))

import fsm  # noqa: E402
import runtime  # noqa: E402
from fsmscope.server.http_server import ServerThread  # noqa: E402
from table import print_table, verdict  # noqa: E402

USERDATA = {"count": 0, "pose": [0.1 * i for i in range(7)], "name": "pick the red cube"}
TRANSITIONS = 20_000  # per run, for each machine (the nested one counts steps)


def load_original() -> Any:
    """The original smach, imported under its own name from ../shared/reference."""
    if not (ORIGINAL_SRC / "smach" / "__init__.py").exists():
        sys.exit("bench/original_smach.py needs the original SMACH at %s (shared/ beside the project)" % ORIGINAL_SRC)
    sys.path.insert(0, str(ORIGINAL_SRC))
    import smach
    return smach


def containers(machine: Any) -> list:
    """The machine and every container below it."""
    found = [machine]
    for child in machine.get_children().values():
        if hasattr(child, "get_children"):
            found += containers(child)
    return found


def smach_ros_cost(machine: Any) -> None:
    """smach_ros's IntrospectionServer's work in the machine's thread: its ContainerProxy registers a
    start, transition and termination callback on every container, and each one pickles and
    base64-encodes that container's userdata for the status message."""
    for container in containers(machine):
        def status(*args: Any, container: Any = container) -> None:
            base64.b64encode(pickle.dumps(container.userdata._data, 2)).decode("utf-8")
        container.register_start_cb(status)
        container.register_transition_cb(status)
        container.register_termination_cb(status)


class Watched:
    """fsmscope's in-process watch: the recorder and the hub of a real server, attached to a machine."""

    def __init__(self, server: ServerThread) -> None:
        self.server = server
        fd, self.path = tempfile.mkstemp(suffix=".jsonl")
        os.close(fd)
        self.recorder = fsm.Recorder(self.path)
        self.name: str | None = None

    def attach(self, machine: Any) -> None:
        fsm.attach(machine, self.recorder)
        self.name = self.server.hub.add_local(machine, name="bench-%d" % time.monotonic_ns()).name

    def close(self) -> None:
        self.server.hub.remove(self.name)
        self.recorder.close()
        for leftover in (self.path, self.path + ".idx"):
            if os.path.exists(leftover):
                os.unlink(leftover)


def rate(smach: Any, factory: Callable, watcher: str, server: ServerThread, runs: int) -> float:
    """Median transitions (or steps) per second of ``runs`` runs of a fresh machine."""
    rates = []
    for _ in range(runs):
        machine, run = factory(smach, dict(USERDATA))
        watch = None
        if watcher == "smach_ros":
            smach_ros_cost(machine)
        elif watcher == "fsmscope":
            watch = Watched(server)
            watch.attach(machine)
        start = time.perf_counter()
        count = run()
        rates.append(count / (time.perf_counter() - start))
        if watch is not None:
            watch.close()
    return statistics.median(rates)


def cost_us(bare: float, watched: float) -> float:
    """Microseconds a watcher adds per transition."""
    return 1e6 * (1 / watched - 1 / bare)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    original = load_original()
    runtime.LOOP_TRANSITIONS = runtime.NESTED_STEPS = TRANSITIONS
    quiet = lambda msg: None  # noqa: E731  (loggers off on both, as bench/runtime.py measures)
    for smach in (original, fsm):
        smach.set_loggers(quiet, quiet, quiet, quiet)
    server = ServerThread().start()
    rows = []
    try:
        for workload, factory in (("two-state loop", runtime.two_state_loop), ("3-level nested", runtime.nested_machine)):
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
    print_table("Watching the original smach (userdata: count, a pose, a name; medians of %d runs of %d)"
                % (args.runs, TRANSITIONS), rows)


if __name__ == "__main__":
    main()
