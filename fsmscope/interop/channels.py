"""What fsmscope's events become on the channels Foxglove reads: one mapping, used by the MCAP
writer (mcap_log.py) and the live Foxglove server (foxglove_live.py).

- ``/fsmscope/<machine>/events``: every event but snapshots, JSON, schema ``fsmscope.Event``
  (made from fsm.observation.schema);
- ``/fsmscope/<machine>/state``: at each structure, start, transition and terminate, the deepest
  active state's path (``active``, "" when idle) and every active state's, JSON, ``fsmscope.State``
  (Foxglove's State Transitions and Plot panels);
- ``/fsmscope/log``: the transcript's lines (what ``fsmscope replay`` prints), ``foxglove.Log``;
- ``/tf``: a recorded pose as ``foxglove.FrameTransform`` messages, one per frame.

Foxglove's well-known messages (``foxglove.Log``, ``foxglove.FrameTransform``) and their schemas
come from ``foxglove-sdk``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from foxglove.messages import FrameTransform, Log, LogLevel, Quaternion, Timestamp, Vector3

from fsm.logfiles.transcript import Transcript
from fsm.observation import schema
from fsm.observation.status import Status

EVENTS = "/fsmscope/%s/events"
STATE = "/fsmscope/%s/state"
LOG = "/fsmscope/log"
TF = "/tf"
LEVELS = {"debug": LogLevel.Debug, "info": LogLevel.Info, "warn": LogLevel.Warning, "error": LogLevel.Error}
STATE_KINDS = ("start", "transition", "terminate", "structure")

# (parent frame, child frame, [x, y, z], [qw, qx, qy, qz]) of one pose event
Frame = tuple[str, str, list[float], list[float]]


def _event_schema() -> dict:
    """The JSON Schema of an event, from fsm.observation.schema (the envelope; each kind's own fields
    are named in its description)."""
    return {"title": "fsmscope.Event", "type": "object", "description": "An fsmscope event (docs/events.md).",
            "properties": {"v": {"type": "integer"}, "seq": {"type": "integer"}, "t": {"type": "number"},
                           "run": {"type": ["string", "null"]}, "machine": {"type": "string"},
                           "kind": {"enum": sorted(k for k in schema.KINDS if k != "snapshot"),
                                    "description": "; ".join("%s: %s" % (k.name, k.doc)
                                                             for k in schema.KINDS.values())},
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


@dataclass
class Message:
    """One message for ``topic`` at ``t``: JSON (``data`` with its ``schema``) or one of Foxglove's own
    (``data`` a foxglove.messages object, ``schema`` None)."""

    topic: str
    t: float
    data: dict | Log | FrameTransform
    schema: dict | None = None


def body_frames(event: dict) -> list[Frame]:
    """A pose event's free bodies, each a frame of the world."""
    return [("world", name, list(pose[:3]), list(pose[3:7])) for name, pose in (event.get("bodies") or {}).items()]


def nanoseconds(t: float) -> int:
    """An event's ``t`` (seconds) as the nanoseconds MCAP and Foxglove count in."""
    return max(0, int(round(t * 1e9)))


def stamp(t: float) -> Timestamp:
    ns = nanoseconds(t)
    return Timestamp(sec=ns // 10**9, nsec=ns % 10**9)


class Channels:
    """The messages of a stream of events (in order: each machine's Status and the transcript follow it)."""

    def __init__(self, frames: Callable[[dict], list[Frame]] | None = None) -> None:
        self.frames = frames or body_frames
        self.statuses: dict[str, Status] = {}
        self.transcript = Transcript()

    def messages(self, event: dict) -> list[Message]:
        """What ``event`` puts on the channels. A snapshot (a machine joined mid-run) puts its active
        states only: it is no event of the run."""
        machine, t = event["machine"], event["t"]
        if event["kind"] == "snapshot":
            status = self.statuses[machine] = Status.from_dict(dict(event["status"], machine=machine))
            self.transcript.structures.apply(event)
            return [self._state(status, event)]
        out = [Message(EVENTS % machine, t, event, EVENT_SCHEMA)]
        status = self.statuses.setdefault(machine, Status(machine))
        status.apply(event)
        if event["kind"] in STATE_KINDS:
            out.append(self._state(status, event))
        for line in self.transcript.lines(event):
            out.append(Message(LOG, t, Log(timestamp=stamp(t), level=LEVELS.get(line.level, LogLevel.Info),
                                           message=line.msg, name=machine + ":" + line.path, file="", line=0)))
        if event["kind"] == "pose":
            for parent, child, xyz, wxyz in self.frames(event):
                out.append(Message(TF, t, FrameTransform(
                    timestamp=stamp(t), parent_frame_id=parent, child_frame_id=child,
                    translation=Vector3(x=xyz[0], y=xyz[1], z=xyz[2]),
                    rotation=Quaternion(x=wxyz[1], y=wxyz[2], z=wxyz[3], w=wxyz[0]))))
        return out

    @staticmethod
    def _state(status: Status, event: dict) -> Message:
        active = status.active_leaves()
        return Message(STATE % event["machine"], event["t"], {"active": max(active, key=len, default=""),
                                                              "active_states": active, "seq": event["seq"],
                                                              "kind": event["kind"]}, STATE_SCHEMA)
