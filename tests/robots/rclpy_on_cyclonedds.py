"""The smallest stand-in for rclpy that executive_smach's ``ros2`` branch's smach_ros/introspection.py
runs on, built on cyclonedds as rmw_cyclonedds builds a ROS 2 node, so that tests/ros2/ can run that
file itself, unchanged, as a robot would, with no ROS 2 here (its README says none can be installed).

``install(msg_dir)`` puts modules named rclpy, rclpy.node, rclpy.clock, rclpy.executors,
rclpy.logging, builtin_interfaces.msg, std_msgs.msg, rcl_interfaces.msg and smach_msgs.msg in
``sys.modules``. It is written apart from fsmscope.ros2 (whose names, layouts and QoS the tests check
against it) from ROS 2's documents:

* names: a topic ``/a/b`` is DDS's ``rt/a/b``, a relative name is under the node's namespace ``/``;
  a type ``pkg/msg/Name`` is ``pkg::msg::dds_::Name_`` (design doc "Topic and Service name mapping
  to DDS");
* layouts: generated here from the .msg files (smach_msgs' from the ros2 branch's msg folder; the
  four others' text below, as their packages have it), as rosidl does: a final struct, members in
  order, ``T[]`` a sequence, an empty message given ``uint8 structure_needs_at_least_one_member``;
  a received ``uint8[]`` is an ``array('B')``, as rclpy gives it;
* QoS: a depth ``N`` is rmw's default profile with that depth (reliable, volatile, keep last N),
  written as XCDR1; /rosout's publisher is reliable, transient-local, keep last 1000;
* one DDS participant per process (an rclpy context), every node of it a user of that participant.
"""
import array
import sys
import threading
import time
import types
from pathlib import Path

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import make_idl_struct
from cyclonedds.idl import types as idl
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

TIME_MSG = "int32 sec\nuint32 nanosec\n"
HEADER_MSG = "builtin_interfaces/Time stamp\nstring frame_id\n"
EMPTY_MSG = ""
LOG_MSG = """byte DEBUG=10
byte INFO=20
byte WARN=30
byte ERROR=40
byte FATAL=50
builtin_interfaces/Time stamp
uint8 level
string name # name of the node
string msg # message
string file # file the message came from
string function # function the message came from
uint32 line # line the message came from
"""
PRIMITIVES = {"bool": bool, "byte": idl.byte, "char": idl.char, "int8": idl.int8, "uint8": idl.uint8,
              "int16": idl.int16, "uint16": idl.uint16, "int32": idl.int32, "uint32": idl.uint32,
              "int64": idl.int64, "uint64": idl.uint64, "float32": idl.float32, "float64": idl.float64,
              "string": str}
_messages = {}      # "pkg/msg/Name" -> class
_state = {"participant": None, "ok": False, "domain_id": 0, "rosout": None}


def _message(package, name, text):
    """A message class from a .msg file's text, as rosidl lays it out on DDS."""
    members, zeros, byte_members = {}, {}, set()
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line or "=" in line:
            continue
        kind, member = line.split()[:2]
        is_sequence = kind.endswith("[]")
        base = kind[:-2] if is_sequence else kind
        if base in PRIMITIVES:
            member_type, zero = PRIMITIVES[base], ("" if base == "string" else 0)
        else:
            ref = base if "/" in base else ("std_msgs/" + base)
            pkg, nested = ref.split("/")[0], ref.split("/")[-1]
            member_type = _messages[f"{pkg}/msg/{nested}"]
            zero = member_type
        if is_sequence:
            member_type, zero = idl.sequence[member_type], list
            if base == "uint8":
                byte_members.add(member)
        members[member] = member_type
        zeros[member] = zero
    if not members:
        members["structure_needs_at_least_one_member"] = idl.uint8
        zeros["structure_needs_at_least_one_member"] = 0
    cls = make_idl_struct(name, f"{package}::msg::dds_::{name}_", members)
    dataclass_init = cls.__init__

    def __init__(self, *args, **kwargs):
        for member in list(members)[len(args):]:
            if member not in kwargs:
                zero = zeros[member]
                kwargs[member] = zero() if callable(zero) else zero
        dataclass_init(self, *args, **kwargs)
    cls.__init__ = __init__
    cls._byte_members = byte_members
    _messages[f"{package}/msg/{name}"] = cls
    return cls


def _module(name, **attributes):
    module = types.ModuleType(name)
    module.__dict__.update(attributes)
    sys.modules[name] = module
    return module


def _participant():
    if _state["participant"] is None:
        _state["participant"] = DomainParticipant(_state["domain_id"])
    return _state["participant"]


def _qos(depth, transient_local=False):
    return Qos(Policy.Reliability.Reliable(duration(milliseconds=100)),
               Policy.Durability.TransientLocal if transient_local else Policy.Durability.Volatile,
               Policy.History.KeepLast(depth), Policy.DataRepresentation(use_cdrv0_representation=True))


