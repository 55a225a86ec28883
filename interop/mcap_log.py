"""fsmscope's events in MCAP, the robotics world's log format, which Foxglove opens (docs/interop.md).

Written with the ``mcap`` library; Foxglove's well-known schemas (``foxglove.Log``,
``foxglove.FrameTransform``) and their protobuf encoding come from ``foxglove-sdk``. Channels:

- ``/fsmscope/<machine>/events``: every event of the machine but snapshots, JSON, schema
  ``fsmscope.Event`` (made from fsm.observation.schema): what ``fsmscope replay`` reads back;
- ``/fsmscope/<machine>/state``: at each start, transition and terminate, the deepest active
  state's path (``active``, "" when idle) and every active state's, JSON, schema ``fsmscope.State``
  (Foxglove's State Transitions and Plot panels);
- ``/fsmscope/log``: the transcript's lines (what ``fsmscope replay`` prints), ``foxglove.Log``;
- ``/tf``: the robot's recorded pose as ``foxglove.FrameTransform`` messages (``frames`` gives each
  pose event's frames), for Foxglove's 3D panel.

Each message's log time is its event's ``t``; an event's ``sequence`` is its place in the log, so
the events read back in the order they were written (not re-sorted by a wall clock).
"""

from __future__ import annotations

import json
import os
import struct
from typing import IO, Callable, Iterable, Iterator

from foxglove.messages import FrameTransform, Log, LogLevel, Quaternion, Timestamp, Vector3
from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader, make_reader
from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap.writer import Writer

from fsm.logfiles.transcript import Transcript
from fsm.observation import schema
from fsm.observation.encoding import dumps, loads
from fsm.observation.status import Status

from .to_log import ReadError

LIBRARY = "fsmscope"  # the MCAP header's library: how ``is_fsmscope_mcap`` knows a file as ours
EVENTS = "/fsmscope/%s/events"
STATE = "/fsmscope/%s/state"
LOG = "/fsmscope/log"
TF = "/tf"
LEVELS = {"debug": LogLevel.Debug, "info": LogLevel.Info, "warn": LogLevel.Warning, "error": LogLevel.Error}
STATE_KINDS = ("start", "transition", "terminate", "structure")
CHUNK_BYTES = 256 << 10  # a file cut short loses the chunk it was cut in: at most this much

# (parent frame, child frame, [x, y, z], [qw, qx, qy, qz]) of one pose event
Frame = tuple[str, str, list[float], list[float]]


class McapLogError(ReadError):
    """The file is no MCAP fsmscope wrote, or is damaged; the message says which."""


def _event_schema() -> dict:
    """The JSON Schema of an event, from fsm.observation.schema (the envelope; each kind's own fields
    are named in its description)."""
    return {"title": "fsmscope.Event", "type": "object", "description": "An fsmscope event (docs/events.md).",
            "properties": {"v": {"type": "integer"}, "seq": {"type": "integer"}, "t": {"type": "number"},
                           "run": {"type": ["string", "null"]}, "machine": {"type": "string"},
                           "kind": {"enum": sorted(k for k in schema.KINDS if k != "snapshot"),
                                    "description": "; ".join("%s: %s" % (k.name, k.doc) for k in schema.KINDS.values())},
                           "path": {"type": "string"}},
            "required": ["v", "seq", "t", "run", "machine", "kind", "path"]}


EVENT_SCHEMA = _event_schema()
STATE_SCHEMA = {"title": "fsmscope.State", "type": "object",
                "description": "The machine's active states after an event: Foxglove's State Transitions panel "
                               "plots `active`.",
                "properties": {"active": {"type": "string", "description": "the deepest active state's path, "
                                                                            "'' when idle"},
                               "active_states": {"type": "array", "items": {"type": "string"}},
                               "seq": {"type": "integer"}, "kind": {"type": "string"}},
                "required": ["active", "active_states", "seq", "kind"]}


def _ns(t: float) -> int:
    return max(0, int(round(t * 1e9)))


