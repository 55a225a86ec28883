"""What publishing a machine on Zenoh costs it (issue 13): the two-state loop (bench/runtime.py) with
the dashboard's hub attached (a real uvicorn serving it), against the same with a
``fleet.robot.ZenohRobot`` following it as ``fsmscope run --zenoh`` composes them: with nobody
listening, and with a dashboard's watcher following it from another process (loopback, explicit tcp
endpoint). Target: <= 10 % fewer transitions/s. Each round runs every case once, one after the
other; the table gives the medians over the rounds of each case's rate against the round's
baseline (the rate of this shared machine drifts more between rounds than within one).

The watcher shares this machine's two cores with the loop: a last case runs the loop beside a
process that only burns as much CPU as the watcher took, without Zenoh, to tell that apart.

The speed of one core of this machine drifts by half between runs of seconds, so the rates are
backed by a count that does not: the instructions a transition costs (valgrind's callgrind, which
counts the work of every thread of the loop's process), without the robot, with it and nobody
listening, and with it and the watcher following, of runs of ``COUNTED`` transitions less those of
an empty run. The watcher's own work, in its process, is not counted: on a robot it runs elsewhere.

    .venv/bin/python bench/fleet_cost.py [--runs 16] [--no-instructions]
"""

import argparse
import gc
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
from typing import Callable

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, ROOT)

import fsmscope.fleet.robot  # noqa: E402
import fsm  # noqa: E402
import runtime  # noqa: E402
from fsmscope.fleet.robot import ZenohRobot  # noqa: E402
from runtime import two_state_loop  # noqa: E402
from fsmscope.server.cli.zenoh_options import robot_follows  # noqa: E402
from fsmscope.server.http_server import ServerThread  # noqa: E402
from fsmscope.server.testing.demo_process import free_endpoint  # noqa: E402
from table import print_table, verdict  # noqa: E402

BURNER = """
import sys, time
duty = float(sys.argv[1])
print("burning", flush=True)
while True:
    start = time.perf_counter()
    while time.perf_counter() - start < 0.01 * duty:
        pass
    time.sleep(0.01 * (1 - duty))
"""

WATCHER = """
import sys, threading
from fsmscope.fleet.watcher import FleetWatcher
seen = [0]
def count(events):
    seen[0] += len(events)
FleetWatcher(count, lambda name, up: None, listen=[sys.argv[1]], tokens={None: "bench"})
print("listening", flush=True)
threading.Event().wait()
"""


WARM_UP = 2_000  # transitions run first, untimed: a watcher joins the new machine meanwhile
JOINING = 1.0  # s given to the watcher to join (ask the machine's state and its history, once)


def prepared(srv: ServerThread, robot: ZenohRobot | None, joining: float = JOINING) -> Callable[[], int]:
    """A new two-state loop served by ``srv`` and published by ``robot`` (if any), warmed up: its
    ``run``. Each round's machine is a new one, and a watcher following the robot joins it (asks its
    state and the history the robot keeps, once), as a dashboard does once per machine: that is done
    here, in every case alike, so that the timed run is that of a machine being followed."""
    sm, run = two_state_loop()
    entry = srv.hub.add_local(sm, name="loop-%d" % time.monotonic_ns())
    if robot is not None:  # as `fsmscope run --zenoh` composes them (fsmscope/server/cli/fleet_bridge.py)
        robot_follows(robot, entry)
    timed, runtime.LOOP_TRANSITIONS = runtime.LOOP_TRANSITIONS, WARM_UP
    try:
        run()
    finally:
        runtime.LOOP_TRANSITIONS = timed
    if robot is not None:
        robot.flush()
    time.sleep(joining)
    return run


def timed_rate(run: Callable[[], int], robot: ZenohRobot | None) -> float:
    """Transitions/s of one run of a ``prepared`` loop."""
    start = time.perf_counter()
    count = run()
    elapsed = time.perf_counter() - start
    if robot is not None:
        robot.flush()
    return count / elapsed


def rate(srv: ServerThread, robot: ZenohRobot | None, joining: float = JOINING) -> float:
    """Transitions/s of a new loop, warmed up, published by ``robot`` (if any)."""
    return timed_rate(prepared(srv, robot, joining), robot)


def followed_rate(srv: ServerThread, robot: ZenohRobot, watcher: subprocess.Popen, cpu: list[float]) -> float:
    """``rate`` with the watcher following: the share of a core it took during the timed run goes to ``cpu``."""
    run = prepared(srv, robot)
    before, start = cpu_seconds(watcher.pid), time.perf_counter()
    result = timed_rate(run, robot)
    cpu.append((cpu_seconds(watcher.pid) - before) / (time.perf_counter() - start))
    return result


def burnt_rate(srv: ServerThread, share: float) -> float:
    """``rate`` without a robot, beside a process burning ``share`` of a core."""
    burner = spawn(BURNER, str(min(1.0, share)))
    try:
        return rate(srv, None)
    finally:
        burner.kill()
        burner.wait()


COUNTED = 20_000  # transitions of a run under callgrind (about 50 times slower)


