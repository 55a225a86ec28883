"""What the REST API says of machines (docs/api.md): the list, the tiles, a structure, a status, a page of
history, a timeline, the states' statistics, and the few answers of the pages; OpenAPI is generated
from these. The controls' requests and answers are fsmscope/server/control_models.py.

The shapes the schema defines (fsm/observation/schema/: a machine's status and what it holds, a
breakpoint, a structure node, a fleet overview tile) are restated here for OpenAPI's sake, with their
descriptions, and tests/unit/test_models_schema.py fails when a model and its shape in the schema differ."""

from __future__ import annotations

from typing import Any, Literal, Optional

from pydantic import BaseModel, ConfigDict, Field

from fsm.observation.schema import SOURCES, TILE_STATES

JsonValue = Any


class Error(BaseModel):
    detail: str = Field(description="human readable message")


class Health(BaseModel):
    ok: bool = True


class Session(BaseModel):
    model_config = ConfigDict(json_schema_extra={"examples": [{"role": "viewer"}]})

    role: str = Field(description="'operator' (watch and control) or 'viewer' (watch only)")


class Scene(BaseModel):
    """Where the 3D view of the simulated robot is served (None: this server has none)."""
    url: str | None = None


VIEW = "0f3c9a7e5b2d4c6f8a1e3b5d7c9f2a4e"  # an example of a page's view id (fsmscope/static/scene.js makes one per page)


class ScenePoseRequest(BaseModel):
    """POST /api/scene/pose: a pose event's fields to show in one page's 3D view, or null for the live robot."""
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [
        {"view": VIEW, "pose": {"joints": {"j1": 0.0, "j2": 0.0309, "finger_left": 0.04},
                                "bodies": {"cube": [0.4, 0.15, 0.42, 1.0, 0.0, 0.0, 0.0]}}},
        {"view": VIEW, "pose": None}]})

    view: str = Field(pattern=r"^[A-Za-z0-9_-]{16,64}$",
                      description="the page's own 3D view: the random id its frame of the view connected with "
                                  "(ws://HOST:PORT/view/ID); only that view's browsers are shown the pose")
    pose: Optional[dict[str, JsonValue]] = Field(description="{joints: {name: position}, bodies?: {name: "
                                                 "[x, y, z, qw, qx, qy, qz]}} (docs/events.md, kind pose), or null")


class ScenePoseShown(BaseModel):
    live: bool = Field(description="the page's 3D view shows the live robot again (the request's pose was null)")


class ReplayInfo(BaseModel):
    speed: float = Field(description="the play speed the page opens with (--speed), 0.1 to 10")


class MachineInfo(BaseModel):
    name: str
    running: bool
    outcome: Optional[str] = None
    last_seq: int
    root_path: Optional[str] = None
    can_start: bool
    can_hold: bool = Field(default=False, description="its host runs it in a loop that POST .../hold can stop "
                           "after the current run")
    held: bool = Field(default=False, description="a hold was asked and no start has come since")
    cannot: dict[str, str] = Field(default_factory=dict, description="the controls it never takes, each with why "
                                   "(a ROS robot's machine: those smach_ros does not take)")
    source: Literal[SOURCES]  # type: ignore[valid-type]
    controllable: bool = Field(default=False, description="its controls would be taken now: a machine of this "
                               "process, or one whose publishing process takes them and is connected")
    connected: Optional[bool] = Field(default=None, description="a machine of another process: whether its "
                                      "publisher is connected (null for the others)")
    rejected: int = Field(default=0, description="events refused at the door for not fitting the schema")
    replay: Optional[ReplayInfo] = Field(default=None, description="a machine of `fsmscope replay --serve` "
                                         "(source replay): how the page plays it; null for the others")
    script: Optional[str] = Field(default=None, description="a machine of `fsmscope run`: the script that built "
                                  "it (a page that shows one that ended follows the newest of its script); null "
                                  "for the others")


