"""The ros2 layer: each test on a ROS 2 domain of its own, fsmscope's Node on the loopback
(tests/ros2_support.py), robots started by the tests and stopped after them."""

import pytest

from fsmscope.ros2 import Node
from ros2_support import PrivateDomain, Robot, skip_without_reference


@pytest.fixture
def domain():
    held = PrivateDomain()
    yield held.id
    held.release()


@pytest.fixture
def node(domain):
    """fsmscope's node on the test's domain: the loopback only, multicast off, the loopback its peer."""
    made = Node(domain, "127.0.0.1")
    yield made
    made.close()


@pytest.fixture
def robots(domain):
    """``robots(mode)`` starts a robot on the test's domain; each is stopped after the test."""
    skip_without_reference()
    started: list[Robot] = []

    def start(mode: str = "smach") -> Robot:
        started.append(Robot(domain, mode))
        return started[-1]
    yield start
    for robot in started:
        robot.stop()