def loop_once(case: str, transitions: int, endpoint: str) -> None:
    """One run of the loop with the hub, and the robot if the case has one ("quiet": nobody listens;
    "followed": a watcher listening at ``endpoint`` follows it): what callgrind counts (the warm-up's
    instructions, and the watcher's join, are in the runs of ``transitions`` and of none alike)."""
    runtime.LOOP_TRANSITIONS = transitions
    fsmscope.fleet.robot.LINGER = 1.0  # callgrind slows the loop: batches as full as at full speed (MAX_BATCH)
    fsm.set_loggers(*[lambda msg: None] * 4)
    srv = ServerThread().start()
    make = {"base": None, "quiet": lambda: ZenohRobot("bench", token="bench"),
            "followed": lambda: ZenohRobot("bench", connect=[endpoint], token="bench")}[case]
    robot = make() if make else None
    rate(srv, robot, joining=10.0)  # the join's answers, slowed too, are over before the timed run
    if robot is not None:
        robot.close()
    srv.stop()


def instructions(case: str, transitions: int, endpoint: str) -> int:
    """The instructions of a process running ``loop_once`` (every thread's, start-up included; not
    the watcher's, which runs in a process of its own)."""
    out = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", sys.executable,
                          __file__, "--once", case, str(transitions), endpoint],
                         cwd=ROOT, capture_output=True, text=True, check=True).stderr
    return int(re.search(r"Collected : (\d+)", out).group(1))


def instruction_rows(endpoint: str) -> list[tuple[str, str, str, str]]:
    """Instructions per transition without the robot, with it and nobody listening, and with the
    watcher listening at ``endpoint`` following it: the table's rows. Counted, they do not depend on
    what else runs on the two cores, as the rates do."""
    if shutil.which("valgrind") is None:
        return [("instructions per transition (valgrind is not installed)", "", "-", verdict(None))]
    per = {case: (instructions(case, COUNTED, endpoint) - instructions(case, 0, endpoint)) / COUNTED
           for case in ("base", "quiet", "followed")}
    rows = [("instructions per transition, the loop with the hub", "", "%.0f" % per["base"], verdict(None))]
    for case, said in (("quiet", "nobody listening"), ("followed", "a dashboard's watcher following")):
        cost = per[case] / per["base"] - 1
        rows.append(("  + ZenohRobot, %s" % said, "<= 10 % more", "%.0f (%+.1f %%)" % (per[case], 100 * cost),
                     verdict(cost <= 0.10)))
    return rows


def cpu_seconds(pid: int) -> float:
    """User and system CPU time of process ``pid`` so far."""
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rpartition(")")[2].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def spawn(code: str, *argv: str) -> subprocess.Popen:
    """A Python process running ``code``, once it printed that it is ready."""
    process = subprocess.Popen([sys.executable, "-c", code, *argv], cwd=ROOT, stdout=subprocess.PIPE, text=True,
                               env=dict(os.environ, PYTHONPATH=ROOT))
    process.stdout.readline()
    return process


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=16)
    parser.add_argument("--no-instructions", action="store_true", help="skip the count under callgrind (minutes)")
    parser.add_argument("--once", nargs=3, metavar=("CASE", "TRANSITIONS", "ENDPOINT"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.once:
        loop_once(args.once[0], int(args.once[1]), args.once[2])
        return
    fsm.set_loggers(*[lambda msg: None] * 4)
    srv = ServerThread().start()
    endpoint = free_endpoint()
    watcher = spawn(WATCHER, endpoint)
    try:
        alone = ZenohRobot("bench", token="bench")  # nobody listens to it
        watched = ZenohRobot("bench2", connect=[endpoint], token="bench")
        cases = {"base": lambda: rate(srv, None), "quiet": lambda: rate(srv, alone),
                 "followed": lambda: followed_rate(srv, watched, watcher, watcher_cpu),
                 "burnt": lambda: burnt_rate(srv, statistics.median(watcher_cpu or [0.25]))}
        ratios: dict[str, list[float]] = {name: [] for name in cases}
        base: list[float] = []
        watcher_cpu: list[float] = []
        for round_ in range(args.runs):
            order = list(cases)[round_ % 4:] + list(cases)[:round_ % 4]  # no case always first
            rates = {}
            for name in order:
                gc.collect()
                rates[name] = cases[name]()
            base.append(rates["base"])
            for name in cases:
                ratios[name].append(rates[name] / rates["base"])
        alone.close()
        watched.close()
        counted = [] if args.no_instructions else instruction_rows(endpoint)
    finally:
        watcher.kill()
        srv.stop()
    q, f, c = (statistics.median(ratios[name]) for name in ("quiet", "followed", "burnt"))
    w = statistics.median(watcher_cpu)
    print_table("Publishing the two-state loop on Zenoh (rate against the round's baseline, medians of %d rounds)"
                % args.runs, [
                    ("the loop with the hub attached (served)", "", "%.0f transitions/s" % statistics.median(base),
                     verdict(None)),
                    ("  + ZenohRobot, nobody listening", "<= 10 % fewer", "%+.1f %%" % (100 * (q - 1)),
                     verdict(q >= 0.9)),
                    ("  + ZenohRobot, a dashboard's watcher following (another process)", "<= 10 % fewer",
                     "%+.1f %%" % (100 * (f - 1)), verdict(f >= 0.9)),
                    ("    the watcher's CPU meanwhile (it shares the machine's 2 cores)", "", "%.0f %% of a core" % (100 * w),
                     verdict(None)),
                    ("  no robot, beside a process burning as much CPU (no Zenoh)", "", "%+.1f %%" % (100 * (c - 1)),
                     verdict(None)),
                    *counted,
                ])


if __name__ == "__main__":
    main()
