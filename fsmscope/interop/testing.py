"""ROS bags of SMACH runs written as smach_ros's IntrospectionServer publishes them, for the tests and
the benchmarks (rosbags' writers; a run is given as the messages it publishes)."""

from __future__ import annotations

import base64
import pickle
from pathlib import Path

import numpy
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2

from . import bag_reader, smach_msgs


def _message(store, kind: str, fields: dict, t: float, ros2: bool, raw_pickle: bool):
    Header, Time = store.types["std_msgs/msg/Header"], store.types["builtin_interfaces/msg/Time"]
    stamp = Time(sec=int(t), nanosec=int(round((t % 1) * 1e9)))
    header = Header(stamp=stamp, frame_id="") if ros2 else Header(seq=0, stamp=stamp, frame_id="")
    if kind == "structure":
        return store.types[smach_msgs.STRUCTURE](header=header, **fields)
    data = {k: v for k, v in fields.items() if k != "userdata"}
    pickled = fields["userdata"] if isinstance(fields["userdata"], bytes) else pickle.dumps(fields["userdata"], 2)
    if ros2 or raw_pickle:
        data["local_data"] = numpy.frombuffer(pickled, dtype=numpy.uint8)
    else:
        data["local_data"] = base64.b64encode(pickled).decode()
    return store.types[smach_msgs.STATUS](header=header, **data)


def write_bag(path: Path, layout: str, runs: list[tuple[float, str, str, dict]]) -> Path:
    """``runs``, (t, topic, kind "structure" or "status", fields; a status's ``userdata`` is pickled as
    smach_ros does, or is the pickle when bytes), written to a bag at ``path``: ``layout`` "ros1" (noetic: base64 of the pickle),
    "ros1-raw" (the raw pickle of older releases), "ros2-sqlite3" or "ros2-mcap"."""
    ros2 = layout.startswith("ros2")
    raw = layout == "ros1-raw"
    store = smach_msgs.typestore(ros2=ros2, local_data_bytes=raw)
    types = {"structure": smach_msgs.STRUCTURE, "status": smach_msgs.STATUS}
    if ros2:
        plugin = StoragePlugin.MCAP if layout == "ros2-mcap" else StoragePlugin.SQLITE3
        writer = Writer2(path, version=8, storage_plugin=plugin)
    else:
        writer = Writer1(path)
    with writer:
        connections = {}
        for t, topic, kind, fields in runs:
            if topic not in connections:
                if raw and kind == "status":  # the wire form of a raw pickle's string: the noetic md5 and definition
                    noetic = smach_msgs.typestore(ros2=False)
                    msgdef, md5 = noetic.generate_msgdef(types[kind])
                    connections[topic] = writer.add_connection(topic, types[kind], msgdef=msgdef, md5sum=md5)
                else:
                    connections[topic] = writer.add_connection(topic, types[kind], typestore=store)
            msg = _message(store, kind, fields, t, ros2, raw)
            data = store.serialize_cdr(msg, types[kind]) if ros2 else store.serialize_ros1(msg, types[kind])
            writer.write(connections[topic], int(t * 1e9), data)
    return path


def container_run(server: str, structures: dict[str, tuple[list, list, list]],
                  statuses: list[tuple[float, str, list, list, dict]], t0: float = 1.7e9) -> list:
    """The messages (t, topic, kind, fields) of a server: each container's structure at ``t0``
    (``structures``: path -> (children, edges (outcome, from, to), outcomes)), then ``statuses``
    (seconds after ``t0``, path, initial states, active states, userdata)."""
    run = [(t0, "/%s/smach/container_structure" % server, "structure", {
        "path": path, "children": children, "internal_outcomes": [e[0] for e in edges],
        "outcomes_from": [e[1] for e in edges], "outcomes_to": [e[2] for e in edges], "container_outcomes": outcomes})
        for path, (children, edges, outcomes) in structures.items()]
    run += [(t0 + t, "/%s/smach/container_status" % server, "status", {
        "path": path, "initial_states": initial, "active_states": active, "userdata": userdata, "info": "HEARTBEAT"})
        for t, path, initial, active, userdata in statuses]
    return run


