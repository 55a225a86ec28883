"""fsmscope.ros2's Node against a ROS 2 robot: executive_smach's ros2 branch's own SMACH core and
smach_ros/introspection.py, publishing over Cyclone DDS as rmw does, in a process of its own
(tests/robots/ros2_robot.py), and impostors that publish on the same topic what is no SmachContainerStatus."""

import pickle
import re
import threading
import time

import pytest

from fsmscope.ros2 import Received
from fsmscope.server.testing.polling import wait_for
from ros2_support import ROBOT_LEASE, STATUS, STATUS_TOPIC, STRUCTURE


class Inbox:
    """What a subscription handed over, collected from its thread."""

    def __init__(self) -> None:
        self.messages: list[Received] = []
        self.publishers: list[list[str]] = []
        self.lock = threading.Lock()

    def message(self, received: Received) -> None:
        with self.lock:
            self.messages.append(received)

    def publisher_set(self, publishers: list[str]) -> None:
        with self.lock:
            self.publishers.append((time.monotonic(), publishers))

    def first(self, predicate, timeout: float = 20) -> Received:
        def found():
            with self.lock:
                return next((m for m in self.messages if predicate(m)), None)
        return wait_for(found, timeout, interval=0.02, what=lambda: f"a message; got {self.messages[-3:]}")


def test_status_arrives_with_its_fields_local_data_as_published_and_the_header_stamp(node, robots):
    inbox = Inbox()
    subscription = node.subscribe(STATUS_TOPIC, STATUS, inbox.message)
    started = time.time()
    robot = robots()
    status = inbox.first(lambda m: m.fields["path"] == "/SM_ROOT/SUB" and m.fields["active_states"] == ["Y"])
    fields = status.fields
    # introspection.py: header.stamp = ROSClock().now(), local_data = pickle.dumps(userdata._data, 2), info = the
    # transition callback's arguments. The count the sub-machine holds at Y is the one Y prints.
    assert fields["initial_states"] == ["X"]
    def pickles_of_counts_at_y() -> list[bytes]:
        return [pickle.dumps({"count": int(line.split()[-1])}, 2)
                for line in robot.output.splitlines() if line.startswith("state: Y ")]
    wait_for(lambda: fields["local_data"] in pickles_of_counts_at_y(), 5, interval=0.02,
             what=lambda: f"local_data {fields['local_data']!r} to be the pickle of a count Y printed:\n{robot.output}")
    assert isinstance(fields["local_data"], bytes)
    assert "UserData" in fields["info"]
    stamp = fields["header"]["stamp"]
    assert status.stamp == stamp["sec"] + stamp["nanosec"] * 1e-9
    assert started <= status.stamp <= status.t
    assert status.topic == STATUS_TOPIC
    assert subscription.publishers == [status.publisher]


def test_published_topics_finds_the_introspection_servers_topics_by_their_types(node, robots):
    robots()
    topics = wait_for(lambda: (lambda t: t if STATUS_TOPIC in t and "/robot/smach/container_structure" in t else None)(
        node.published_topics()), 20, interval=0.05, what=lambda: f"the robot's topics in {node.published_topics()}")
    assert topics[STATUS_TOPIC] == STATUS
    assert topics["/robot/smach/container_structure"] == STRUCTURE
    assert topics["/rosout"] == "rcl_interfaces/msg/Log"
    assert [name for name, kind in topics.items() if kind == STATUS] == [STATUS_TOPIC]


def test_the_structure_of_each_container_arrives(node, robots):
    inbox = Inbox()
    node.subscribe("/robot/smach/container_structure", STRUCTURE, inbox.message)
    robots()
    root = inbox.first(lambda m: m.fields["path"] == "/SM_ROOT").fields
    assert root["children"] == ["A", "SUB", "C"]
    # get_internal_edges(): every outcome of every child, 'None' where the machine maps it nowhere.
    assert sorted(zip(root["outcomes_from"], root["internal_outcomes"], root["outcomes_to"])) == [
        ("A", "next", "SUB"), ("A", "preempted", "None"), ("C", "next", "done"), ("C", "preempted", "None"),
        ("SUB", "done", "C"), ("SUB", "preempted", "None")]
    assert sorted(root["container_outcomes"]) == ["done", "preempted"]


