"""Bad input from a live ROS 1 graph (a real rosmaster; fsmscope's own ROS 1 node publishing as a
hostile or careless node would): the watcher (fsmscope/interop/ros_watcher.py) runs nothing it is
sent, follows nothing that only has a SMACH name, keeps going when the master goes away, and
``fsmscope serve --ros1`` shows a robot's machine beside the others."""

from __future__ import annotations

import base64
import os
import pickle
import threading

import pytest
from fsmscope.interop.ros_watcher import ROS1, RosWatcher
from fsmscope.ros1 import Node
from fsmscope.server.testing.polling import wait_for

from fleet_support import started, stop
from recording_support import cli
from ros1_support import READY


class Planted:
    """A pickle that would create ``path`` if it were unpickled by Python's unpickler."""

    def __init__(self, path: str) -> None:
        self.path = path

    def __reduce__(self):
        return os.system, ("touch %s" % self.path,)


class Watched:
    """A RosWatcher of the master, what it delivered (by machine) and what it said."""

    def __init__(self, master_uri: str) -> None:
        self.events: dict[str, list[dict]] = {}
        self.said: list[str] = []
        self.lock = threading.Lock()
        self.watcher = RosWatcher(Node(master_uri), ROS1, self._deliver, lambda name, up: None, self.said.append,
                                  poll=0.2)

    def _deliver(self, events: list[dict]) -> None:
        with self.lock:
            for event in events:
                self.events.setdefault(event["machine"], []).append(event)

    def close(self) -> None:
        self.watcher.close()


@pytest.fixture
def watched(ros):
    made = Watched(ros.master_uri)
    yield made
    made.close()


@pytest.fixture
def hostile(ros):
    """A node of the master that publishes whatever a test gives it."""
    node = Node(ros.master_uri, name="/hostile")
    yield node
    node.close()


def structure(path: str, children: list[str]) -> dict:
    return {"path": path, "children": children, "internal_outcomes": ["go"], "outcomes_from": [children[0]],
            "outcomes_to": ["done"], "container_outcomes": ["done"]}


def status(path: str, active: list[str], local_data: str) -> dict:
    return {"path": path, "initial_states": ["A"], "active_states": active, "local_data": local_data, "info": ""}


def test_a_status_whose_userdata_is_a_malicious_pickle_runs_nothing_and_shows_it_opaque(ros, watched, hostile, tmp_path):
    mark = tmp_path / "ran"
    structures = hostile.advertise("/evil/smach/container_structure", ROS1.structure)
    statuses = hostile.advertise("/evil/smach/container_status", ROS1.status)
    wait_for(lambda: statuses.subscribers and structures.subscribers, 20, interval=0.05, what="the watcher to subscribe")
    evil = base64.b64encode(pickle.dumps({"goal": Planted(str(mark))}, 2)).decode()

    def started_with_userdata() -> dict | None:
        structures.publish(structure("/SM_ROOT", ["A"]))
        statuses.publish(status("/SM_ROOT", ["A"], evil))
        return next((e["userdata"] for e in watched.events.get("evil", []) if e["kind"] == "start"), None)
    userdata = wait_for(started_with_userdata, 20, interval=0.3, what=lambda: "the machine's start: %s" % watched.events)
    assert userdata == {"goal": {"$repr": "<opaque posix.system>"}}
    assert not mark.exists()


def test_a_topic_with_a_smach_name_and_another_type_is_said_and_not_followed(ros, watched, hostile):
    hostile.advertise("/odd/smach/container_status", "std_msgs/String").publish({"data": "not a status"})
    wait_for(lambda: any("/odd/smach/container_status" in text for text in watched.said), 20, interval=0.05,
             what=lambda: "the watcher to say so: %s" % watched.said)
    said = next(text for text in watched.said if "/odd/smach/container_status" in text)
    assert "std_msgs/String" in said and "not followed" in said
    assert "odd" not in watched.events


def test_serve_ros1_shows_a_robots_machine_and_follows_it_after_its_master_restarted(ros):
    robot = ros.robot("smach_ros_loop.py", "robot1", "/r1", "/r1/sm_stop", ready=READY)
    proc, found = started(["serve", "--port", "0", "--ros1", ros.master_uri], r"serving the dashboard at (http://\S+)")
    base, token = found.group(1).split("/?token=")
    try:
        import httpx

        def last_seq() -> int:
            machines = httpx.get(base + "/api/machines", params={"token": token}, timeout=10).json()
            return next((m["last_seq"] for m in machines if m["name"] == "r1"), 0)
        wait_for(lambda: last_seq() > 0, 30, interval=0.1, what="r1 on the dashboard")
        ros.stop()
        ros.start()  # a new master on the same port: the nodes of the old one know nothing of it
        robot.stop()
        robot = ros.robot("smach_ros_loop.py", "robot1", "/r1", "/r1/sm_stop", ready=READY)
        seen = last_seq()
        wait_for(lambda: last_seq() > seen, 30, interval=0.1, what="r1's events again after the master's restart")
    finally:
        robot.stop()
        stop(proc)


def test_a_headless_recorder_beside_a_robot_writes_a_log_that_replays(ros, tmp_path):
    robot = ros.robot("smach_ros_loop.py", "robot1", "/r1", "/r1/sm_stop", ready=READY)
    log = tmp_path / "headless.jsonl"
    proc, _ = started(["ros1", "--master", ros.master_uri, "--no-serve", "--record", str(log)], r"recording to")
    try:
        wait_for(lambda: log.exists() and log.read_text().count('"transition"') >= 3, 30, interval=0.2,
                 what="three transitions in the log")
    finally:
        stop(proc)  # SIGTERM, as a service manager stops it: the log is closed
        robot.stop()
    assert proc.returncode == 0
    printed = cli("replay", str(log))
    assert "State machine transitioning 'MOVE':'arrived'-->'SCAN'" in printed.stdout, printed.stdout + printed.stderr


def test_no_serve_without_record_is_a_usage_error():
    printed = cli("ros1", "--no-serve")
    assert printed.returncode == 2 and "--no-serve needs --record" in printed.stderr
