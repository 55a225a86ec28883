"""A ROS 2 robot as the ros2 branch makes one (tests/robots/ros2_robot.py: its SMACH core and its own
introspection.py, on a stand-in for rclpy over Cyclone DDS), followed by a real ``fsmscope ros2``
process on the test's private domain, the loopback only: shown live, its next run started where the
dashboard set it, preempted from the dashboard, shown disconnected when killed."""

from __future__ import annotations

import re

import httpx
import pytest
from fsmscope.server.testing.polling import wait_for

from fleet_support import started, stop


class Viewer:
    """``fsmscope ros2 --domain DOMAIN --interface 127.0.0.1``, recording, in a process of its own."""

    def __init__(self, domain: int, recording) -> None:
        self.proc, found = started(["ros2", "--domain", str(domain), "--interface", "127.0.0.1", "--port", "0",
                                    "--record", str(recording)], r"dashboard at (http://\S+)")
        self.base, self.token = found.group(1).split("/?token=")

    def machines(self) -> dict[str, dict]:
        return {m["name"]: m for m in httpx.get(self.base + "/api/machines", params={"token": self.token}).json()}

    def post(self, path: str, body: dict) -> httpx.Response:
        return httpx.post(self.base + path, params={"token": self.token}, json=body, timeout=10)

    def transitions(self, name: str) -> list[tuple]:
        answer = httpx.get(self.base + "/api/machines/%s/history" % name,
                           params={"token": self.token, "kinds": "transition", "limit": 10000})
        return [(e["path"], e["from"], e["outcome"], e["to"]) for e in answer.json()["events"]]


@pytest.fixture
def viewer(domain, tmp_path):
    shown = Viewer(domain, tmp_path / "live.jsonl")
    yield shown
    stop(shown.proc)


def test_the_robots_machine_is_shown_live_with_the_outcomes_its_edges_tell(robots, viewer):
    robots()
    wait_for(lambda: viewer.machines().get("robot", {}).get("running"), 30, interval=0.1, what="the robot's machine")
    wait_for(lambda: ("/SM_ROOT/SUB", "X", "next", "Y") in viewer.transitions("robot"), 30, interval=0.1,
             what=lambda: "SUB's X -> Y: %s" % viewer.transitions("robot"))


def test_set_initial_state_from_the_dashboard_starts_the_robots_next_run_there(robots, viewer):
    robot = robots()
    wait_for(lambda: viewer.machines().get("robot", {}).get("running"), 30, interval=0.1, what="the robot's machine")
    answer = viewer.post("/api/machines/robot/initial-state", {"path": "/SM_ROOT", "states": ["C"], "userdata": {"count": 40}})
    assert answer.status_code in (200, 202), answer.text
    # smach_ros sets the userdata at once (the run going on counts from 40) and the initial state for the next run.
    wait_for(lambda: "starting in initial state 'C'" in robot.output and re.search(r"state: \w+ 4\d\b", robot.output),
             30, interval=0.1, what=lambda: "a count from 40 and a run that starts at C:\n" + robot.output)


def test_preempt_from_the_dashboard_reaches_the_robots_stop_topic(robots, viewer):
    robot = robots()
    wait_for(lambda: viewer.machines().get("robot", {}).get("running"), 30, interval=0.1, what="the robot's machine")
    answer = viewer.post("/api/machines/robot/preempt", {"reason": "test"})
    assert answer.status_code == 202, answer.text
    robot.wait_for_line("outcome: preempted", 20)


def test_a_robot_killed_shows_disconnected(robots, viewer):
    robot = robots()
    wait_for(lambda: viewer.machines().get("robot", {}).get("running"), 30, interval=0.1, what="the robot's machine")
    robot.kill()
    wait_for(lambda: viewer.machines()["robot"]["connected"] is False, 20, interval=0.1, what="the robot gone")
