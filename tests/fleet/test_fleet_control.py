"""Controls across the network (fsmscope/fleet/control.py), over real Zenoh sessions on the loopback: the
robot's process checks the token itself, applies the control, records it in its own stream, and
answers with the event it caused; nothing without the robot's token controls its machine."""

from __future__ import annotations

import time

import fsm
import pytest
import zenoh
from fleet_support import TOKEN, free_endpoint, run_published, slow_loop

from fsmscope.fleet.config import session_config
from fsmscope.fleet.robot import ZenohRobot
from fsmscope.fleet.watcher import FleetWatcher
from fsmscope.server.testing.polling import wait_for



@pytest.fixture
def fleet():
    """A dashboard's watcher and robot r1 (started with TOKEN) whose machine "loop" runs ticks of 20 ms
    until preempted; yields (watcher, robot, the events of the robot's own stream)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    endpoint = free_endpoint()
    watcher = FleetWatcher(lambda events: None, lambda name, up: None, listen=[endpoint], tokens={None: TOKEN})
    robot = ZenohRobot("r1", connect=[endpoint], token=TOKEN)
    sm = slow_loop(100_000, 0.02)
    own, runner = run_published(robot, sm)
    wait_for(lambda: watcher.controls.get("r1:loop"), 10, what="the robot's machine joined, taking controls")
    try:
        yield watcher, robot, own
    finally:
        sm.request_preempt()
        runner.join(10)
        robot.close()
        watcher.close()


def controls_of(events: list[dict]) -> list[dict]:
    return [e for e in events if e["kind"] == "control"]


def test_a_control_with_the_robots_token_is_applied_recorded_and_answered_with_its_event(fleet):
    watcher, robot, own = fleet
    answer = watcher.ask("r1", "loop", TOKEN, "preempt", {"reason": "from the fleet page"}, "operator")
    assert answer["status"] == 202
    [control] = [e for e in controls_of(own) if e["seq"] == answer["seq"]]
    assert (control["action"], control["result"], control["client"], control["reason"]) == (
        "preempt", "accepted", "operator", "from the fleet page")


def test_a_control_with_a_wrong_token_is_refused_by_the_robot_with_no_authenticated_answer(fleet):
    watcher, robot, own = fleet
    assert watcher.ask("r1", "loop", "not-" + TOKEN, "preempt", {}, "intruder") is None
    assert robot.controls.refused == 1
    assert controls_of(own) == []


def test_a_control_the_machine_refuses_is_answered_with_why(fleet):
    watcher, robot, own = fleet
    answer = watcher.ask("r1", "loop", TOKEN, "start", {}, "operator")
    assert answer["status"] == 409 and "cannot re-run" in answer["detail"]
    assert [(e["action"], e["result"]) for e in controls_of(own)] == [("start", "this process cannot re-run the machine")]


def test_a_robot_started_without_controls_takes_none():
    fsm.set_loggers(*(lambda msg: None,) * 4)
    endpoint = free_endpoint()
    with FleetWatcher(lambda events: None, lambda name, up: None, listen=[endpoint], tokens={None: TOKEN}) as watcher, \
            ZenohRobot("r1", connect=[endpoint], token=TOKEN, controls=False) as robot:
        sm = slow_loop(3, 0.0)
        fsm.attach(sm, robot, name="loop")
        sm.execute()
        robot.flush()
        wait_for(lambda: "r1:loop" in watcher.controls, 10, what="the machine joined")
        assert watcher.controls["r1:loop"] is None  # the dashboard is told: it shows no control
        answer = watcher.ask("r1", "loop", TOKEN, "preempt", {}, "operator")
        assert answer["status"] == 403 and "without controls" in answer["detail"]


def test_a_robot_given_no_token_makes_one_and_says_it(capfd):
    with ZenohRobot("r1", connect=[free_endpoint()]) as robot:
        said = capfd.readouterr().err
    assert len(robot.controls.token) >= 32 and "serve --zenoh-token r1=%s" % robot.controls.token in said


def test_the_robot_applies_the_deadman_when_the_dashboard_holding_the_lease_is_gone(fleet):
    watcher, robot, own = fleet
    lease = {"held": True, "after": 0.3, "action": "preempt", "dashboard": watcher.id}
    assert watcher.ask("r1", "loop", TOKEN, "lease", lease, "operator") == {"status": 200}
    watcher.close()
    wait_for(lambda: any(e["kind"] == "terminate" for e in own), 10, what="the run ended by the deadman")
    assert [(e["action"], e["client"]) for e in controls_of(own)] == [("deadman", "robot"), ("preempt", "robot")]
    [deadman] = [e for e in controls_of(own) if e["action"] == "deadman"]
    assert deadman["params"] == {"after": 0.3, "then": "preempt"} and watcher.id in deadman["reason"]


def test_a_strangers_beats_do_not_keep_a_gone_dashboards_lease():
    fsm.set_loggers(*(lambda msg: None,) * 4)
    endpoint, dashboards = free_endpoint(), free_endpoint()
    robot = ZenohRobot("r1", listen=[endpoint], token=TOKEN)
    watcher = FleetWatcher(lambda events: None, lambda name, up: None, connect=[endpoint], listen=[dashboards],
                           tokens={None: TOKEN})
    stranger = zenoh.open(session_config(connect=[endpoint, dashboards]))  # hears the beats; stays when the dashboard goes
    sm = slow_loop(100_000, 0.02)
    own, runner = run_published(robot, sm)
    wait_for(lambda: watcher.controls.get("r1:loop"), 10, what="the robot's machine joined, taking controls")
    beats: list[tuple[str, bytes, bytes]] = []
    heard = stranger.declare_subscriber("fsmscope-dashboards/**", lambda sample: beats.append(
        (str(sample.key_expr), sample.payload.to_bytes(), sample.attachment.to_bytes())))
    lease = {"held": True, "after": 0.3, "action": "preempt"}
    assert watcher.ask("r1", "loop", TOKEN, "lease", lease, "operator") == {"status": 200}
    wait_for(lambda: len(beats) >= 3, 10, what="the dashboard's beats heard")
    watcher.close()
    heard.undeclare()
    presence = stranger.liveliness().declare_token("fsmscope-dashboards/" + watcher.id)  # what stood for it before
    try:
        gone = time.monotonic()
        while not any(e["kind"] == "terminate" for e in own):  # the beats played again, forged ones between
            assert time.monotonic() - gone < 8, "the deadman did not fire while a stranger played the beats"
            for key, payload, proof in beats:
                stranger.put(key, payload, attachment=proof)
                stranger.put(key, b"999999", attachment=proof)
            time.sleep(0.1)
    finally:
        presence.undeclare()
        stranger.close()
        sm.request_preempt()
        runner.join(10)
        robot.close()
    assert [(e["action"], e["client"]) for e in controls_of(own)] == [("deadman", "robot"), ("preempt", "robot")]
    assert robot.controls.refused >= 10  # the forged beats, said
