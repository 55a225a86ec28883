"""A real ROS 1 robot (tests/robots/ros1_robot.py: the original SMACH with smach_ros on rospy, a real
rosmaster) watched by fsmscope's IntrospectionServer: a message on /sm_stop sent with the real
``rostopic pub`` ends its patrol, the dashboard sees the MonitorState's outcome as what ended it and
the rounds its userdata counted, and the run's recording replays as the robot's own console printed it."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import pytest
from fsmscope.server.testing.polling import wait_for

from recording_support import cli
from ros1_support import Robot, logged_lines, rospy_lines


@dataclass
class Run:
    outcome: str
    events: list[dict]  # the transitions and terminations the dashboard served while the robot lived
    userdata: dict  # {container path: its userdata} as the dashboard showed it at the end
    console: str  # all the robot printed
    recording: Path


@pytest.fixture(scope="module")
def stopped(ros) -> Run:
    """One run of the robot, ended by ``rostopic pub -1 /sm_stop std_msgs/Empty`` once SCAN has been
    retried; the robot is stopped (SIGINT) after its dashboard was read."""
    recording = ros.home / "stopped.jsonl"
    robot: Robot = ros.robot("ros1_robot.py", str(recording))
    try:
        wait_for(lambda: "'RETRY':'again'-->'SCAN'" in robot.output, 30, interval=0.05,
                 what=lambda: "the robot to retry a scan:\n" + robot.output)
        # `pub -1` latches the message and waits 3 s for subscribers before it exits: the run goes on meanwhile.
        publisher = ros.rostopic("pub", "-1", "/sm_stop", "std_msgs/Empty")
        outcome = robot.outcome()
        with robot.api() as api:
            answer = api.get("/api/machines/robot/history", params={"kinds": "transition,terminate", "limit": 10000})
            assert answer.status_code == 200, answer.text
            status = api.get("/api/machines/robot/status").json()
    finally:
        robot.stop()
    published = publisher.communicate(timeout=30)[0]
    assert publisher.returncode == 0, published
    userdata = {path: container["userdata"] for path, container in status["containers"].items()}
    return Run(outcome, answer.json()["events"], userdata, robot.output, recording)


def test_a_message_on_sm_stop_from_rostopic_ends_the_patrol_through_the_monitor_state(stopped):
    assert stopped.outcome == "stopped"
    patrol = [e for e in stopped.events if e["path"] == "/SM_ROOT/PATROL"]
    first_to_finish = next(e for e in patrol if e["kind"] == "transition")
    assert (first_to_finish["from"], first_to_finish["outcome"]) == ("MONITOR_STOP", "invalid")
    assert (patrol[-1]["kind"], patrol[-1]["outcome"], patrol[-1]["outcomes"]) == (
        "terminate", "stopped", {"MONITOR_STOP": "invalid", "WORK": "preempted"})
    top = [(e["kind"], e.get("from"), e["outcome"], e.get("to")) for e in stopped.events if e["path"] == "/SM_ROOT"]
    assert top == [("transition", "PATROL", "stopped", "DOCK"), ("terminate", None, "stopped", None)]


def test_the_dashboard_shows_the_rounds_the_robots_userdata_counted(stopped):
    rounds = stopped.console.count("'MOVE':'arrived'-->'SCAN'")
    assert rounds >= 1
    assert [stopped.userdata[path]["rounds"] for path in ("/SM_ROOT", "/SM_ROOT/PATROL", "/SM_ROOT/PATROL/WORK")] == [
        rounds] * 3


# A line of `fsmscope replay --no-time`: PATH [ LEVEL ] : MESSAGE (fsm/logfiles/transcript.py).
TRANSCRIPT_LINE = re.compile(r"^\S+ \[ *(INFO|WARN|ERROR|DEBUG) *\] : (.*)$")


def test_the_recording_replays_as_the_robots_console_printed_the_run(stopped):
    replayed = cli("replay", stopped.recording, "--no-time")
    assert replayed.returncode == 0, replayed.stdout + replayed.stderr
    # rospy prints INFO and above by default: SMACH's debug lines are in the transcript, not on the console.
    transcript = [line for line in logged_lines(replayed.stdout, TRANSCRIPT_LINE) if line[0] != "debug"]
    console = rospy_lines(stopped.console)
    assert len(console) > 10 and any("'RETRY':'again'-->'SCAN'" in message for _, message in console)
    assert transcript == console