def _dds_topic(name, msg_type):
    absolute = name if name.startswith("/") else "/" + name
    return Topic(_participant(), "rt" + absolute, msg_type)


class Time:
    def __init__(self, nanoseconds):
        self.nanoseconds = nanoseconds

    def to_msg(self):
        return _messages["builtin_interfaces/msg/Time"](sec=self.nanoseconds // 10**9,
                                                        nanosec=self.nanoseconds % 10**9)


class ROSClock:
    def now(self):
        return Time(time.time_ns())


class Logger:
    """Prints as rclpy's console does; a node's logger also publishes on /rosout, as rcl does."""

    def __init__(self, name, rosout=False):
        self.name, self.rosout = name, rosout

    def _log(self, level, severity, msg):
        print(f"[{severity}] [{time.time():.9f}] [{self.name}]: {msg}", flush=True)
        if self.rosout and _state["rosout"] is not None:
            log = _messages["rcl_interfaces/msg/Log"]
            _state["rosout"].write(log(stamp=ROSClock().now().to_msg(), level=level, name=self.name,
                                       msg=str(msg), file="", function="", line=0))

    def debug(self, msg):
        pass

    def info(self, msg):
        self._log(20, "INFO", msg)

    def warn(self, msg):
        self._log(30, "WARN", msg)

    warning = warn

    def error(self, msg):
        self._log(40, "ERROR", msg)


class Node:
    def __init__(self, node_name, **kwargs):
        self._name = node_name
        self._timers, self._subscriptions = [], []
        self._logger = Logger(node_name, rosout=True)
        if _state["rosout"] is None:
            _state["rosout"] = DataWriter(_participant(), _dds_topic("/rosout", _messages["rcl_interfaces/msg/Log"]),
                                          qos=_qos(1000, transient_local=True))

    def get_logger(self):
        return self._logger

    def create_publisher(self, msg_type, topic, qos_depth):
        writer = DataWriter(_participant(), _dds_topic(topic, msg_type), qos=_qos(qos_depth))
        return types.SimpleNamespace(publish=writer.write, writer=writer)

    def create_subscription(self, msg_type, topic, callback, qos_depth):
        reader = DataReader(_participant(), _dds_topic(topic, msg_type), qos=_qos(qos_depth))
        self._subscriptions.append((reader, callback, msg_type))
        return reader

    def create_timer(self, period, callback):
        self._timers.append([period, time.monotonic() + period, callback])

    def _spin_once(self):
        now = time.monotonic()
        for timer in self._timers:
            if now >= timer[1]:
                timer[1] = now + timer[0]
                timer[2]()
        for reader, callback, msg_type in self._subscriptions:
            for msg in reader.take(N=16):
                if msg.sample_info.valid_data:
                    for member in msg_type._byte_members:
                        setattr(msg, member, array.array("B", getattr(msg, member)))
                    callback(msg)


class SingleThreadedExecutor:
    def __init__(self):
        self._nodes, self._stop = [], threading.Event()

    def add_node(self, node):
        self._nodes.append(node)

    def spin(self):
        while _state["ok"] and not self._stop.is_set():
            for node in self._nodes:
                node._spin_once()
            time.sleep(0.005)

    def shutdown(self):
        self._stop.set()


def install(smach_msg_dir, domain_id):
    """Make the modules importable, on DDS domain ``domain_id`` (Cyclone's configuration from
    ``CYCLONEDDS_URI``), with smach_msgs from the .msg files in ``smach_msg_dir``."""
    _state.update(domain_id=domain_id, ok=True)
    _module("builtin_interfaces"), _module("builtin_interfaces.msg", Time=_message("builtin_interfaces", "Time", TIME_MSG))
    _module("std_msgs")
    _module("std_msgs.msg", Header=_message("std_msgs", "Header", HEADER_MSG), Empty=_message("std_msgs", "Empty", EMPTY_MSG))
    _module("rcl_interfaces"), _module("rcl_interfaces.msg", Log=_message("rcl_interfaces", "Log", LOG_MSG))
    smach = {path.stem: _message("smach_msgs", path.stem, path.read_text()) for path in sorted(Path(smach_msg_dir).glob("*.msg"))}
    _module("smach_msgs"), _module("smach_msgs.msg", **smach)
    rclpy = _module("rclpy", ok=lambda: _state["ok"], shutdown=lambda: _state.update(ok=False))
    rclpy.node = _module("rclpy.node", Node=Node)
    rclpy.clock = _module("rclpy.clock", ROSClock=ROSClock)
    rclpy.executors = _module("rclpy.executors", SingleThreadedExecutor=SingleThreadedExecutor)
    rclpy.logging = _module("rclpy.logging", get_logger=lambda name: Logger(name))