class Tile(BaseModel):
    """A machine's tile on the fleet overview (fsmscope/server/overview.py; ``schema.TILE``)."""
    name: str = Field(description="the dashboard's name of the machine (a robot's: robot:machine)")
    robot: Optional[str] = Field(default=None, description="the robot publishing it on Zenoh (null for the others)")
    machine: str = Field(description="its name on its robot (its name, for the others)")
    source: Literal[SOURCES]  # type: ignore[valid-type]
    state: Literal[TILE_STATES] = Field(  # type: ignore[valid-type]
        description="failed: its run ended on an error; gone: its process went away while it ran or idled; "
                    "done: it reached an outcome")
    outcome: Optional[str] = Field(default=None, description="the outcome its run reached")
    error: Optional[str] = Field(default=None, description="the exception type of a failed run")
    active: list[str] = Field(description="the full paths of its active states (leaves)")
    rate: float = Field(description="events per second over the last 5 s, as the server received them")
    last_seq: int
    last_seen: Optional[float] = Field(default=None, description="when the server saw its newest event "
                                       "(Unix time, the server's clock; null before any)")
    connected: bool = Field(description="false when the process that publishes it has gone away")


class Transition(BaseModel):
    model_config = ConfigDict(populate_by_name=True)

    from_: str = Field(alias="from")
    outcome: str
    to: Optional[str] = None


class StructureNode(BaseModel):
    """A node of a ``structure`` event (docs/events.md); containers carry children and transitions."""

    model_config = ConfigDict(extra="allow")

    label: str
    path: str
    type: str
    container: bool
    outcomes: list[str]
    input_keys: list[str]
    output_keys: list[str]
    remapping: dict[str, str]
    doc: Optional[str] = Field(None, description="the first paragraph of its class's docstring")
    initial: Optional[list[str]] = None
    children: Optional[list[StructureNode]] = None
    transitions: Optional[list[Transition]] = None
    default_outcome: Optional[str] = Field(None, description="a Concurrence's")
    outcome_map: Optional[dict[str, dict[str, str]]] = Field(None, description="a Concurrence's {container "
                                                             "outcome: {child: outcome}}")


class LastTransition(BaseModel):
    model_config = ConfigDict(populate_by_name=True)

    from_: str = Field(alias="from")
    outcome: str
    to: Optional[str] = None
    seq: int = Field(description="the event that made it")


class KeyChange(BaseModel):
    old: Optional[JsonValue] = Field(default=None, description="absent: the key is new")
    new: JsonValue


class ContainerStatus(BaseModel):
    active: list[str]
    initial: list[str]
    userdata: dict[str, JsonValue]
    running: bool
    outcome: Optional[str] = None
    last: Optional[LastTransition] = Field(default=None, description="its last transition in this run")
    changes: dict[str, KeyChange] = Field(default_factory=dict, description="the userdata keys its last "
                                          "transition wrote: {key: {old?, new}}")
    written: bool = Field(default=False, description="userdata was written since its last transition")


class Pose(BaseModel):
    seq: int
    t: float
    joints: dict[str, float]
    bodies: dict[str, list[float]] = Field(default_factory=dict, description="name: [x, y, z, qw, qx, qy, qz]")


class PendingPreempt(BaseModel):
    seq: int
    t: float = Field(description="when it was requested (wall clock, seconds)")
    path: str = Field(description="the container it was requested of")
    serviced: list[str] = Field(description="the states that serviced it so far")


class BreakpointSpec(BaseModel):
    model_config = ConfigDict(extra="forbid")

    state: str = Field(max_length=4096, description="the state's path")
    at: str = Field(default="before", description="'before' it runs or 'after' it returned")
    outcome: Optional[str] = Field(default=None, max_length=1000, description="after: only this outcome")
    when: Optional[str] = Field(default=None, max_length=1000, description="a condition over its container's "
                                "userdata (docs/debugging.md): comparisons, and/or/not, in, len(), literals")