def test_container_init_from_fsmscope_sets_where_the_robots_next_run_starts(node, robots):
    inbox = Inbox()
    node.subscribe(STATUS_TOPIC, STATUS, inbox.message)
    init = node.advertise("/robot/smach/container_init", "smach_msgs/msg/SmachContainerInitialStatusCmd")
    robot = robots()
    wait_for(lambda: len(init.subscribers) >= 1, 20, interval=0.02, what="the robot's subscription to container_init")
    init.publish({"path": "/SM_ROOT", "initial_states": ["C"], "local_data": pickle.dumps({"count": 100}, 2)})
    remote = inbox.first(lambda m: m.fields["info"] == "REMOTE_INIT")
    assert remote.fields["path"] == "/SM_ROOT"
    assert remote.fields["initial_states"] == ["C"]
    assert remote.fields["local_data"] == pickle.dumps({"count": 100}, 2)
    # The command came while a run was going: its userdata at once, its initial state from the next run on.
    started_at_c = "State machine starting in initial state 'C'"
    wait_for(lambda: started_at_c in robot.output, 20, interval=0.02, what=lambda: f"a run starting at C:\n{robot.output}")
    first_at_c = wait_for(lambda: re.search(r"^state: C (\d+)$", robot.output.split(started_at_c, 1)[1], re.M), 10,
                          interval=0.02, what=lambda: f"C to run:\n{robot.output}")
    assert int(first_at_c.group(1)) > 100


def test_an_empty_message_on_sm_stop_preempts_the_robots_machine(node, robots):
    stop = node.advertise("/sm_stop", "std_msgs/msg/Empty")
    robot = robots()
    wait_for(lambda: len(stop.subscribers) >= 1, 20, interval=0.02, what="the robot's subscription to /sm_stop")
    robot.wait_for_line("state: A 0")
    stop.publish({})
    robot.wait_for_line("outcome: preempted")


def test_a_killed_robot_leaves_the_publishers_within_its_lease(node, robots):
    inbox = Inbox()
    subscription = node.subscribe(STATUS_TOPIC, STATUS, inbox.message, inbox.publisher_set)
    robot = robots()
    inbox.first(lambda m: True)
    [publisher] = subscription.publishers
    assert inbox.publishers[-1][1] == [publisher]
    robot.kill()
    killed = time.monotonic()
    wait_for(lambda: inbox.publishers[-1][1] == [], ROBOT_LEASE + 5, interval=0.02,
             what=lambda: f"the killed robot to leave the publishers: {inbox.publishers}")
    assert inbox.publishers[-1][0] - killed <= ROBOT_LEASE + 2


def test_a_topic_with_a_smach_name_and_another_type_is_reported_with_its_type_and_not_taken(node, robots):
    inbox = Inbox()
    subscription = node.subscribe(STATUS_TOPIC, STATUS, inbox.message)
    robots("other-type")
    wait_for(lambda: node.published_topics().get(STATUS_TOPIC) == "std_msgs/msg/String", 20, interval=0.05,
             what=lambda: f"the impostor in {node.published_topics()}")
    said = wait_for(lambda: [p for p in subscription.problems if "std_msgs/msg/String" in p], 10, interval=0.05,
                    what=lambda: f"the subscription to say so: {subscription.problems}")
    assert "not received" in said[0]
    assert inbox.messages == [] and subscription.publishers == []


def test_a_publisher_of_the_smach_type_name_with_another_layout_is_not_taken_and_said(node, robots):
    inbox = Inbox()
    subscription = node.subscribe(STATUS_TOPIC, STATUS, inbox.message)
    robots("other-layout")
    said = wait_for(lambda: [p for p in subscription.problems if "does not match ours" in p], 15, interval=0.05,
                    what=lambda: f"the subscription to say so: {subscription.problems}")
    assert STATUS in said[0]
    assert inbox.messages == [] and subscription.publishers == []


def test_a_message_that_does_not_decode_is_counted_and_said_and_the_next_ones_arrive(node, robots):
    inbox = Inbox()
    subscription = node.subscribe(STATUS_TOPIC, STATUS, inbox.message)
    robots("bad-utf8")
    wait_for(lambda: subscription.undecodable >= 3 and len(inbox.messages) >= 3, 20, interval=0.05,
             what=lambda: f"bad and good messages: {subscription.undecodable}, {len(inbox.messages)}")
    assert {m.fields["path"] for m in inbox.messages} == {"/after"}
    assert "did not decode" in subscription.problems[0] and "UnicodeDecodeError" in subscription.problems[0]


def test_smachs_log_lines_arrive_on_rosout_with_the_nodes_name(node, robots):
    inbox = Inbox()
    node.subscribe("/rosout", "rcl_interfaces/msg/Log", inbox.message)
    robots()
    line = inbox.first(lambda m: m.fields["msg"] == "State machine transitioning 'A':'next'-->'SUB'")
    assert line.fields["name"] == "robot_main"
    assert line.fields["level"] == 20
    assert line.stamp == line.fields["stamp"]["sec"] + line.fields["stamp"]["nanosec"] * 1e-9


def test_a_value_the_message_cannot_hold_is_refused_before_anything_is_written(node):
    init = node.advertise("/robot/smach/container_init", "smach_msgs/msg/SmachContainerInitialStatusCmd")
    with pytest.raises(ValueError, match="cannot write"):
        init.publish({"path": "/SM_ROOT", "local_data": [256]})
    with pytest.raises(ValueError, match="no member"):
        init.publish({"paths": "/SM_ROOT"})
