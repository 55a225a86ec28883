"""The fleet overview's tile: what an operator scans a fleet for, one per machine a server knows
(fsmscope/server/overview.py makes them with ``tile``; GET /api/overview and the ``overview`` frame carry them)."""

from __future__ import annotations

from ..vocabularies import DONE, FAILED, GONE, IDLE, RUNNING
from .events import SOURCES
from .fields import BOOL, LIST_STR, NAME, NUMBER, OPT_NUMBER, OPT_STR, SEQ, STR, Field, maker, one_of, shape

# A tile's states: the run states (fsm/observation/vocabularies.py) in the order that needs a look
# first (the fleet page sorts "by state" so).
TILE_STATES = (FAILED, GONE, RUNNING, IDLE, DONE)

TILE_FIELDS = (
    Field("name", NAME, doc="the dashboard's name of the machine (a robot's: robot:machine)"),
    Field("robot", OPT_STR, doc="the robot publishing it on Zenoh (null for the others)"),
    Field("machine", STR, doc="its name on its robot (its name, for the others)"),
    Field("source", one_of(*SOURCES), doc="where its events come from (GET /api/machines' source)"),
    Field("state", one_of(*TILE_STATES), doc="failed: its run ended on an error; gone: its process went away "
                                              "while it ran or idled; done: it reached an outcome"),
    Field("outcome", OPT_STR, doc="the outcome its run reached"),
    Field("error", OPT_STR, doc="the exception type of a failed run"),
    Field("active", LIST_STR, doc="the full paths of its active states (leaves)"),
    Field("rate", NUMBER, doc="events per second over the last 5 s, as the server received them"),
    Field("last_seq", SEQ, doc="its newest event's"),
    Field("last_seen", OPT_NUMBER, doc="when the server saw its newest event (Unix time, the server's clock; "
                                       "null before any)"),
    Field("connected", BOOL, doc="false when the process that publishes it has gone away"),
)
TILE = shape("a fleet overview tile", "Tile", TILE_FIELDS)

# ``tile(...)``: the one way a tile is made, its fields in their order.
tile = maker("tile", (), TILE_FIELDS, "A machine's tile on the fleet overview.")