def wide_run(children: int) -> list:
    """A machine of one container with ``children`` states in a chain (S0 -> S1 -> ... -> done), run
    from S0 to S1, then ended."""
    labels = ["S%d" % i for i in range(children)]
    edges = [("next", label, labels[i + 1] if i + 1 < children else "done") for i, label in enumerate(labels)]
    return container_run("wide", {"/ROOT": (labels, edges, ["done"])},
                         [(0.0, "/ROOT", ["S0"], ["S0"], {}), (1.0, "/ROOT", ["S0"], ["S1"], {}),
                          (2.0, "/ROOT", ["S0"], ["None"], {})])


ROS2_LEVELS = {1: 10, 2: 20, 4: 30, 8: 40, 16: 50}  # rosgraph_msgs/Log's levels as rcl_interfaces/msg/Log's


def rewrite(recorded: Path, out: Path, layout: str, rosout: bool = True, since: float = 0.0,
            until: float | None = None) -> Path:
    """The messages of a ROS 1 bag ``recorded`` (smach_ros's introspection, /rosout) written again at
    ``out``, those recorded from ``since`` to ``until`` (seconds, the bag's time: a recorder that joined
    late, or stopped early):
    ``layout`` "ros1" (the same connections and bytes; without /rosout unless ``rosout``), or
    "ros2-sqlite3" / "ros2-mcap" as a ROS 2 robot publishes them (``local_data`` the raw pickle, the
    Log as rcl_interfaces', the node's name without its slash)."""
    from rosbags.highlevel import AnyReader

    kept = smach_msgs.STRUCTURE, smach_msgs.STATUS, "rosgraph_msgs/msg/Log"
    with AnyReader([recorded]) as reader:
        wanted = [c for c in reader.connections if c.msgtype in kept[:2] or (rosout and c.msgtype == kept[2])]
        if layout == "ros1":
            with Writer1(out) as writer:
                made = {c.id: writer.add_connection(c.topic, c.msgtype, msgdef=c.msgdef.data, md5sum=c.digest,
                                                    callerid=c.ext.callerid, latching=c.ext.latching) for c in wanted}
                for c, t, raw in reader.messages(connections=wanted, start=int(since * 1e9),
                                                 stop=None if until is None else int(until * 1e9)):
                    writer.write(made[c.id], t, raw)
            return out
        store = smach_msgs.typestore(ros2=True)
        plugin = StoragePlugin.MCAP if layout == "ros2-mcap" else StoragePlugin.SQLITE3
        with Writer2(out, version=8, storage_plugin=plugin) as writer:
            made = {}
            for c, t, raw in reader.messages(connections=wanted):
                msgtype = "rcl_interfaces/msg/Log" if c.msgtype == kept[2] else c.msgtype
                if c.topic not in made:
                    made[c.topic] = writer.add_connection(c.topic, msgtype, typestore=store)
                msg = _ros2(store, reader.deserialize(raw, c.msgtype), c.msgtype)
                writer.write(made[c.topic], t, store.serialize_cdr(msg, msgtype))
    return out


def _ros2(store, msg, msgtype: str):
    """A ROS 1 message (smach_msgs', a Log) as its ROS 2 counterpart."""
    Time = store.types["builtin_interfaces/msg/Time"]
    stamp = Time(sec=msg.header.stamp.sec, nanosec=msg.header.stamp.nanosec)
    if msgtype == "rosgraph_msgs/msg/Log":
        return store.types["rcl_interfaces/msg/Log"](stamp=stamp, level=ROS2_LEVELS.get(msg.level, 20),
                                                      name=msg.name.lstrip("/"), msg=msg.msg, file=msg.file,
                                                      function=msg.function, line=msg.line)
    header = store.types["std_msgs/msg/Header"](stamp=stamp, frame_id=msg.header.frame_id)
    fields = {name: getattr(msg, name) for name in (bag_reader.STRUCTURE_FIELDS if msgtype == smach_msgs.STRUCTURE
                                                     else bag_reader.STATUS_FIELDS)}
    if msgtype == smach_msgs.STATUS:
        fields["local_data"] = numpy.frombuffer(base64.b64decode(msg.local_data), dtype=numpy.uint8)
    return store.types[msgtype](header=header, **fields)
