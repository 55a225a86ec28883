"""`fsmscope serve --zenoh` in a real process follows a robot's machine published on Zenoh (a real
session on the loopback): the machine appears in /api/machines with the robot's state, and is shown
disconnected when the robot leaves."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys

import fsm
import httpx
import pytest
from fleet_support import free_endpoint, slow_loop

from fleet.robot import ZenohRobot
from fleet.watcher import FleetWatcher
from fsm.logfiles.log_reader import read_events
from server.cli.demo import MACHINE_NAME
from server.testing.polling import wait_for

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_a_robot_machine_appears_in_the_dashboard_and_is_shown_gone_when_it_leaves():
    fsm.set_loggers(*(lambda msg: None,) * 4)
    endpoint = free_endpoint()
    proc = subprocess.Popen([sys.executable, "-m", "server.cli", "serve", "--port", "0", "--zenoh",
                             "--zenoh-listen", endpoint], cwd=ROOT, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    try:
        for line in proc.stderr:
            found = re.search(r"serving the dashboard at (http://\S+)", line)
            if found:
                break
        url = found.group(1)
        base, token = url.split("/?token=")
        machines = lambda: {m["name"]: m for m in httpx.get(base + "/api/machines", params={"token": token}).json()}
        robot = ZenohRobot("r1", connect=[endpoint])
        own = []
        sm = slow_loop(40)
        fsm.attach(sm, robot, name="loop")
        fsm.attach(sm, own.append)
        sm.execute()
        robot.flush()
        wait_for(lambda: machines().get("r1:loop", {}).get("last_seq") == own[-1]["seq"], 15,
                 what=lambda: "r1:loop at seq %d: %r" % (own[-1]["seq"], machines()))
        assert machines()["r1:loop"]["connected"] is True
        robot.close()
        wait_for(lambda: machines()["r1:loop"]["connected"] is False, 15, what="r1:loop shown gone")
    finally:
        os.killpg(proc.pid, signal.SIGINT)
        proc.wait(20)


@pytest.fixture
def watching():
    """(the endpoint a watcher listens on, the events it delivers)."""
    endpoint = free_endpoint()
    seen: list[dict] = []
    watcher = FleetWatcher(seen.append, lambda name, up: None, listen=[endpoint])
    yield endpoint, seen
    watcher.close()


def published(command: list[str], log, endpoint: str) -> int:
    """Run ``fsmscope COMMAND`` publishing on Zenoh to ``endpoint`` and recording to ``log``; the seq of
    the last event it recorded."""
    done = subprocess.run([sys.executable, "-m", "server.cli", *command, "--record", str(log), "--zenoh-connect",
                           endpoint], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return max(e["seq"] for e in read_events(str(log)) if e["kind"] != "snapshot")


def test_the_demo_published_with_zenoh_reaches_a_dashboard_to_its_last_event(tmp_path, watching):
    endpoint, seen = watching
    last = published(["demo", "--headless", "--episodes", "1", "--fast", "--zenoh", "lab1"], tmp_path / "demo.jsonl",
                     endpoint)
    wait_for(lambda: seen and seen[-1]["seq"] == last, 10, what="the demo's last event")
    assert {e["machine"] for e in seen} == {"lab1:" + MACHINE_NAME}


SCRIPT = """
import time
import fsm
sm = fsm.StateMachine(["done"])
with sm:
    fsm.StateMachine.add("A", fsm.CBState(lambda ud: time.sleep(0.01) or "go", outcomes=["go"]), {"go": "B"})
    fsm.StateMachine.add("B", fsm.CBState(lambda ud: time.sleep(0.01) or "go", outcomes=["go"]), {"go": "done"})
sm.execute()
"""


def test_a_script_run_with_zenoh_reaches_a_dashboard_as_the_robots_machine(tmp_path, watching):
    endpoint, seen = watching
    script = tmp_path / "pick.py"
    script.write_text(SCRIPT)
    last = published(["run", str(script), "--no-serve", "--zenoh", "arm2"], tmp_path / "pick.jsonl", endpoint)
    wait_for(lambda: seen and seen[-1]["seq"] == last, 10, what="the run's last event")
    assert {e["machine"] for e in seen} == {"arm2:pick"}
