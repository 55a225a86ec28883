"""The ROS 1 client's codecs, without a network: TCPROS's connection header and framing
(fsmscope/ros1/tcpros.py) and messages as plain dicts (fsmscope/ros1/messages.py)."""

from __future__ import annotations

import pickle
import socket
import struct

import numpy as np
import pytest
from fsmscope.interop import smach_msgs
from fsmscope.ros1 import Ros1Error
from fsmscope.ros1 import tcpros
from fsmscope.ros1.messages import message_type

# The example of http://wiki.ros.org/ROS/Connection%20Header: rostopic's publisher of /chatter.
WIKI_FIELDS = {"message_definition": "string data\n\n", "callerid": "/rostopic_4767_1316912741557",
               "latching": "1", "md5sum": "992ce8a1687cec8c8bd883ec73ca41d1", "topic": "/chatter",
               "type": "std_msgs/String"}
WIKI_HEADER = bytes.fromhex(
    "b0000000"
    "20000000" "6d6573736167655f646566696e6974696f6e3d737472696e6720646174610a0a"
    "25000000" "63616c6c657269643d2f726f73746f7069635f343736375f31333136393132373431353537"
    "0a000000" "6c61746368696e673d31"
    "27000000" "6d643573756d3d3939326365386131363837636563386338626438383365633733636134316431"
    "0e000000" "746f7069633d2f63686174746572"
    "14000000" "747970653d7374645f6d7367732f537472696e67")


def test_a_header_encodes_as_the_ros_wiki_shows_it():
    assert tcpros.encode_header(WIKI_FIELDS) == WIKI_HEADER


def test_the_ros_wikis_header_decodes_to_its_fields():
    assert tcpros.decode_header(WIKI_HEADER[4:]) == WIKI_FIELDS


def test_a_header_field_without_an_equals_sign_is_refused_with_words():
    with pytest.raises(Ros1Error, match="no '='"):
        tcpros.decode_header(struct.pack("<I", 5) + b"topic")


def test_a_header_field_longer_than_the_header_is_refused_with_words():
    with pytest.raises(Ros1Error, match="past its end"):
        tcpros.decode_header(struct.pack("<I", 50) + b"topic=/x")


def test_a_message_cut_short_by_a_closed_connection_is_a_closed_connection():
    ours, theirs = socket.socketpair()
    with ours, theirs:
        theirs.sendall(struct.pack("<I", 10) + b"abc")
        theirs.close()
        with pytest.raises(tcpros.ConnectionClosed):
            tcpros.read_message(ours)


def test_a_length_beyond_what_the_client_reads_is_refused_before_reading_it():
    ours, theirs = socket.socketpair()
    with ours, theirs:
        theirs.sendall(struct.pack("<I", tcpros.MAX_HEADER + 1))
        with pytest.raises(Ros1Error, match="more than"):
            tcpros.read_header(ours)


def test_framed_messages_are_read_back_one_by_one():
    ours, theirs = socket.socketpair()
    with ours, theirs:
        theirs.sendall(tcpros.frame(b"first") + tcpros.frame(b"") + tcpros.frame(b"third"))
        assert [tcpros.read_message(ours) for _ in range(3)] == [b"first", b"", b"third"]


def test_a_status_whose_local_data_is_a_raw_pickle_reads_it_as_bytes():
    """A ROS 1 robot before Noetic put the pickle itself in the ``string``: no UTF-8."""
    raw_pickle = pickle.dumps({"n": 1}, 2)
    store = smach_msgs.typestore(ros2=False, local_data_bytes=True)
    types = store.types
    header = types["std_msgs/msg/Header"](seq=1, stamp=types["builtin_interfaces/msg/Time"](sec=2, nanosec=3),
                                          frame_id="")
    status = types[smach_msgs.STATUS](header=header, path="/SM", initial_states=[], active_states=["A"],
                                      local_data=np.frombuffer(raw_pickle, dtype=np.uint8), info="")
    wire = bytes(store.serialize_ros1(status, smach_msgs.STATUS))
    fields = message_type("smach_msgs/SmachContainerStatus").decode(wire)
    assert fields["local_data"] == raw_pickle and fields["path"] == "/SM"


def test_a_message_built_from_a_few_fields_has_zero_and_empty_for_the_others():
    kind = message_type("rosgraph_msgs/Log")
    assert kind.decode(kind.encode({"msg": "hello", "level": 2})) == {
        "header": {"seq": 0, "stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}, "level": 2, "name": "",
        "msg": "hello", "file": "", "function": "", "line": 0, "topics": []}


def test_a_time_given_in_seconds_is_its_seconds_and_nanoseconds():
    kind = message_type("smach_msgs/SmachContainerStructure")
    fields = kind.decode(kind.encode({"header": {"stamp": 12.5}}))
    assert fields["header"]["stamp"] == {"sec": 12, "nanosec": 500000000}


def test_a_field_the_type_does_not_have_is_refused_by_name():
    with pytest.raises(Ros1Error, match="SmachContainerInitialStatusCmd has no field paths"):
        message_type("smach_msgs/SmachContainerInitialStatusCmd").encode({"paths": "/SM"})


def test_a_value_of_the_wrong_kind_is_refused_with_the_fields_name():
    with pytest.raises(Ros1Error, match="InitialStatusCmd.initial_states: a string is a str"):
        message_type("smach_msgs/SmachContainerInitialStatusCmd").encode({"initial_states": [3]})


def test_a_string_where_an_array_is_wanted_is_refused_not_spelled_out():
    with pytest.raises(Ros1Error, match="initial_states: an array is a list, not str"):
        message_type("smach_msgs/SmachContainerInitialStatusCmd").encode({"initial_states": "SCAN"})


def test_a_type_the_client_does_not_know_is_refused_with_words():
    with pytest.raises(Ros1Error, match="does not know"):
        message_type("robot_msgs/Secret")
