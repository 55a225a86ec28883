"""What publishing a machine on Zenoh costs it (issue 13): the two-state loop (bench/runtime.py) with
the dashboard's hub attached (a real uvicorn serving it), against the same with a
``fleet.robot.ZenohRobot`` attached too: with nobody listening, and with a dashboard's watcher
following it from another process (loopback, explicit tcp endpoint). Target: <= 10 % fewer
transitions/s. Medians of 5 runs.

    .venv/bin/python bench/fleet_cost.py [--runs 5]
"""

import argparse
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, ROOT)

import fsm  # noqa: E402
from fleet.robot import ZenohRobot  # noqa: E402
from runtime import two_state_loop  # noqa: E402
from server.cli.fleet_bridge import robot_follows  # noqa: E402
from server.http_server import ServerThread  # noqa: E402
from server.testing.demo_process import free_endpoint  # noqa: E402
from table import print_table, verdict  # noqa: E402

WATCHER = """
import sys, threading
from fleet.watcher import FleetWatcher
seen = [0]
def count(events):
    seen[0] += len(events)
FleetWatcher(count, lambda name, up: None, listen=[sys.argv[1]])
print("listening", flush=True)
threading.Event().wait()
"""


def rate(srv: ServerThread, robot: ZenohRobot | None) -> float:
    """Transitions/s of one run of the loop, served by ``srv`` and published by ``robot`` (if any)."""
    sm, run = two_state_loop()
    entry = srv.hub.add_local(sm, name="loop-%d" % time.monotonic_ns())
    if robot is not None:  # as `fsmscope run --zenoh` composes them (server/cli/fleet_bridge.py)
        fsm.attach(sm, robot)
        robot_follows(robot, entry)
    start = time.perf_counter()
    count = run()
    elapsed = time.perf_counter() - start
    if robot is not None:
        robot.flush(30)
    return count / elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    fsm.set_loggers(*[lambda msg: None] * 4)
    srv = ServerThread().start()
    endpoint = free_endpoint()
    watcher = subprocess.Popen([sys.executable, "-c", WATCHER, endpoint], cwd=ROOT, stdout=subprocess.PIPE, text=True,
                               env=dict(os.environ, PYTHONPATH=ROOT))
    try:
        watcher.stdout.readline()
        alone = ZenohRobot("bench")  # nobody listens to it
        watched = ZenohRobot("bench2", connect=[endpoint])
        base, quiet, followed = [], [], []
        for _ in range(args.runs):
            base.append(rate(srv, None))
            quiet.append(rate(srv, alone))
            followed.append(rate(srv, watched))
        alone.close()
        watched.close()
    finally:
        watcher.kill()
        srv.stop()
    b, q, f = (statistics.median(x) for x in (base, quiet, followed))
    print_table("Publishing the two-state loop on Zenoh (medians of %d runs)" % args.runs, [
        ("the loop with the hub attached (served)", "", "%.0f transitions/s" % b, verdict(None)),
        ("  + ZenohRobot, nobody listening", "<= 10 % fewer", "%.0f (%+.1f %%)" % (q, 100 * (q / b - 1)),
         verdict(q >= 0.9 * b)),
        ("  + ZenohRobot, a dashboard's watcher following (another process)", "<= 10 % fewer",
         "%.0f (%+.1f %%)" % (f, 100 * (f / b - 1)), verdict(f >= 0.9 * b)),
    ])


if __name__ == "__main__":
    main()
