"""`fsmscope serve --zenoh` in a real process follows a robot's machine published on Zenoh (a real
session on the loopback): the machine appears in /api/machines with the robot's state, is shown
disconnected when the robot leaves, shows every event the robot recorded even across a network cut,
and takes the dashboard's controls when it holds the robot's token."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import fsm
import pytest
import zenoh
from fleet_support import (TOKEN, ROOT, Dashboard, Proxy, Robot, free_endpoint, preempted_the_dashboard_has_the_robots_log,
                           run_published, slow_loop, stop)

from fsmscope.fleet import keys
from fsmscope.fleet.config import session_config
from fsmscope.fleet.robot import ZenohRobot
from fsmscope.fleet.watcher import FleetWatcher
from fsm.logfiles.log_reader import read_events
from fsmscope.server.cli.demo import MACHINE_NAME
from fsmscope.server.testing.polling import wait_for


@pytest.fixture
def dashboard_with():
    """A dashboard started with these options; stopped after the test."""
    started: list[Dashboard] = []

    def start(*options: str) -> Dashboard:
        started.append(Dashboard(*options))
        return started[-1]

    yield start
    for dash in started:
        dash.stop()


@pytest.fixture
def patrolling(dashboard_with, tmp_path):
    """(a dashboard, the proxy between it and robot r1, r1): r1's patrol seen running."""
    dash = dashboard_with("--zenoh-token", TOKEN)
    proxy = Proxy(dash.endpoint)
    robot = Robot("r1", proxy.endpoint, TOKEN, tmp_path / "r1.jsonl")
    try:
        wait_for(lambda: dash.machines().get("r1:patrol", {}).get("running"), 20, what="r1:patrol running")
        yield dash, proxy, robot
    finally:
        robot.stop()
        proxy.close()


def test_a_robot_process_cut_off_and_back_leaves_no_gap_in_the_dashboard(patrolling):
    dash, proxy, robot = patrolling
    first = dash.machines()["r1:patrol"]["last_seq"]
    proxy.cut()
    time.sleep(4.0)  # past the link's lease: the dashboard sees the robot gone, and it runs on unseen
    assert dash.machines()["r1:patrol"]["connected"] is False
    proxy.restore()
    wait_for(lambda: dash.machines()["r1:patrol"]["connected"], 20, what="r1:patrol back")
    preempted_the_dashboard_has_the_robots_log(dash, robot, first + 1)


def test_a_dashboard_restarted_shows_the_robots_whole_run_and_controls_it(patrolling, dashboard_with):
    first, proxy, robot = patrolling
    second = dashboard_with("--zenoh-token", TOKEN)
    proxy.point_to(second.endpoint)  # the robot's link, when it comes back, reaches the new dashboard
    proxy.cut()
    first.stop()
    proxy.restore()
    wait_for(lambda: second.machines().get("r1:patrol", {}).get("running"), 20, what="r1:patrol on the new one")
    preempted_the_dashboard_has_the_robots_log(second, robot, 1)


def test_a_robot_machine_appears_in_the_dashboard_and_is_shown_gone_when_it_leaves(dashboard_with):
    fsm.set_loggers(*(lambda msg: None,) * 4)
    dash = dashboard_with("--zenoh-token", TOKEN)
    robot = ZenohRobot("r1", connect=[dash.endpoint], token=TOKEN)
    own = []
    sm = slow_loop(40)
    fsm.attach(sm, robot, name="loop")
    fsm.attach(sm, own.append)
    sm.execute()
    robot.flush()
    wait_for(lambda: dash.machines().get("r1:loop", {}).get("last_seq") == own[-1]["seq"], 15,
             what=lambda: "r1:loop at seq %d: %r" % (own[-1]["seq"], dash.machines()))
    assert dash.machines()["r1:loop"]["connected"] is True
    robot.close()
    wait_for(lambda: dash.machines()["r1:loop"]["connected"] is False, 15, what="r1:loop shown gone")


