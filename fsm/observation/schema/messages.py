"""The websocket frames: the messages around the events, defined beside them (viser's way: one place
for every message), each a JSON object whose ``type`` says which.

The page's stream (docs/api.md, "Stream") and the fleet overview's, and the publisher's link to the
server (docs/api.md, "Ingest"). ``frame.NAME(...)`` makes each, as ``build`` makes events (the
fields in their order, optional ones by keyword) and ``field_names(NAME)`` names what a reader reads;
``fsmscope/static/schema.js`` carries their JSDoc typedefs.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

from .events import EVENT
from .fields import (BOOL, JSON, LIST_STR, NAME, NUMBER, OBJECT, SEQ, STR, Field, fields_problem, list_of,
                     maker, object_of, one_of, shape, simple)
from .status import BREAKPOINT, STATUS
from .tile import TILE

MAX_PACE_MS = 10_000  # the slowest pace a page may ask for
DEADMAN_ACTIONS = ("pause", "preempt", "none")  # what a publisher does itself when an operator's link is gone
HISTORY_LIMIT = 5000  # events of the current run a new page is sent with its first snapshot, at most
COUNT = simple("an integer of 0 or more", (int,), lambda v: v >= 0)
PACE_MS = simple("an integer from 0 to %d" % MAX_PACE_MS, (int,), lambda v: 0 <= v <= MAX_PACE_MS)
HISTORY_FIELDS = (Field("complete", BOOL, doc="whether it reaches back to the run's first event"),
                  Field("events", list_of(EVENT, "a list of events"), doc="oldest first, at most %d" % HISTORY_LIMIT))


@dataclass(frozen=True)
class Message:
    """One frame: its ``type``, who sends it to whom, what it says, its fields."""

    name: str
    sender: str
    doc: str
    fields: tuple[Field, ...]


MESSAGES: dict[str, Message] = {m.name: m for m in (
    Message("snapshot", "server to page", "The machine's whole state: the first frame of a stream (unless it "
            "resumes), and again after missed.", (
                Field("status", STATUS, doc="the machine's status with its structure (docs/events.md)"),
                Field("last_seq", SEQ, doc="the seq of the last event the status includes"),
                Field("history", shape("a history (below)", "History", HISTORY_FIELDS),
                      required=False, doc="a new connection's only: the current run's events up to last_seq, "
                                          "for the log (already in the status: not to be applied again)"))),
    Message("events", "server to page", "Events in seq order: one per frame while the page keeps up, every "
            "event of the last 20 ms under a flood, or of the page's pace.", (
                Field("events", list_of(EVENT, "a list of events")),)),
    Message("missed", "server to page", "The page fell behind and this many events were dropped for it; a "
            "snapshot follows.", (Field("count", COUNT),)),
    Message("pace", "page to server", "At most one frame every ms from now on, each with every event since "
            "the one before (0: each as it comes).", (Field("ms", PACE_MS),)),
    Message("overview", "server to page", "The fleet overview's tiles (GET /api/overview's), at most twice a "
            "second, when a tile changed.", (
                Field("now", NUMBER, doc="the server's clock"),
                Field("tiles", list_of(TILE, "a list of tiles"), doc="as GET /api/overview"))),
    Message("hello", "publisher to server", "Which of its machines take controls (and may be started again): "
            "first on each connection, again when a machine is attached; each replaces the last.", (
                Field("controllable", LIST_STR, doc="machine names"),
                Field("can_start", object_of(BOOL, "an object of booleans"),
                      doc="{name: whether it may be started again}"))),
    Message("control", "server to publisher", "A REST control of one of its machines (docs/api.md).", (
        Field("id", COUNT, doc="its answer carries it"), Field("machine", NAME),
        Field("action", STR, doc="what to do (below)"), Field("params", OBJECT, doc="the action's (below)"),
        Field("client", STR, doc="who asked"))),
    Message("answer", "publisher to server", "The result of a control.", (
        Field("id", COUNT, doc="the control's"), Field("status", COUNT, doc="200/202, or the 4xx the request answers"),
        Field("seq", SEQ, required=False, doc="of the control event it caused"),
        Field("detail", STR, required=False, doc="why not"),
        Field("breakpoints", list_of(BREAKPOINT, "a list of breakpoints"), required=False,
              doc="breakpoints, get-breakpoints: the whole set"))),
    Message("lease", "server to publisher", "The operator lease of one of its machines was taken, released or "
            "lapsed; sent again when the publisher reconnects.", (
                Field("machine", NAME), Field("held", BOOL), Field("after", NUMBER, doc="seconds"),
                Field("action", one_of(*DEADMAN_ACTIONS),
                      doc="while it is held, what the publisher does itself when its link is gone that long"))),
    Message("rejected", "server to publisher", "An event refused at the door.", (
        Field("reason", STR, doc="what is wrong, in words"), Field("machine", JSON, doc="the event's, if any"),
        Field("seq", JSON, doc="the event's, if any"))),
)}

# ``frame.NAME(...)``: the one way each frame is made.
frame = SimpleNamespace(**{name: maker(name, (("type", repr(name)),), m.fields, m.doc) for name, m in MESSAGES.items()})


def field_names(name: str) -> tuple[str, ...]:
    """A frame's field names in their definition's order, the order its maker takes them: what a reader
    of the frame unpacks (``machine, held, after, action = field_names("lease")``), so that a field
    renamed here is renamed there, and one added or removed fails the reader's import."""
    return tuple(f.name for f in MESSAGES[name].fields)


def frame_problem(message: Any) -> str | None:
    """What is wrong with a frame, in words (None when it fits its definition)."""
    if type(message) is not dict:
        return "a frame must be an object"
    spec = MESSAGES.get(message.get("type")) if type(message.get("type")) is str else None
    if spec is None:
        return "unknown frame type %r" % (message.get("type"),)
    return fields_problem(message, spec.fields, spec.name)


# The fan-out encodes each event once and each snapshot once, and splices what it already encoded into
# frames: these put the encoded parts where the definitions above say.

def list_frame(name: str) -> tuple[bytes, bytes]:
    """The text before and after the already-encoded items of a frame whose one field is a list
    (``events``): the fan-out joins each client's batch between them instead of encoding it again."""
    (field,) = MESSAGES[name].fields
    return b'{"type":"%s","%s":[' % (name.encode(), field.name.encode()), b"]}"


def encoded_history(complete: bool, events: list[bytes]) -> bytes:
    """A snapshot's ``history`` (HISTORY_FIELDS) from already-encoded events."""
    return b'{"complete":%s,"events":[%s]}' % (b"true" if complete else b"false", b",".join(events))


def with_history(snapshot: str, history: bytes) -> str:
    """An encoded snapshot frame (whose last field is ``last_seq``) with its optional ``history`` added."""
    return snapshot[:-1] + ',"history":' + history.decode() + "}"
