"""smach_msgs' three introspection messages, registered with rosbags from their definitions.

The fields are those of ros/executive_smach's smach_msgs/msg/*.msg (the same since fuerte); on
its ROS 2 branch ``local_data`` is ``uint8[]`` (a raw pickle) where ROS 1 has a ``string``
(base64 of a pickle on noetic, the raw pickle before). A bag carries its own definitions
(ROS 1, ROS 2 mcap, recent sqlite3 bags); these are used when it does not (a Humble sqlite3 bag),
and to read a ROS 1 status whose ``local_data`` is a raw pickle, which is no UTF-8: the wire form of
``string`` and ``uint8[]`` is the same, so it is read as bytes.
"""

from __future__ import annotations

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

STRUCTURE = "smach_msgs/msg/SmachContainerStructure"
STATUS = "smach_msgs/msg/SmachContainerStatus"
INITIAL_STATUS_CMD = "smach_msgs/msg/SmachContainerInitialStatusCmd"  # a viewer's "set initial state"
STRUCTURE_TOPIC = "/smach/container_structure"  # after the introspection server's name
STATUS_TOPIC = "/smach/container_status"

_STRUCTURE = """std_msgs/Header header
string path
string[] children
string[] internal_outcomes
string[] outcomes_from
string[] outcomes_to
string[] container_outcomes
"""
_STATUS = """std_msgs/Header header
string path
string[] initial_states
string[] active_states
{local_data} local_data
string info
"""
_INITIAL_STATUS_CMD = """string path
string[] initial_states
{local_data} local_data
"""


def typestore(ros2: bool, local_data_bytes: bool = False) -> Typestore:
    """A typestore with the three messages: ROS 2's (``local_data`` bytes) or ROS 1's (``local_data`` a
    string, or bytes when ``local_data_bytes``)."""
    store = get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)
    kind = "uint8[]" if ros2 or local_data_bytes else "string"
    types = get_types_from_msg(_STRUCTURE, STRUCTURE)
    types.update(get_types_from_msg(_STATUS.format(local_data=kind), STATUS))
    types.update(get_types_from_msg(_INITIAL_STATUS_CMD.format(local_data=kind), INITIAL_STATUS_CMD))
    store.register(types)
    return store