def running_robot(endpoint: str, token: str):
    """Robot r1 with token ``token``, its machine "loop" running until preempted: (robot, its events, thread)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    robot = ZenohRobot("r1", connect=[endpoint], token=token)
    own, runner = run_published(robot, slow_loop(100_000, 0.02))
    return robot, own, runner


def test_a_preempt_asked_of_the_dashboard_ends_the_run_on_the_robot(dashboard_with):
    dash = dashboard_with("--zenoh-token", "r1=secret")
    robot, own, runner = running_robot(dash.endpoint, "secret")
    try:
        wait_for(lambda: dash.machines().get("r1:loop", {}).get("controllable"), 15, what="r1:loop controllable")
        answer = dash.post("/api/machines/r1:loop/preempt", {"reason": "from the dashboard"})
        assert answer.status_code == 202, answer.text
        runner.join(10)
        assert [(e["action"], e["result"], e["seq"]) for e in own if e["kind"] == "control"] == [
            ("preempt", "accepted", answer.json()["seq"])]
        wait_for(lambda: not dash.machines()["r1:loop"]["running"], 15, what="the run shown ended")
    finally:
        robot.close()


def test_a_dashboard_with_the_wrong_token_neither_shows_nor_controls_the_robots_machine(dashboard_with):
    dash = dashboard_with("--zenoh-token", "r1=guess")
    robot, own, runner = running_robot(dash.endpoint, "secret")
    try:
        wait_for(lambda: len(own) > 20, 15, what="r1:loop running")
        time.sleep(1.0)  # what the dashboard would have shown by now
        assert "r1:loop" not in dash.machines()
        assert dash.post("/api/machines/r1:loop/preempt", {}).status_code == 404
        assert runner.is_alive()
    finally:
        robot.controls.handles["loop"].preempt(None, "test")
        runner.join(10)
        robot.close()


@pytest.fixture
def watching():
    """(the endpoint a watcher listens on, the events it delivers)."""
    endpoint = free_endpoint()
    seen: list[dict] = []
    watcher = FleetWatcher(seen.extend, lambda name, up: None, listen=[endpoint], tokens={None: TOKEN})
    yield endpoint, seen
    watcher.close()


def published(command: list[str], log, endpoint: str) -> int:
    """Run ``fsmscope COMMAND`` publishing on Zenoh to ``endpoint`` and recording to ``log``; the seq of
    the last event it recorded."""
    done = subprocess.run([sys.executable, "-m", "fsmscope", *command, "--record", str(log), "--zenoh-connect",
                           endpoint, "--zenoh-token", TOKEN], cwd=ROOT, capture_output=True, text=True, timeout=120)
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


@pytest.mark.parametrize("serving", [["--no-serve"], ["--exit"]],
                         ids=["the robot observes the machine", "the robot follows the served dashboard's hub"])
def test_a_script_run_with_zenoh_reaches_a_dashboard_as_the_robots_machine(tmp_path, watching, serving):
    endpoint, seen = watching
    script = tmp_path / "pick.py"
    script.write_text(SCRIPT)
    last = published(["run", str(script), *serving, "--zenoh", "arm2"], tmp_path / "pick.jsonl", endpoint)
    wait_for(lambda: seen and seen[-1]["seq"] == last, 10, what="the run's last event")
    assert {e["machine"] for e in seen} == {"arm2:pick"}


EPISODES = ROOT / "tests" / "robots" / "episodes.py"


def test_a_robot_that_builds_a_machine_per_episode_publishes_every_one_of_them(tmp_path, watching):
    endpoint, seen = watching
    stderr = tmp_path / "robot.err"
    with open(stderr, "w") as err:
        robot = subprocess.Popen([sys.executable, "-m", "fsmscope", "run", str(EPISODES), "--no-serve", "--record",
                                  str(tmp_path / "r1.jsonl"), "--zenoh", "r1", "--zenoh-connect", endpoint,
                                  "--zenoh-token", TOKEN], cwd=ROOT, stderr=err, start_new_session=True)
    names = ["r1:episodes"] + ["r1:episodes-%d" % i for i in range(2, 11)]
    try:
        wait_for(lambda: {e["machine"] for e in seen if e["kind"] == "terminate" and e["outcome"] == "done"
                          and e["path"] == "/SM_ROOT"} == set(names), 30,
                 what=lambda: "ten machines ended, seen: %s" % sorted({e["machine"] for e in seen}))
    finally:
        stop(robot)
    recorded = list(read_events(str(tmp_path / "r1.jsonl")))
    for name in names:
        assert [e["seq"] for e in seen if e["machine"] == name] == [
            e["seq"] for e in recorded if "r1:" + e["machine"] == name and e["kind"] != "snapshot"], name
    assert "an observer" not in stderr.read_text()


def test_a_script_that_never_closes_its_robot_still_exits(tmp_path):
    script = tmp_path / "forgetful.py"
    script.write_text(SCRIPT.replace("import fsm\n", "import fsm\nfrom fsmscope.fleet.robot import ZenohRobot\n")
                      .replace("sm.execute()", "fsm.attach(sm, ZenohRobot('r1'), name='pick')\nsm.execute()"))
    done = subprocess.run([sys.executable, str(script)], cwd=ROOT, capture_output=True, text=True, timeout=30,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr


def test_a_strangers_answer_to_a_control_is_not_what_the_dashboard_answers(dashboard_with):
    dash = dashboard_with("--zenoh-token", TOKEN)
    robot, own, runner = running_robot(dash.endpoint, TOKEN)
    stranger = zenoh.open(session_config(connect=[dash.endpoint]))
    try:
        wait_for(lambda: dash.machines().get("r1:loop", {}).get("controllable"), 15, what="r1:loop controllable")
        cut_off = robot._machines["loop"]  # the robot's controls cut off: only the stranger answers
        cut_off.control.undeclare()
        cut_off.control = robot.session.declare_queryable(keys.control_key("r1", "loop"), lambda query: query.drop())
        forged = stranger.declare_queryable(keys.control_key("r1", "loop"), complete=True, handler=lambda query: (
            query.reply(query.key_expr, b'{"status": 202, "seq": 1}'), query.drop()))
        answer = dash.post("/api/machines/r1:loop/preempt", {})
        assert answer.status_code == 504 and "no authenticated answer from robot 'r1'" in answer.json()["detail"]
        assert runner.is_alive() and not [e for e in own if e["kind"] == "control"]
        forged.undeclare()
    finally:
        stranger.close()
        robot.controls.handles["loop"].preempt(None, "test")
        runner.join(10)
        robot.close()
