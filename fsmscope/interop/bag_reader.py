"""The SMACH introspection messages of a ROS bag, and SMACH's lines on /rosout, read with rosbags (no
ROS needed).

smach_ros's IntrospectionServer publishes ``<server>/smach/container_structure`` and
``<server>/smach/container_status``; every introspection server of the bag is found by those
topics. SMACH logs through rospy (rclpy), whose lines go to ``/rosout`` (and ``/rosout_agg``) with
the node's name: those that are SMACH's are kept. The messages come out in the bag's order (each
topic's as recorded; ``smach_events.in_time_order`` merges them by stamp) as plain dicts. ROS 1
``.bag`` files and ROS 2 bags (a folder with metadata.yaml, or its ``.db3`` / ``.mcap`` file) are read.
"""

from __future__ import annotations

import shutil
import sqlite3
import tempfile
from contextlib import closing
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator

from rosbags.highlevel import AnyReader

from . import smach_lines, smach_msgs
from .mcap_header import mcap_header
from .to_log import ReadError

STRUCTURE_FIELDS = ("path", "children", "internal_outcomes", "outcomes_from", "outcomes_to", "container_outcomes")
STATUS_FIELDS = ("path", "initial_states", "active_states", "info")
LOG_TOPICS = ("/rosout", "/rosout_agg")
LOG_TYPES = ("rosgraph_msgs/msg/Log", "rcl_interfaces/msg/Log")


class BagError(ReadError):
    """The bag cannot be read, or holds no SMACH introspection; the message says which."""


@dataclass
class Message:
    """One message: ``t`` in seconds (its stamp, else the bag's time), the server it came from,
    ``kind`` "structure" or "status" (its fields; ``local_data`` as bytes), or "log" (a SMACH line
    of /rosout: ``msg``, ``level`` as the Log message has it, ``name`` its node; ``server`` empty);
    ``node``: the publisher's name (a ROS 1 connection's caller id; a line's node), None when unknown."""

    t: float
    server: str
    kind: str
    fields: dict
    node: str | None = None


def is_bag(path: str) -> bool:
    """Whether ``path`` looks like a ROS bag (by its name and layout; its content is read later)."""
    p = Path(path)
    if p.is_dir():
        return (p / "metadata.yaml").exists()
    return p.suffix in (".bag", ".db3") or (p.suffix == ".mcap" and getattr(mcap_header(path), "profile", "") == "ros2")


def _server(topic: str) -> tuple[str, str] | None:
    for kind, suffix in (("structure", smach_msgs.STRUCTURE_TOPIC), ("status", smach_msgs.STATUS_TOPIC)):
        if topic.endswith(suffix):
            return topic[:-len(suffix)].strip("/") or "smach", kind
    return None


def read_bag(path: str) -> Iterator[Message]:
    """Every introspection message of the bag at ``path``, and SMACH's lines of /rosout, in the bag's
    order. Raises ``BagError``."""
    p = Path(path)
    if not p.exists():
        raise BagError("%s: no such file or folder" % path)
    with tempfile.TemporaryDirectory(prefix="fsmscope-bag-") as folder:
        yield from _read(path, _without_unknown_definitions(p, Path(folder)))


def _without_unknown_definitions(p: Path, folder: Path) -> Path:
    """The bag, or a copy of it in ``folder`` without the definitions a ROS 2 sqlite3 bag marks
    ``unknown`` (rosbag2 writes that for a type it had no definition of, which rosbags cannot read:
    without them it reads the types it knows, smach_msgs' and the Log's)."""
    bag = p if p.is_dir() else p.parent
    dbs = sorted(bag.glob("*.db3")) if (bag / "metadata.yaml").exists() and p.suffix != ".bag" else []
    try:
        if not any(_unknown_definitions(db) for db in dbs):
            return p
        copy = folder / bag.name
        shutil.copytree(bag, copy)
        for db in sorted(copy.glob("*.db3")):
            with closing(sqlite3.connect(db)) as con, con:
                con.execute("DELETE FROM message_definitions WHERE encoding = 'unknown'")
        return copy if p.is_dir() else copy / p.name
    except (OSError, sqlite3.Error):  # rosbags then says what is wrong with it
        return p


