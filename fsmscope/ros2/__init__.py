"""ROS 2 without ROS: SMACH's introspection topics (and /rosout) over DDS, with cyclonedds.

``Node`` joins a ROS 2 domain, finds what is published, subscribes and publishes; ``Received`` is
one message as it arrived. See docs/ros2.md for what was tested and against what."""

from fsmscope.ros2.node import Node
from fsmscope.ros2.publisher import Publisher
from fsmscope.ros2.subscription import Received, Subscription

__all__ = ["Node", "Publisher", "Received", "Subscription"]