def _stamp(t: float) -> Timestamp:
    ns = _ns(t)
    return Timestamp(sec=ns // 10**9, nsec=ns % 10**9)


class _Out:
    """The writer and its channels, registered as they are first needed."""

    def __init__(self, stream: IO[bytes]) -> None:
        self.writer = Writer(stream, chunk_size=CHUNK_BYTES)
        self.writer.start(profile="", library=LIBRARY)
        self.schemas: dict[str, int] = {}
        self.channels: dict[str, int] = {}
        self.count = 0

    def schema(self, name: str, encoding: str, data: bytes) -> int:
        if name not in self.schemas:
            self.schemas[name] = self.writer.register_schema(name=name, encoding=encoding, data=data)
        return self.schemas[name]

    def channel(self, topic: str, encoding: str, schema_id: int) -> int:
        if topic not in self.channels:
            self.channels[topic] = self.writer.register_channel(topic=topic, message_encoding=encoding,
                                                                schema_id=schema_id)
        return self.channels[topic]

    def json(self, topic: str, schema_: dict, t: float, message: dict) -> None:
        channel = self.channels.get(topic)
        if channel is None:
            sid = self.schema(schema_["title"], SchemaEncoding.JSONSchema, json.dumps(schema_).encode())
            channel = self.channel(topic, MessageEncoding.JSON, sid)
        self._add(channel, t, dumps(message))

    def foxglove(self, topic: str, message: Log | FrameTransform, t: float) -> None:
        channel = self.channels.get(topic)
        if channel is None:
            known = type(message).get_schema()
            channel = self.channel(topic, known.encoding, self.schema(known.name, known.encoding, bytes(known.data)))
        self._add(channel, t, message.encode())

    def _add(self, channel: int, t: float, data: bytes) -> None:
        self.writer.add_message(channel_id=channel, log_time=_ns(t), publish_time=_ns(t), data=data,
                                sequence=self.count)
        self.count += 1


def write_mcap(events: Iterable[dict], out: str, frames: Callable[[dict], list[Frame]] | None = None) -> int:
    """The events (snapshots left out) into a new MCAP file ``out``; the number of events written.
    ``frames``: a pose event's frames (default: its free bodies', from the world)."""
    if os.path.exists(out):
        raise McapLogError("%s exists already" % out)
    frames = frames or body_frames
    partial = out + ".partial"
    statuses: dict[str, Status] = {}
    transcript = Transcript()
    written = 0
    try:
        with open(partial, "wb") as stream:
            o = _Out(stream)
            for event in events:
                if event["kind"] == "snapshot":
                    continue
                machine, t = event["machine"], event["t"]
                o.json(EVENTS % machine, EVENT_SCHEMA, t, event)
                written += 1
                status = statuses.setdefault(machine, Status(machine))
                status.apply(event)
                if event["kind"] in STATE_KINDS:
                    active = status.active_leaves()
                    o.json(STATE % machine, STATE_SCHEMA, t, {"active": max(active, key=len, default=""),
                                                              "active_states": active, "seq": event["seq"],
                                                              "kind": event["kind"]})
                for line in transcript.lines(event):
                    o.foxglove(LOG, Log(timestamp=_stamp(t), level=LEVELS.get(line.level, LogLevel.Info),
                                        message=line.msg, name=machine + ":" + line.path, file="", line=0), t)
                if event["kind"] == "pose":
                    for parent, child, xyz, wxyz in frames(event):
                        o.foxglove(TF, FrameTransform(
                            timestamp=_stamp(t), parent_frame_id=parent, child_frame_id=child,
                            translation=Vector3(x=xyz[0], y=xyz[1], z=xyz[2]),
                            rotation=Quaternion(x=wxyz[1], y=wxyz[2], z=wxyz[3], w=wxyz[0])), t)
            o.writer.finish()
    except BaseException:
        if os.path.exists(partial):
            os.remove(partial)
        raise
    os.replace(partial, out)
    return written


def body_frames(event: dict) -> list[Frame]:
    """A pose event's free bodies, each a frame of the world."""
    return [("world", name, list(pose[:3]), list(pose[3:7])) for name, pose in (event.get("bodies") or {}).items()]


def is_fsmscope_mcap(path: str) -> bool:
    """Whether ``path`` is an MCAP file fsmscope wrote (its header's library)."""
    try:
        with open(path, "rb") as f:
            return make_reader(f).get_header().library.startswith(LIBRARY)
    except Exception:  # not an MCAP, unreadable: not ours
        return False


def read_mcap(path: str, on_problem: Callable[[str], None] | None = None) -> Iterator[dict]:
    """The events of an MCAP file ``write_mcap`` wrote, in the order written; a message that is no
    event of the schema is skipped (``on_problem`` hears why). A file cut short yields every event
    before the cut, then raises ``McapLogError``."""
    read = 0
    try:
        with open(path, "rb") as f:
            for _, channel, message in NonSeekingReader(f).iter_messages(log_time_order=False):
                if not (channel.topic.startswith("/fsmscope/") and channel.topic.endswith("/events")):
                    continue
                try:
                    event = loads(message.data)
                except ValueError as exc:
                    problem = "a message of %s that is no JSON (%s)" % (channel.topic, exc)
                else:
                    problem = schema.validate(event)
                if problem is None:
                    read += 1
                    yield event
                elif on_problem is not None:
                    on_problem(problem)
    except (McapError, struct.error, EOFError, ValueError) as exc:
        raise McapLogError("%s is damaged after %d events (%s: %s)" % (path, read, type(exc).__name__, exc)) from None