def _unknown_definitions(db: Path) -> bool:
    with closing(sqlite3.connect(db.resolve().as_uri() + "?mode=ro", uri=True)) as con:
        try:
            found = con.execute("SELECT 1 FROM message_definitions WHERE encoding = 'unknown' LIMIT 1").fetchone()
        except sqlite3.OperationalError:  # an older bag: no such table
            return False
        return found is not None


def _read(path: str, p: Path) -> Iterator[Message]:
    ros2 = p.suffix != ".bag"
    try:
        reader = AnyReader([p], default_typestore=smach_msgs.typestore(ros2=True) if ros2 else None)
        reader.open()
    except Exception as exc:  # rosbags raises its own errors, sqlite's, KeyError for odd definitions
        raise BagError("%s: cannot read this bag (%s: %s)" % (path, type(exc).__name__, exc)) from None
    try:
        found = {c.id: _server(c.topic) for c in reader.connections}
        wanted = [c for c in reader.connections
                  if found[c.id] and c.msgtype in (smach_msgs.STRUCTURE, smach_msgs.STATUS)]
        logs = [c for c in reader.connections if c.topic in LOG_TOPICS and c.msgtype in LOG_TYPES]
        if not wanted:
            topics = sorted({c.topic for c in reader.connections})
            raise BagError("%s: no SMACH introspection topics (…%s, …%s) among its %d topics%s" % (
                path, smach_msgs.STRUCTURE_TOPIC, smach_msgs.STATUS_TOPIC, len(topics),
                (": " + ", ".join(topics[:8])) if topics else ""))
        lenient = None if ros2 else smach_msgs.typestore(ros2=False, local_data_bytes=True)
        ours = None if ros2 else smach_msgs.typestore(ros2=False).generate_msgdef(smach_msgs.STATUS)[1]
        count = 0
        try:
            agg = {c.id for c in logs if c.topic == "/rosout_agg"} if len({c.topic for c in logs}) > 1 else set()
            for connection, stamp, raw in reader.messages(connections=wanted + [c for c in logs if c.id not in agg]):
                if connection.msgtype in LOG_TYPES:
                    line = _line(reader.deserialize(raw, connection.msgtype), stamp)
                    if line is not None:
                        yield line
                    continue
                server, kind = found[connection.id]
                if kind == "status" and lenient is not None and connection.digest == ours:
                    msg = lenient.deserialize_ros1(raw, smach_msgs.STATUS)  # a raw pickle is no UTF-8
                else:
                    msg = reader.deserialize(raw, connection.msgtype)
                yield Message(_time(msg.header.stamp, stamp), server, kind, introspection_fields(lambda name: getattr(msg, name), kind),
                              getattr(connection.ext, "callerid", None))
                count += 1
        except BagError:
            raise
        except Exception as exc:  # a bag cut short: what came before it was yielded
            raise BagError("%s: the bag is damaged after %d introspection messages (%s: %s)" % (
                path, count, type(exc).__name__, exc)) from None
    finally:
        reader.close()


def _line(log: object, stamp_ns: int) -> Message | None:
    """A Log message as a "log" Message when it is one of SMACH's lines, else None."""
    if not smach_lines.is_smach(log.msg):
        return None
    stamp = log.stamp if hasattr(log, "stamp") else log.header.stamp  # ROS 2's Log has no header
    return Message(_time(stamp, stamp_ns), "", "log", {"msg": log.msg, "level": int(log.level), "name": log.name},
                   log.name)


def _time(stamp: object, stamp_ns: int) -> float:
    return stamp.sec + stamp.nanosec * 1e-9 if stamp.sec or stamp.nanosec else stamp_ns * 1e-9


def introspection_fields(value_of: Callable[[str], Any], kind: str) -> dict:
    """A structure's or a status's fields as the converter takes them (``value_of(name)`` reads one from
    a bag's message or a live one): the header left out, ``local_data`` as bytes."""
    names = STRUCTURE_FIELDS if kind == "structure" else STATUS_FIELDS
    out = {name: value_of(name) for name in names}
    if kind == "status":
        data = value_of("local_data")
        out["local_data"] = data.encode("utf-8", "surrogateescape") if isinstance(data, str) else bytes(data)
    return out

