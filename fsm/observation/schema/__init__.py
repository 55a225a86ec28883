"""The schema, defined once: every event kind and field, the status, the websocket frames, the graph's ids.

One package, one module per concept:

* ``fields``: the vocabulary (limits, ``Type``, ``Field``, ``Kind``, the types shapes are made of);
* ``tree``: the structure tree a ``structure`` event carries, and the makers of its parts;
* ``status``: a machine's status (``fsm.observation.status.Status.to_dict()``), its debugger's state,
  holds and breakpoints;
* ``events``: the envelope, each kind's fields, and ``build``, the one way each kind is made
  (``fields_of``: a kind's own fields, without the envelope; ``build_batch``: a batch's events, its
  steps' records made into transitions by the same literal, stamped in order);
* ``messages``: the websocket frames around the events (snapshot, events, missed, pace, ...), beside
  them as in viser's one message module;
* ``tile``: the fleet overview's tile of a machine, and ``tile``, its maker;
* ``validation``: ``validate``, which says in words what is wrong with an event from outside;
* ``ids``: the graph's element ids (``s:``, ``c:``, ``o:``, ``e:``), shared by the server's SVG and the page.

Every producer makes events with ``build`` (the runtime's reporter, the recorder's and the
publisher's snapshots, the server's control events) and frames with ``messages``; every door an
event comes in through from outside calls ``validate``. The browser's ``fsmscope/static/schema.js`` (its
constants and JSDoc typedefs) and the field tables of ``docs/events.md`` are generated from here
(``python -m server.schema_export``); a test fails when they differ. The REST models of
fsmscope/server/models.py are tested against the status, breakpoint and tile shapes.

Everything is importable from ``fsm.observation.schema`` itself. Standard library only, like the rest of ``fsm``.
"""

from .events import ENVELOPE, EVENT, KINDS, SOURCES, build, build_batch, event, fields_of
from .fields import (ABSENT, BODY_POSE, BOOL, JSON, LIST_STR, MAP_BODY_POSE, MAP_NUMBER, MAP_OPT_STR, MAP_STR,
                     MAX_DOC, MAX_NAME, MAX_PATH, MAX_SEQ, MAX_STRUCTURE_DEPTH, MAX_STRUCTURE_NODES, MAX_VALUE_DEPTH,
                     NAME, NUMBER, OBJECT, OPT_NUMBER, OPT_STR, PATH, SEQ, SHAPES, STR, VERSION, Field, Kind, Type,
                     argument)
from .ids import ID_ESCAPES, ID_PREFIXES, container_id, edge_id, id_text, outcome_id, state_id
from .messages import (DEADMAN_ACTIONS, HISTORY_FIELDS, HISTORY_LIMIT, MAX_PACE_MS, MESSAGES, Message,
                       encoded_history, field_names, frame, frame_problem, list_frame, with_history)
from .status import (AT, BREAKPOINT, BREAKPOINT_FIELDS, CONTAINER_STATUS_FIELDS, DEBUG_ACTIONS, DEBUG_MODES,
                     DEBUG_STATUS_FIELDS, HOLD_FIELDS, LAST_TRANSITION_FIELDS, POSE_FIELDS, POSITIONS, PREEMPT_FIELDS,
                     STATUS, STATUS_FIELDS)
from .tile import TILE, TILE_FIELDS, TILE_STATES, tile
from .tree import (CONTAINER_FIELDS, CONTAINER_TYPES, KIND_FIELDS, NODE, NODE_FIELDS, TRANSITION_FIELDS,
                   container_fields, container_kind, edge, node, node_problem)
from .validation import DEBUG_NEEDS, validate

__all__ = [
    "ABSENT", "ENVELOPE", "EVENT", "KINDS", "SOURCES", "argument", "build", "event", "fields_of",
    "MAX_DOC", "MAX_NAME", "MAX_PATH", "MAX_SEQ", "MAX_STRUCTURE_DEPTH", "MAX_STRUCTURE_NODES", "MAX_VALUE_DEPTH",
    "SHAPES", "VERSION", "Field", "Kind", "Type", "BODY_POSE", "BOOL", "JSON", "LIST_STR", "MAP_BODY_POSE",
    "MAP_NUMBER", "MAP_OPT_STR", "MAP_STR", "NAME", "NUMBER", "OBJECT", "OPT_NUMBER", "OPT_STR", "PATH", "SEQ", "STR",
    "ID_ESCAPES", "ID_PREFIXES", "container_id", "edge_id", "id_text", "outcome_id", "state_id",
    "DEADMAN_ACTIONS", "HISTORY_FIELDS", "HISTORY_LIMIT", "MAX_PACE_MS", "MESSAGES", "Message", "encoded_history",
    "field_names", "frame", "frame_problem", "list_frame", "with_history",
    "AT", "BREAKPOINT", "BREAKPOINT_FIELDS", "CONTAINER_STATUS_FIELDS", "DEBUG_ACTIONS", "DEBUG_MODES",
    "DEBUG_STATUS_FIELDS", "HOLD_FIELDS", "LAST_TRANSITION_FIELDS", "POSE_FIELDS", "POSITIONS", "PREEMPT_FIELDS",
    "STATUS", "STATUS_FIELDS", "TILE", "TILE_FIELDS", "TILE_STATES", "tile",
    "CONTAINER_FIELDS", "CONTAINER_TYPES", "KIND_FIELDS", "NODE", "NODE_FIELDS", "TRANSITION_FIELDS",
    "container_fields", "container_kind", "edge", "node", "node_problem", "DEBUG_NEEDS", "validate",
]
