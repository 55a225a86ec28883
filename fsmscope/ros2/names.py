"""ROS 2's names on DDS, both ways, as its design document "Topic and Service name mapping to DDS"
and rosidl's DDS type support define them, and as every rmw (Cyclone DDS, Fast DDS) puts them on
the wire.

A topic ``/a/b`` is the DDS topic ``rt/a/b`` (services and actions use ``rq/``, ``rr/``, which
fsmscope neither reads nor reports). A message type ``pkg/msg/Name`` is the DDS type
``pkg::msg::dds_::Name_``.
"""

from __future__ import annotations

TOPIC_PREFIX = "rt"


def dds_topic(ros_topic: str) -> str:
    """The DDS topic of a ROS topic: ``/a/b`` -> ``rt/a/b`` (a name without its leading slash is
    taken as absolute: fsmscope has no node namespace to resolve it in)."""
    name = ros_topic.strip()
    if not name.strip("/"):
        raise ValueError(f"not a ROS topic name: {ros_topic!r}")
    return f"{TOPIC_PREFIX}/{name.lstrip('/')}"


def ros_topic(dds_topic_name: str) -> str | None:
    """The ROS topic of a DDS topic (``rt/a/b`` -> ``/a/b``), None for a DDS topic that is not a ROS
    topic (a service's ``rq/``, ``rr/``, or another program's)."""
    prefix = TOPIC_PREFIX + "/"
    if not dds_topic_name.startswith(prefix) or len(dds_topic_name) == len(prefix):
        return None
    return "/" + dds_topic_name[len(prefix):]


def dds_type(ros_type: str) -> str:
    """The DDS type of a ROS 2 message type: ``pkg/msg/Name`` (or ``pkg/Name``) ->
    ``pkg::msg::dds_::Name_``."""
    parts = ros_type.strip().split("/")
    if len(parts) == 2:
        parts = [parts[0], "msg", parts[1]]
    if len(parts) != 3 or not all(parts):
        raise ValueError(f"not a ROS 2 message type: {ros_type!r} (want pkg/msg/Name)")
    package, kind, name = parts
    return f"{package}::{kind}::dds_::{name}_"


def ros_type(dds_type_name: str) -> str:
    """The ROS 2 type of a DDS type (``pkg::msg::dds_::Name_`` -> ``pkg/msg/Name``); a DDS type that
    does not follow ROS 2's layout is returned as it is, so that it is reported, never mistaken."""
    parts = dds_type_name.split("::")
    if len(parts) == 4 and parts[2] == "dds_" and parts[3].endswith("_") and all(parts[:2]) and len(parts[3]) > 1:
        return f"{parts[0]}/{parts[1]}/{parts[3][:-1]}"
    return dds_type_name
