"""The smallest ROS 1 client, for a computer with no ROS: fsmscope subscribes to smach_ros's
introspection topics on a live master and publishes its two controls, from any Python 3.11.

``Node`` (node.py) is the one entry point; it speaks the master's XML-RPC API (master.py), serves
its own (slave.py), and carries messages over TCPROS (tcpros.py, listener.py, subscription.py,
publication.py) as plain dicts made by the kept library rosbags (messages.py). docs/ros1.md says
what it speaks and what it was tested against.
"""

from .errors import Ros1Error
from .node import Node
from .publication import Publication
from .subscription import Received, Subscription

__all__ = ["Node", "Publication", "Received", "Ros1Error", "Subscription"]
