"""ROS 2's names on DDS (fsmscope.ros2.names), the messages as dicts (fsmscope.ros2.messages) and
Cyclone's configuration for one interface (fsmscope.ros2.config): no network."""

import pytest

from fsmscope.ros2.config import cyclone_config
from fsmscope.ros2.messages import SmachContainerInitialStatusCmd, SmachContainerStatus, from_fields, message_class, to_fields
from fsmscope.ros2.names import dds_topic, dds_type, ros_topic, ros_type


def test_a_ros_topic_is_the_dds_topic_under_rt_and_back():
    assert dds_topic("/robot/smach/container_status") == "rt/robot/smach/container_status"
    assert ros_topic("rt/robot/smach/container_status") == "/robot/smach/container_status"


def test_a_dds_topic_outside_rt_is_no_ros_topic():
    assert ros_topic("rq/robot/get_stateRequest") is None
    assert ros_topic("DCPSParticipant") is None
    assert ros_topic("rt/") is None


def test_a_ros_type_is_the_dds_type_under_dds_with_an_underscore_and_back():
    assert dds_type("smach_msgs/msg/SmachContainerStatus") == "smach_msgs::msg::dds_::SmachContainerStatus_"
    assert dds_type("std_msgs/Empty") == "std_msgs::msg::dds_::Empty_"
    assert ros_type("smach_msgs::msg::dds_::SmachContainerStatus_") == "smach_msgs/msg/SmachContainerStatus"


def test_a_dds_type_not_laid_out_as_ros_2s_is_reported_as_it_is():
    assert ros_type("SmachContainerStatus") == "SmachContainerStatus"
    assert ros_type("a::b::c::D_") == "a::b::c::D_"


@pytest.mark.parametrize("bad", ["", "/", "Status", "a/b/c/d", "pkg//Name"])
def test_what_is_no_ros_type_or_topic_is_refused(bad):
    with pytest.raises(ValueError):
        dds_type(bad)
    if bad.strip("/") == "":
        with pytest.raises(ValueError):
            dds_topic(bad)


def test_a_message_from_a_dict_leaves_out_members_as_zero_and_reads_back_as_the_same_dict():
    message = from_fields(SmachContainerStatus, {"path": "/SM", "local_data": b"\x80\x02}q\x00."})
    fields = to_fields(SmachContainerStatus.deserialize(message.serialize(use_version_2=False)))
    assert fields == {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}, "path": "/SM",
                      "initial_states": [], "active_states": [], "local_data": b"\x80\x02}q\x00.", "info": ""}


def test_a_message_is_written_as_xcdr1_little_endian():
    message = from_fields(SmachContainerInitialStatusCmd, {"path": "/SM", "initial_states": ["C"], "local_data": b"\x01"})
    assert message.serialize(use_version_2=False) == (
        b"\x00\x01\x00\x00" b"\x04\x00\x00\x00/SM\x00" b"\x01\x00\x00\x00" b"\x02\x00\x00\x00C\x00\x00\x00"
        b"\x01\x00\x00\x00\x01")


def test_a_member_the_message_lacks_or_a_type_fsmscope_does_not_know_is_refused():
    with pytest.raises(ValueError, match="no member local"):
        from_fields(SmachContainerStatus, {"local": b""})
    with pytest.raises(ValueError, match="does not know"):
        message_class("smach_msgs/msg/SmachContainerStatusX")


def test_on_the_loopback_discovery_is_by_unicast_to_the_loopback_with_multicast_off():
    config = cyclone_config("127.0.0.1")
    assert '<NetworkInterface address="127.0.0.1"/>' in config
    assert "<AllowMulticast>false</AllowMulticast>" in config
    assert '<Peers><Peer address="127.0.0.1"/></Peers>' in config


def test_an_interface_alone_keeps_multicast_discovery():
    config = cyclone_config("eth0")
    assert '<NetworkInterface name="eth0"/>' in config
    assert "AllowMulticast" not in config and "Peers" not in config


def test_an_address_that_would_break_the_xml_is_refused():
    with pytest.raises(ValueError):
        cyclone_config('127.0.0.1"/><Peer address="10.0.0.1')


def test_a_message_a_big_endian_machine_wrote_reads_the_same():
    from cyclonedds.idl._support import Endianness
    message = from_fields(SmachContainerStatus, {"path": "/SM", "active_states": ["A"], "local_data": b"\x80\x02",
                                                 "header": {"stamp": {"sec": 3, "nanosec": 4}}})
    big = message.serialize(endianness=Endianness.Big, use_version_2=False)
    assert big[:2] == b"\x00\x00"  # CDR_BE
    assert to_fields(SmachContainerStatus.deserialize(big)) == to_fields(message)
