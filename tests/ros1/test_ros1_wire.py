"""fsmscope's own ROS 1 client (fsmscope/ros1/), with no rospy in its process, against the real
thing: Debian's rosmaster, rospy nodes (tests/robots/rospy_node.py) and ``rostopic``."""

from __future__ import annotations

import base64
import pickle
import subprocess
import threading
import xmlrpc.client

import pytest
from fsmscope.ros1 import Node, Received, Ros1Error
from fsmscope.ros1.messages import message_type
from fsmscope.server.testing.demo_process import free_port
from fsmscope.server.testing.polling import wait_for

from ros1_support import Ros1
from rospy_support import RospyNode

STATUS = "smach_msgs/SmachContainerStatus"


class Inbox:
    """What a subscription was given: every message, and every list of connected publishers."""

    def __init__(self) -> None:
        self.messages: list[Received] = []
        self.publishers: list[list[str]] = []
        self._lock = threading.Lock()

    def on_message(self, received: Received) -> None:
        with self._lock:
            self.messages.append(received)

    def on_publishers(self, publishers: list[str]) -> None:
        with self._lock:
            self.publishers.append(publishers)

    def from_(self, publisher: str) -> list[Received]:
        with self._lock:
            return [m for m in self.messages if m.publisher == publisher]

    def connected(self) -> list[str] | None:
        with self._lock:
            return self.publishers[-1] if self.publishers else None


@pytest.fixture
def node(ros, request):
    """fsmscope's node on the module's master, named after the test."""
    ours = Node(ros.master_uri, "/wire_" + request.node.name.removeprefix("test_")[:40])
    yield ours
    ours.close()


def subscribed(node: Node, topic: str, type_name: str = STATUS):
    inbox = Inbox()
    return inbox, node.subscribe(topic, type_name, inbox.on_message, inbox.on_publishers)


# Each type's md5sum as the classes genpy generates (rospy's) have it.
GENPY_MD5SUMS = """
import importlib, sys
for name in sys.argv[1:]:
    package, short = name.split("/")
    print(getattr(importlib.import_module(package + ".msg"), short)._md5sum)
"""


def test_the_md5sums_are_those_of_the_classes_genpy_generates(ros):
    names = ["smach_msgs/SmachContainerStatus", "smach_msgs/SmachContainerStructure",
             "smach_msgs/SmachContainerInitialStatusCmd", "std_msgs/Empty", "rosgraph_msgs/Log"]
    genpy = subprocess.run(["/usr/bin/python3", "-c", GENPY_MD5SUMS, *names], env=ros.robot_env(),
                           capture_output=True, text=True, timeout=60)
    assert genpy.returncode == 0, genpy.stderr
    assert [message_type(name).md5sum for name in names] == genpy.stdout.split()


def test_a_rospy_status_reaches_the_node_as_plain_fields_with_its_stamp_and_publisher(ros, node):
    robot = RospyNode(ros, "/status_robot", "status", "/robot/smach/container_status")
    try:
        inbox, _ = subscribed(node, "/robot/smach/container_status")
        first = wait_for(lambda: inbox.from_("/status_robot"), 20, what="a status from the robot")[0]
    finally:
        robot.kill()
    assert first.topic == "/robot/smach/container_status"
    assert first.stamp == pytest.approx(1700000000.25)
    fields = first.fields
    assert (fields["path"], fields["initial_states"], fields["active_states"][0][:5]) == ("/SM_ROOT", ["INIT"], "STEP_")
    assert pickle.loads(base64.b64decode(fields["local_data"])) == {"rounds": 3}
    assert fields["header"]["stamp"] == {"sec": 1700000000, "nanosec": 250000000}


def test_messages_of_one_publisher_arrive_in_the_order_it_sent_them(ros, node):
    robot = RospyNode(ros, "/ordered_robot", "status", "/ordered/smach/container_status")
    try:
        inbox, _ = subscribed(node, "/ordered/smach/container_status")
        received = wait_for(lambda: len(inbox.messages) >= 10 and inbox.from_("/ordered_robot"), 20)
    finally:
        robot.kill()
    numbers = [int(m.fields["info"]) for m in received]
    assert numbers == list(range(numbers[0], numbers[0] + len(numbers)))


def test_published_topics_name_each_topic_with_its_ros1_type(ros, node):
    robot = RospyNode(ros, "/typed_robot", "status", "/typed/smach/container_status")
    try:
        node.advertise("/typed/smach/container_init", "smach_msgs/SmachContainerInitialStatusCmd")
        topics = node.published_topics()
    finally:
        robot.kill()
    assert topics["/typed/smach/container_status"] == STATUS
    assert topics["/typed/smach/container_init"] == "smach_msgs/SmachContainerInitialStatusCmd"