class Hold(BaseModel):
    path: str = Field(description="the holding container")
    state: str
    at: str
    outcome: Optional[str] = Field(default=None, description="at 'after': the outcome it will take")
    reason: str = Field(description="pause, step or breakpoint")
    detail: str = Field(description="in words")
    seq: int = Field(description="the hold event's")


class DebugState(BaseModel):
    """The debugger's state as its events say (docs/debugging.md)."""

    mode: str = Field(description="run, pause or step")
    level: Optional[str] = Field(default=None, description="step: the container whose next transition ends it")
    holds: list[Hold]
    breakpoints: list[BreakpointSpec]


class MachineStatus(BaseModel):
    """``fsm.observation.status.Status.to_dict()`` without ``structure``: now, or after event ``seq``."""

    model_config = ConfigDict(json_schema_extra={"examples": [{
        "machine": "two", "run": "3f9c2a1b7d4e", "root_path": "/SM_ROOT",
        "containers": {"/SM_ROOT": {"active": ["BAR"], "initial": ["FOO"], "userdata": {"visits": ["FOO"]},
                                    "running": True, "outcome": None,
                                    "last": {"from": "FOO", "outcome": "go", "to": "BAR", "seq": 4},
                                    "changes": {"visits": {"old": [], "new": ["FOO"]}}, "written": False}},
        "running": True, "outcome": None, "error": None, "last_seq": 4, "last_t": 1700000000.25, "run_seq": 1,
        "preempt": None, "pose": None, "debug": None, "preempt_waiting_on": []}]})

    machine: str
    run: Optional[str] = None
    root_path: Optional[str] = None
    containers: dict[str, ContainerStatus]
    running: bool
    outcome: Optional[str] = None
    error: Optional[dict[str, JsonValue]] = None
    last_seq: int
    last_t: Optional[float] = None
    run_seq: int = Field(default=0, description="the seq of the current run's first event")
    preempt: Optional[PendingPreempt] = Field(default=None, description="a preempt requested and not over yet")
    pose: Optional[Pose] = Field(default=None, description="the robot's last recorded pose (a pose event)")
    debug: Optional[DebugState] = Field(default=None, description="the debugger's state; null until a debug event")
    preempt_waiting_on: list[str] = Field(default_factory=list, description="the active states that have not "
                                          "serviced the pending preempt")


class HistoryPage(BaseModel):
    """GET /api/machines/{name}/history (docs/api.md, "Time travel")."""

    model_config = ConfigDict(json_schema_extra={"examples": [{
        "events": [{"v": 1, "seq": 3, "t": 1700000000.2, "run": "3f9c2a1b7d4e", "machine": "two",
                    "kind": "start", "path": "/SM_ROOT", "initial": ["FOO"], "active": ["FOO"],
                    "userdata": {"visits": []}},
                   {"v": 1, "seq": 4, "t": 1700000000.25, "run": "3f9c2a1b7d4e", "machine": "two",
                    "kind": "transition", "path": "/SM_ROOT", "from": "FOO", "outcome": "go", "to": "BAR",
                    "active": ["BAR"], "changes": {"visits": ["FOO"]}}],
        "first_seq": 1, "last_seq": 7, "more": True, "next": 5}]})

    events: list[dict[str, JsonValue]] = Field(description="events of docs/events.md, oldest first (no snapshots)")
    first_seq: Optional[int] = Field(description="the oldest seq served for this machine (older: 410)")
    last_seq: Optional[int] = Field(description="its newest event")
    more: bool = Field(description="the range holds more events than this page (or the page stopped scanning)")
    next: Optional[int] = Field(description="since (order=asc) or until (order=desc) of the next page; null: none")


class TimelinePoint(BaseModel):
    seq: int
    t: float = Field(description="wall clock, seconds")


class TimelineRun(TimelinePoint):
    run: str = Field(description="the run's id; seq and t: its first event")


class TimelineTick(TimelinePoint):
    kind: Literal["error", "preempt", "control", "debug", "run"]
    text: str = Field(description="a short description, at most 200 characters")


