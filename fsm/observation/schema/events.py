"""The events: the envelope every event has, each kind's own fields, and the function that makes each.

The makers are generated from the definitions (as a dataclass's ``__init__`` is from its fields), so
a field's name is written once, here, and an event is made as one dict literal: the reporter's hot
path pays no more than for a hand-written one. ``build.transition(seq, t, run, machine, path, from_,
outcome, to, active)``: the envelope's values, then the kind's fields in their order, a field that is
a Python keyword with a trailing ``_``; an optional field left out (``ABSENT``) is not in the event.
``fields_of.pose(joints, bodies)``: the same kind's own fields alone.
"""

from __future__ import annotations

from types import SimpleNamespace

from .fields import (JSON, LIST_STR, MAP_OPT_STR, MAP_BODY_POSE, MAP_NUMBER, NAME, NUMBER, OBJECT, OPT_STR, PATH,
                     SEQ, STR, VERSION, Field, Kind, Type, batch_maker, fields_problem, list_of, maker, nullable, one_of,
                     simple)
from .status import AT, BREAKPOINT, DEBUG_ACTIONS, DEBUG_MODES, STATUS
from .tree import NODE

# Where a served machine's events come from (whether it takes controls is /api/machines' `controllable`).
SOURCES = ("local", "ingest", "replay")

# The envelope every event has, and each kind's own fields.

ENVELOPE = (
    Field("v", simple("the integer %d" % VERSION, (int,), lambda v: v == VERSION), doc="schema version"),
    Field("seq", SEQ, doc="per machine, strictly increasing, never reset while the process lives"),
    Field("t", NUMBER, doc="wall-clock seconds (time.time())"),
    Field("run", OPT_STR, required=False, doc="id of one top-level execution (null before the first)"),
    Field("machine", NAME, doc="the machine's name, unique within a process or server"),
    Field("kind", STR, doc="one of the kinds below"),
    Field("path", PATH, doc="the container (for feedback: the state) the event is about"),
)
EVENT = Type("an event (docs/events.md)", lambda v: fields_problem(v, ENVELOPE), js="FsmEvent")

# A step's writes ride on the event of the step (one event per step, not a ``userdata`` event before it).
_STEP_CHANGES = ("{key: encoded value}: the keys of the container's userdata its child's step wrote (as a "
                 "userdata event before it would say); absent when none")