def test_an_initial_status_command_reaches_a_rospy_subscriber(ros, node):
    publication = node.advertise("/cmd/smach/container_init", "smach_msgs/SmachContainerInitialStatusCmd")
    echo = RospyNode(ros, "/init_echo", "echo", "/cmd/smach/container_init",
                     "smach_msgs/SmachContainerInitialStatusCmd")
    try:
        wait_for(lambda: publication.subscribers == ["/init_echo"], 20, what=lambda: str(publication.subscribers))
        publication.publish({"path": "/SM_ROOT", "initial_states": ["SCAN"], "local_data": "gAJ9cQAu"})
        echoed = wait_for(echo.messages, 20, what=lambda: "the echo:\n" + echo.output)
    finally:
        echo.kill()
    assert echoed == [{"path": "/SM_ROOT", "initial_states": ["SCAN"], "local_data": "gAJ9cQAu"}]


def test_a_latched_empty_reaches_rostopic_echo_started_after_it_was_published(ros, node):
    publication = node.advertise("/latched_stop", "std_msgs/Empty", latch=True)
    publication.publish({})
    echo = ros.rostopic("echo", "-n", "1", "/latched_stop")
    printed = echo.communicate(timeout=30)[0]
    assert echo.returncode == 0 and printed.strip() == "---", printed


def test_smach_ros_introspection_server_is_found_by_type_and_takes_an_initial_state_from_the_node(ros, node):
    """The original SMACH with smach_ros's own IntrospectionServer: its topics found by their types,
    its structure and status read, and a SmachContainerInitialStatusCmd of ours obeyed (it publishes
    the new initial state and userdata as a status saying REMOTE_INIT)."""
    robot = RospyNode(ros, "/smach_robot", "smach", "patrol")
    try:
        def smach_topics() -> dict[str, str] | None:
            found = {topic: kind for topic, kind in node.published_topics().items()
                     if kind.startswith("smach_msgs/") and topic.startswith("/patrol/")}  # others: earlier tests
            return found if len(found) == 2 else None
        topics = wait_for(smach_topics, 20, interval=0.1, what="the introspection server's topics")
        structures, _ = subscribed(node, "/patrol/smach/container_structure", "smach_msgs/SmachContainerStructure")
        statuses, _ = subscribed(node, "/patrol/smach/container_status")
        init = node.advertise("/patrol/smach/container_init", "smach_msgs/SmachContainerInitialStatusCmd")
        wait_for(lambda: init.subscribers == ["/smach_robot"], 20, what=lambda: str(init.subscribers))
        userdata = base64.b64encode(pickle.dumps({"rounds": 7}, 2)).decode()
        init.publish({"path": "/SM_ROOT", "initial_states": ["B"], "local_data": userdata})
        remote = wait_for(lambda: [m for m in statuses.messages if m.fields["info"] == "REMOTE_INIT"], 20,
                          what="the status answering our initial state")[0]
        structure = wait_for(lambda: structures.messages, 20, what="a structure")[0]
    finally:
        robot.kill()
    assert topics == {"/patrol/smach/container_structure": "smach_msgs/SmachContainerStructure",
                      "/patrol/smach/container_status": STATUS}
    assert (structure.fields["path"], structure.fields["children"]) == ("/SM_ROOT", ["A", "B"])
    assert remote.fields["initial_states"] == ["B"] and remote.publisher == "/smach_robot"
    assert pickle.loads(base64.b64decode(remote.fields["local_data"])) == {"rounds": 7}


def test_a_publisher_killed_leaves_the_connected_publishers_and_a_new_one_joins(ros, node):
    topic = "/fleet/smach/container_status"
    first = RospyNode(ros, "/first_robot", "status", topic)
    second = RospyNode(ros, "/second_robot", "status", topic)
    third = None
    try:
        inbox, subscription = subscribed(node, topic)
        wait_for(lambda: inbox.connected() == ["/first_robot", "/second_robot"], 20, what=lambda: str(inbox.publishers))
        first.kill()
        wait_for(lambda: inbox.connected() == ["/second_robot"], 20, what=lambda: str(inbox.publishers))
        third = RospyNode(ros, "/third_robot", "status", topic)
        wait_for(lambda: inbox.connected() == ["/second_robot", "/third_robot"], 20, what=lambda: str(inbox.publishers))
        wait_for(lambda: inbox.from_("/third_robot"), 20, what="a status from the third robot")
    finally:
        for robot in (first, second, third):
            if robot is not None:
                robot.kill()
    assert subscription.undecodable == 0


def test_a_message_that_does_not_decode_is_counted_and_said_and_the_next_one_arrives(ros, node):
    robot = RospyNode(ros, "/broken_robot", "broken", "/broken/smach/container_status")
    try:
        inbox, subscription = subscribed(node, "/broken/smach/container_status")
        wait_for(lambda: subscription.undecodable >= 2 and len(inbox.messages) >= 2, 20,
                 what=lambda: "%d undecodable, %d received" % (subscription.undecodable, len(inbox.messages)))
    finally:
        robot.kill()
    assert {int(m.fields["info"]) % 2 for m in inbox.messages} == {0}  # the whole ones, every other
    assert "from /broken_robot" in subscription.problems[0] and "does not decode" in subscription.problems[0]