class Timeline(BaseModel):
    """GET /api/machines/{name}/timeline (docs/api.md, "Timeline")."""

    model_config = ConfigDict(json_schema_extra={"examples": [{
        "first": {"seq": 1, "t": 1700000000.0}, "last": {"seq": 7, "t": 1700000002.5}, "kept_from": 1,
        "runs": [{"run": "3f9c2a1b7d4e", "seq": 1, "t": 1700000000.0}],
        "bands": {"/SM_ROOT": [[1700000000.1, 1700000002.4, 2, "SUB"], [1700000002.4, 1700000002.5, 7, None]],
                  "/SM_ROOT/SUB": [[1700000000.2, 1700000001.0, 3, "A"], [1700000001.0, 1700000002.3, 4, "B"],
                                   [1700000002.3, 1700000002.5, 6, None]]},
        "ticks": [{"seq": 1, "t": 1700000000.0, "kind": "run", "text": "run 3f9c2a1b7d4e"},
                  {"seq": 5, "t": 1700000001.5, "kind": "preempt", "text": "preempt requested of /SM_ROOT"}],
        "transitions": [[2, 1700000000.1], [3, 1700000000.2], [4, 1700000001.0], [6, 1700000002.3],
                        [7, 1700000002.4]],
        "coarse": False, "history_from": 1}]})

    first: Optional[TimelinePoint] = Field(description="the machine's first event seen (null: none yet)")
    last: Optional[TimelinePoint] = Field(description="its last event")
    kept_from: int = Field(description="the seq from which the detail is whole (older detail was coalesced)")
    runs: list[TimelineRun] = Field(description="the runs starting in the range, and the one under way at its start")
    bands: dict[str, list[tuple[float, float, int, Optional[str]]]] = Field(
        description="per container path: [t0, t1, seq of the band's first event, label]; label: the active child, "
                    "'+' several (a Concurrence), '…' several states within one bucket, null not running")
    ticks: list[TimelineTick] = Field(description="errors, preempt requests, controls, run starts (the newest 5000)")
    transitions: list[tuple[int, float]] = Field(description="[seq, t] of every start/transition/terminate in the "
                                                 "range (at most 5000, evenly spread when there are more)")
    coarse: bool = Field(description="transitions were thinned, or the range reaches into coalesced detail")
    history_from: Optional[int] = Field(None, description="the oldest seq whose instant can be shown (GET .../status?seq="
                                        "): a machine with no recording keeps a bounded ring of recent events")


class StateTime(BaseModel):
    total: float = Field(description="seconds in the state over every visit that ended")
    median: Optional[float] = Field(description="of the visits that ended (null: none has)")
    max: Optional[float]
    last: Optional[float] = Field(description="the last visit that ended")


class StateStatistics(BaseModel):
    visits: int = Field(description="times it became active")
    time: StateTime
    last_outcome: Optional[str] = Field(description="the outcome it returned last (null: none yet)")


class SeqRange(BaseModel):
    first_seq: Optional[int]
    last_seq: Optional[int]


class StateSummary(BaseModel):
    """GET /api/machines/{name}/summary (docs/api.md, "State statistics")."""

    model_config = ConfigDict(json_schema_extra={"examples": [{
        "counted": {"first_seq": 1, "last_seq": 120}, "last_seq": 120, "complete": True,
        "states": {"/SM_ROOT/PICK": {"visits": 3, "time": {"total": 1.5, "median": 0.5, "max": 0.6, "last": 0.4},
                                     "last_outcome": "succeeded"}}}]})

    counted: SeqRange = Field(description="the events counted: from the oldest the history kept when first asked")
    last_seq: Optional[int] = Field(description="the machine's newest event")
    complete: bool = Field(description="every event up to last_seq is counted (else ask again: at most 100,000 more "
                                       "are read per request)")
    states: dict[str, StateStatistics] = Field(description="by state path: the one asked, or every state visited")


StructureNode.model_rebuild()
DebugState.model_rebuild()
