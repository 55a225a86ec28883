"""The ROS 2 messages fsmscope reads and writes, laid out as rosidl lays them out on DDS, and their
conversion to and from plain dicts.

The layouts follow the .msg files: smach_msgs' three messages on executive_smach's ``ros2`` branch
(7fb264e; ``local_data`` is ``uint8[]``, the raw protocol-2 pickle, not base64 as on noetic),
std_msgs/Header (no ``seq`` in ROS 2), builtin_interfaces/Time, std_msgs/Empty (rosidl gives an
empty message one member, ``uint8 structure_needs_at_least_one_member``, as IDL wants no empty
struct) and rcl_interfaces/Log (what ``/rosout`` carries). Each is a final struct, as rosidl makes
them, written as XCDR1 (the plain CDR every rmw reads).

A message as a dict: nested messages as dicts, arrays as lists, ``uint8[]`` as bytes.

(No ``from __future__ import annotations`` here: cyclonedds reads the members' annotations as
objects.)
"""

import dataclasses
import functools
import typing
from typing import Any

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import int32, sequence, uint8, uint32

from fsmscope.ros2.names import dds_type


@dataclasses.dataclass
class Time(IdlStruct, typename=dds_type("builtin_interfaces/msg/Time")):
    sec: int32
    nanosec: uint32


@dataclasses.dataclass
class Header(IdlStruct, typename=dds_type("std_msgs/msg/Header")):
    stamp: Time
    frame_id: str


@dataclasses.dataclass
class Empty(IdlStruct, typename=dds_type("std_msgs/msg/Empty")):
    structure_needs_at_least_one_member: uint8


@dataclasses.dataclass
class SmachContainerStructure(IdlStruct, typename=dds_type("smach_msgs/msg/SmachContainerStructure")):
    header: Header
    path: str
    children: sequence[str]
    internal_outcomes: sequence[str]
    outcomes_from: sequence[str]
    outcomes_to: sequence[str]
    container_outcomes: sequence[str]


@dataclasses.dataclass
class SmachContainerStatus(IdlStruct, typename=dds_type("smach_msgs/msg/SmachContainerStatus")):
    header: Header
    path: str
    initial_states: sequence[str]
    active_states: sequence[str]
    local_data: sequence[uint8]
    info: str


@dataclasses.dataclass
class SmachContainerInitialStatusCmd(IdlStruct, typename=dds_type("smach_msgs/msg/SmachContainerInitialStatusCmd")):
    path: str
    initial_states: sequence[str]
    local_data: sequence[uint8]


@dataclasses.dataclass
class Log(IdlStruct, typename=dds_type("rcl_interfaces/msg/Log")):
    stamp: Time
    level: uint8
    name: str
    msg: str
    file: str
    function: str
    line: uint32


# ROS 2 type name -> its class.
TYPES: dict[str, type[IdlStruct]] = {
    "builtin_interfaces/msg/Time": Time,
    "std_msgs/msg/Header": Header,
    "std_msgs/msg/Empty": Empty,
    "smach_msgs/msg/SmachContainerStructure": SmachContainerStructure,
    "smach_msgs/msg/SmachContainerStatus": SmachContainerStatus,
    "smach_msgs/msg/SmachContainerInitialStatusCmd": SmachContainerInitialStatusCmd,
    "rcl_interfaces/msg/Log": Log,
}


def message_class(ros_type: str) -> type[IdlStruct]:
    """The class of a ROS 2 message type fsmscope knows; ValueError naming those it knows otherwise."""
    try:
        return TYPES[ros_type]
    except KeyError:
        raise ValueError(f"fsmscope does not know the message type {ros_type!r}; it knows {', '.join(sorted(TYPES))}") from None


def _is_bytes(hint: Any) -> bool:
    return any(isinstance(arg, sequence) and arg.subtype == uint8 for arg in typing.get_args(hint))


@functools.cache
def _members(cls: type) -> dict[str, Any]:
    return typing.get_type_hints(cls, include_extras=True)


@functools.cache
def _byte_members(cls: type) -> frozenset[str]:
    return frozenset(name for name, hint in _members(cls).items() if _is_bytes(hint))


def to_fields(message: Any) -> dict[str, Any]:
    """A received message as a plain dict (``uint8[]`` as bytes)."""
    fields: dict[str, Any] = {}
    byte_members = _byte_members(type(message))
    for name in _members(type(message)):
        value = getattr(message, name)
        if dataclasses.is_dataclass(value):
            value = to_fields(value)
        elif name in byte_members:
            value = bytes(value)
        elif isinstance(value, list):
            value = [to_fields(item) if dataclasses.is_dataclass(item) else item for item in value]
        fields[name] = value
    return fields


def _default(hint: Any) -> Any:
    if _is_bytes(hint):
        return b""
    if any(isinstance(arg, sequence) for arg in typing.get_args(hint)):
        return []
    if hint is str:
        return ""
    if isinstance(hint, type) and issubclass(hint, IdlStruct):
        return from_fields(hint, {})
    return 0


def from_fields(cls: type[IdlStruct], fields: dict[str, Any]) -> IdlStruct:
    """A message of ``cls`` from a dict; a member the dict leaves out is zero (0, "", [], b"", a
    nested message of zeros), as a ROS 2 message's constructor leaves it. ValueError for a member
    the message does not have."""
    members = _members(cls)
    unknown = set(fields) - set(members)
    if unknown:
        raise ValueError(f"{cls.__name__} has no member {', '.join(sorted(unknown))} (it has {', '.join(members)})")
    values = {}
    for name, hint in members.items():
        if name not in fields:
            values[name] = _default(hint)
        elif isinstance(fields[name], dict):
            values[name] = from_fields(hint, fields[name])
        else:
            values[name] = fields[name]
    return cls(**values)