def test_a_publisher_of_another_type_on_the_topic_is_refused_with_words(ros, node):
    robot = RospyNode(ros, "/string_robot", "string", "/impostor/smach/container_status")
    try:
        inbox, subscription = subscribed(node, "/impostor/smach/container_status")
        problem = wait_for(lambda: subscription.problems, 20, what="the refusal to be said")[0]
    finally:
        robot.kill()
    assert "/impostor/smach/container_status" in problem and "std_msgs/String" in problem, problem
    assert subscription.publishers == [] and inbox.messages == []


def test_a_master_that_is_not_running_is_said_and_not_waited_for():
    lonely = Node("http://127.0.0.1:%d/" % free_port(), "/lonely")
    try:
        assert lonely.master_connected is False
        with pytest.raises(Ros1Error, match="cannot reach"):
            lonely.published_topics()
    finally:
        lonely.close()


def test_a_subscription_resumes_with_a_master_restarted_on_the_same_port(tmp_path):
    """The node registers again with the new master, so a robot started after the restart is
    connected; the robot from before (rospy does not register again) goes on being read."""
    ros = Ros1(tmp_path).start()
    ours = Node(ros.master_uri, "/wire_restart")
    robots = [RospyNode(ros, "/before_restart", "status", "/again/smach/container_status")]
    try:
        inbox, _ = subscribed(ours, "/again/smach/container_status")
        wait_for(lambda: inbox.from_("/before_restart"), 20, what="a status before the restart")
        ros.stop()
        wait_for(lambda: not ours.master_connected, 10, what="the node to see the master gone")
        ros.start()
        wait_for(lambda: ours.master_connected, 10, what="the node to see the master back")
        robots.append(RospyNode(ros, "/after_restart", "status", "/again/smach/container_status"))
        wait_for(lambda: inbox.from_("/after_restart"), 20, what=lambda: "a status from a robot started after the "
                 "restart; publishers: %s" % inbox.publishers)
        before = len(inbox.from_("/before_restart"))
        wait_for(lambda: len(inbox.from_("/before_restart")) > before, 10, what="the robot from before to go on")
    finally:
        for robot in robots:
            robot.kill()
        ours.close()
        ros.stop()


def test_a_publication_is_found_by_a_subscriber_started_after_the_master_restarted(tmp_path):
    ros = Ros1(tmp_path).start()
    ours = Node(ros.master_uri, "/wire_restart_publisher")
    echo = None
    try:
        publication = ours.advertise("/again_stop", "std_msgs/Empty", latch=True)
        publication.publish({})
        ros.stop()
        wait_for(lambda: not ours.master_connected, 10, what="the node to see the master gone")
        ros.start()
        wait_for(lambda: ours.master_connected, 10, what="the node to see the master back")
        echo = RospyNode(ros, "/late_echo", "echo", "/again_stop", "std_msgs/Empty")
        wait_for(echo.messages, 20, what=lambda: "the latched message after the restart:\n" + echo.output)
    finally:
        if echo is not None:
            echo.kill()
        ours.close()
        ros.stop()


def test_a_subscriber_that_leaves_is_no_longer_among_the_publications_subscribers(ros, node):
    publication = node.advertise("/leaving_stop", "std_msgs/Empty")
    echo = RospyNode(ros, "/leaving_echo", "echo", "/leaving_stop", "std_msgs/Empty")
    try:
        wait_for(lambda: publication.subscribers == ["/leaving_echo"], 20, what=lambda: str(publication.subscribers))
    finally:
        echo.kill()
    wait_for(lambda: publication.subscribers == [], 20, what=lambda: str(publication.subscribers))


def test_closing_the_node_unregisters_its_subscriptions_and_publications(ros):
    ours = Node(ros.master_uri, "/wire_closing")
    ours.subscribe("/closing/smach/container_status", STATUS, lambda received: None)
    ours.advertise("/closing/smach/container_init", "smach_msgs/SmachContainerInitialStatusCmd")

    def registered() -> set[str]:
        publishers, subscribers, _ = xmlrpc.client.ServerProxy(ros.master_uri).getSystemState("/test")[2]
        return {topic for topic, nodes in publishers + subscribers if "/wire_closing" in nodes}

    assert registered() == {"/closing/smach/container_status", "/closing/smach/container_init"}
    ours.close()
    assert registered() == set()


def test_a_subscription_made_before_the_master_runs_is_registered_when_it_does(tmp_path):
    ros = Ros1(tmp_path)
    ours = Node(ros.master_uri, "/wire_early")
    robot = None
    try:
        inbox, _ = subscribed(ours, "/early/smach/container_status")
        assert ours.master_connected is False
        ros.start()
        robot = RospyNode(ros, "/late_robot", "status", "/early/smach/container_status")
        wait_for(lambda: inbox.from_("/late_robot"), 20, what="a status once the master runs")
    finally:
        if robot is not None:
            robot.kill()
        ours.close()
        ros.stop()