KINDS: dict[str, Kind] = {k.name: k for k in (
    Kind("structure", "The whole container tree.", (
        Field("root", NODE, doc="the root container's node; its path is the event's path"),)),
    Kind("start", "A container began executing.", (
        Field("initial", LIST_STR), Field("active", LIST_STR, doc="a Concurrence: all its children"),
        Field("userdata", OBJECT, doc="the container's whole userdata, encoded"))),
    Kind("transition", "The container's active states changed.", (
        Field("from", STR, doc="the state that returned"), Field("outcome", STR, doc="what it returned"),
        Field("to", OPT_STR, doc="the next state; null when a Concurrence child finished"),
        Field("active", LIST_STR, doc="the container's active states now"),
        Field("changes", OBJECT, required=False, doc=_STEP_CHANGES))),
    Kind("terminate", "A container finished.", (
        Field("last", LIST_STR, doc="the last active state(s)"),
        Field("outcome", OPT_STR, doc="null: ended without an outcome"), Field("active", LIST_STR, required=False),
        Field("state_outcome", OPT_STR, required=False, doc="the outcome the last state returned"),
        Field("outcomes", MAP_OPT_STR, required=False, doc="a Concurrence's children's outcomes"),
        Field("error", OPT_STR, required=False, doc="'ExceptionClass: message' when it failed"),
        Field("changes", OBJECT, required=False, doc=_STEP_CHANGES))),
    Kind("userdata", "Keys of a container's userdata written since the last report of them, when no "
                     "transition or terminate of the container carries them.", (
        Field("changes", OBJECT, doc="{key: encoded value}"),)),
    Kind("preempt", "A preempt was requested of, or serviced by, the state at path.", (
        Field("phase", one_of("requested", "serviced")),)),
    Kind("error", "A state raised, or a container failed.", (
        Field("state", OPT_STR, doc="the child that raised"), Field("exc_type", STR, doc="the root cause's class"),
        Field("message", STR), Field("traceback", STR, required=False, doc="the whole chain"),
        Field("wrapped_as", STR, required=False, doc="the SMACH exception that carried it"))),
    Kind("log", "A log line the other events do not already say.", (
        Field("level", one_of("debug", "info", "warn", "error")), Field("msg", STR))),
    Kind("feedback", "Action feedback received by a SimpleActionState.", (
        Field("action", STR, doc="the action's name"), Field("feedback", JSON, doc="encoded"))),
    Kind("control", "Somebody asked the machine to do something.", (
        Field("action", STR, doc="preempt, initial-state, start, publish, ..."),
        Field("reason", OPT_STR, required=False, doc="the operator's words"),
        Field("client", STR, doc="who asked: an address, the role and the page "
                                 "('127.0.0.1 (operator, page 3f2a9c1d)'), or 'deadman'"),
        Field("result", STR, doc="'accepted' or why not"),
        Field("params", OBJECT, required=False, doc="what was asked"))),
    Kind("debug", "The debugger (fsm.debugging) changed mode, held or released a transition, forced an outcome "
                  "or replaced its breakpoints; path is the container's (the root's for mode and breakpoints).", (
        Field("action", one_of(*DEBUG_ACTIONS)),
        Field("mode", one_of(*DEBUG_MODES), required=False, doc="mode: what it is now"),
        Field("level", nullable(PATH), required=False, doc="mode step: the container whose next transition "
                                                            "ends the step (null: the next anywhere)"),
        Field("state", STR, required=False, doc="hold, release, forced: the child's label"),
        Field("at", AT, required=False,
              doc="hold, release: before the child runs, or after it returned (the transition held)"),
        Field("outcome", OPT_STR, required=False, doc="hold: the outcome to be taken; release, forced: the one taken"),
        Field("returned", OPT_STR, required=False, doc="forced: what the state returned (null: it did not run)"),
        Field("reason", one_of("pause", "step", "breakpoint"), required=False, doc="hold: why"),
        Field("detail", STR, required=False, doc="hold: in words ('hit breakpoint before PICK/CLOSE when ...')"),
        Field("by", OPT_STR, required=False, doc="mode, forced, breakpoints: who asked; release: what ended the "
                                                  "hold (resume, step, force, preempt, shutdown, detach)"),
        Field("breakpoints", list_of(BREAKPOINT, "a list of breakpoints"), required=False,
              doc="breakpoints: the whole set"))),
    Kind("pose", "The robot's pose, sampled at the rate the 3D view draws it (the demo: 30 Hz).", (
        Field("joints", MAP_NUMBER, doc="joint positions by joint name (radians, metres)"),
        Field("bodies", MAP_BODY_POSE, required=False,
              doc="free bodies' poses by name: [x, y, z, qw, qx, qy, qz] in the world frame"))),
    Kind("snapshot", "The full rebuilt state of one machine at seq.", (
        Field("status", STATUS, doc="the machine's state after the event seq"),)),
)}



def _envelope(kind: str) -> tuple[tuple[str, str], ...]:
    """The envelope's items in a maker of ``kind``: its version and kind are constants, the rest parameters."""
    constants = {"v": repr(VERSION), "kind": repr(kind)}
    return tuple((f.name, constants.get(f.name, f.name)) for f in ENVELOPE)


# ``build.KIND(...)``: the one way an event of each kind is made.
build = SimpleNamespace(**{name: maker(name, _envelope(name), k.fields, k.doc) for name, k in KINDS.items()})

# ``build_batch(first_seq, items)``: a batch's events stamped in order, its steps' records made into
# transitions (fields.batch_maker; the reporter's records: fsm/observation/introspection.py).
build_batch = batch_maker("build_batch", _envelope("transition"), KINDS["transition"].fields)

# ``fields_of.KIND(...)``: a kind's own fields without the envelope, for what handles them before any
# reporter stamps them (the simulator's pose sampler, POST /api/scene/pose): made as ``build`` makes events.
fields_of = SimpleNamespace(**{name: maker(name, (), k.fields, "A %s event's own fields: %s" % (name, k.doc))
                               for name, k in KINDS.items()})


def event(seq: int, t: float, run: str | None, machine: str, kind: str, path: str,
          fields: dict | None = None) -> dict:
    """An event of any kind from a dict of its fields (for what relays events it did not make: a
    SMACH bag's, a test's); what makes an event of a known kind uses ``build``."""
    if fields:
        return {"v": VERSION, "seq": seq, "t": t, "run": run, "machine": machine, "kind": kind, "path": path,
                **fields}
    return {"v": VERSION, "seq": seq, "t": t, "run": run, "machine": machine, "kind": kind, "path": path}
