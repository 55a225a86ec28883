"""The event schema, defined once: every kind, every field, its type; the builder and the validator.

Every producer builds events with :func:`event` (the runtime's reporter, the recorder's and the
publisher's snapshots, the server's control events). Every door an event comes in through from
outside (a log file, a publisher's ingest, a replay) calls :func:`validate`, which says in words
what is wrong; an event it refuses never reaches a ``Status``, a graph or a client. The browser's
``static/schema.js`` and the field tables of ``docs/events.md`` are generated from this module
(``python -m server.schema_export``) and a test fails when they differ from it.

The graph's element ids (``s:``, ``c:``, ``o:``, ``e:``) are part of the contract between the
server's SVG and the page, so they are defined here too.

One module of about 400 lines on purpose, like viser's one message module: the definition, the
builder and the validator must change together, and the generated browser file and docs come
from this one place.

Standard library only, like the rest of ``fsm``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

from .names import MAX_NAME, is_valid as _is_name

VERSION = 1
MAX_SEQ = 2 ** 53 - 1          # the browser's largest exact integer
MAX_PATH = 4096                # a container or state path
MAX_STRUCTURE_DEPTH = 64       # container levels; JSON encoders refuse much deeper nesting
MAX_STRUCTURE_NODES = 200_000
MAX_DOC = 500                  # characters of a structure node's class docstring
MAX_VALUE_DEPTH = 32           # nesting of a JSON value (userdata is cut at 16 levels when encoded)

# Where a served machine's events come from (whether it takes controls is /api/machines' `controllable`).
SOURCES = ("local", "ingest", "replay")

# Which of SMACH's containers a structure node is: its ``type`` when it is one of these, else (a
# user's subclass) the kind whose own field it carries, else a state machine.
CONTAINER_TYPES = ("StateMachine", "Sequence", "Concurrence", "Iterator")
KIND_FIELDS = (("outcome_map", "Concurrence"), ("exhausted_outcome", "Iterator"))


def container_kind(node: dict) -> str:
    """The SMACH container a structure node is, for readers that treat each kind differently."""
    kind = node.get("type", "StateMachine")
    if kind in CONTAINER_TYPES:
        return kind
    return next((kind for field, kind in KIND_FIELDS if field in node), "StateMachine")

Problem = Callable[[Any], "str | None"]  # a type check: None when the value fits, else what is wrong


@dataclass(frozen=True)
class Type:
    """A field's type: its name in the docs, the check that says what is wrong (or None), and a
    fast test for the common case: the exact Python types allowed (None: any), then ``ok(value)``."""

    name: str
    check: Problem
    types: tuple | None = None
    ok: Callable[[Any], bool] | None = None


@dataclass(frozen=True)
class Field:
    name: str
    type: Type
    required: bool = True
    doc: str = ""


@dataclass(frozen=True)
class Kind:
    name: str
    doc: str
    fields: tuple[Field, ...]


def _what(value: Any) -> str:
    return {type(None): "null", bool: "a boolean", int: "an integer", float: "a number", str: "a string",
            list: "a list", dict: "an object"}.get(type(value), type(value).__name__)


def _simple(name: str, types: tuple, ok: Callable[[Any], bool] | None = None) -> Type:
    """A type that is right when the value is of one of ``types`` and passes ``ok``."""
    def check(v: Any) -> str | None:
        return None if type(v) in types and (ok is None or ok(v)) else "must be %s, not %s" % (name, _what(v))
    return Type(name, check, types, ok)


def _nullable(t: Type) -> Type:
    name = t.name + " or null"

    def check(v: Any) -> str | None:
        problem = None if v is None else t.check(v)
        return problem and problem.replace("must be " + t.name, "must be " + name, 1)

    ok = None if t.ok is None else (lambda v, inner=t.ok: v is None or inner(v))
    return Type(name, check, None if t.types is None else t.types + (type(None),), ok)


STR = _simple("a string", (str,))
BOOL = _simple("a boolean", (bool,))
NUMBER = _simple("a finite number", (float, int), lambda v: type(v) is int or math.isfinite(v))
SEQ = _simple("an integer from 0 to 2^53-1", (int,), lambda v: 0 <= v <= MAX_SEQ)
NAME = _simple("a name of 1 to %d characters (no / * $ ? #, control character or outer space)" % MAX_NAME,
               (str,), _is_name)
PATH = _simple("a string of 1 to %d characters" % MAX_PATH, (str,), lambda v: 0 < len(v) <= MAX_PATH)
OPT_STR = _nullable(STR)
OPT_NUMBER = _nullable(NUMBER)


def _one_of(*values: str) -> Type:
    shown = ", ".join("'%s'" % v for v in values)
    return _simple("one of " + shown, (str,), lambda v: v in values)


def _list_of(item: Type, name: str, ok: Callable[[Any], bool] | None = None) -> Type:
    def check(v: Any) -> str | None:
        if type(v) is not list:
            return "must be %s, not %s" % (name, _what(v))
        for i, x in enumerate(v):
            problem = item.check(x)
            if problem:
                return _join("[%d]" % i, problem)
        return None
    return Type(name, check, (list,), ok or (lambda v: check(v) is None))


def _object_of(value: Type, name: str) -> Type:
    def check(v: Any) -> str | None:
        if type(v) is not dict:
            return "must be %s, not %s" % (name, _what(v))
        for k, x in v.items():
            problem = value.check(x)
            if problem:
                return _join("[%r]" % (k,), problem)
        return None
    return Type(name, check, (dict,), lambda v: check(v) is None)


def _all_str(v: list) -> bool:
    for x in v:
        if type(x) is not str:
            return False
    return True


def _json_depth_problem(v: Any, depth: int) -> str | None:
    if depth > MAX_VALUE_DEPTH:
        return "is nested deeper than %d levels" % MAX_VALUE_DEPTH
    t = type(v)
    if t is dict:
        for x in v.values():
            if type(x) in (dict, list):
                problem = _json_depth_problem(x, depth + 1)
                if problem:
                    return problem
    elif t is list:
        for x in v:
            if type(x) in (dict, list):
                problem = _json_depth_problem(x, depth + 1)
                if problem:
                    return problem
    elif t is float and not math.isfinite(v):
        return "holds a non-finite number"
    return None


JSON = Type("any JSON value", lambda v: _json_depth_problem(v, 0), None, lambda v: _json_depth_problem(v, 0) is None)
OBJECT = Type("an object", lambda v: ("must be an object, not %s" % _what(v)) if type(v) is not dict
              else _json_depth_problem(v, 0), (dict,), lambda v: _json_depth_problem(v, 0) is None)
LIST_STR = _list_of(STR, "a list of strings", _all_str)
MAP_STR = _object_of(STR, "an object of strings")
MAP_OPT_STR = _object_of(OPT_STR, "an object of strings or nulls")
MAP_NUMBER = _object_of(NUMBER, "an object of finite numbers")


def _sized(t: Type, n: int) -> Type:
    """``t`` (a list type) holding exactly ``n`` items."""
    def check(v: Any) -> str | None:
        return t.check(v) or (None if len(v) == n else "must hold %d items, not %d" % (n, len(v)))
    return Type(t.name, check, t.types, lambda v: len(v) == n and t.ok(v))


BODY_POSE = _sized(_list_of(NUMBER, "a list of 7 finite numbers (x, y, z, qw, qx, qy, qz)"), 7)
MAP_BODY_POSE = _object_of(BODY_POSE, "an object of body poses")


def _join(where: str, problem: str) -> str:
    """``where`` followed by a nested problem: ``status.containers['/a'].active[0] must be ...``."""
    return where + (problem if problem[:1] in ("[", ".", " ") else " " + problem)


def _fields_problem(obj: Any, fields: tuple[Field, ...], what: str = "") -> str | None:
    """The first field of ``obj`` that is missing or of the wrong type; ``what`` names ``obj``
    (empty for a nested object, whose problem then reads on from its parent's name)."""
    if type(obj) is not dict:
        return "%s must be an object, not %s" % (what, _what(obj))
    for f in fields:
        if f.name not in obj:
            if f.required:
                return "%s lacks '%s'" % (what, f.name)
            continue
        problem = f.type.check(obj[f.name])
        if problem:
            return _join("%s.%s" % (what, f.name), problem)
    return None


# The structure tree (a ``structure`` event's root, a snapshot's structure).

TRANSITION_FIELDS = (Field("from", STR, doc="a child's label"), Field("outcome", STR, doc="one of its outcomes"),
                     Field("to", OPT_STR, doc="a child's label, a container outcome, or null (the container "
                                              "outcome of the same name)"))
NODE_FIELDS = (
    Field("label", STR, doc="the name its parent knows it by"),
    Field("path", PATH, doc="its parent's path, '/', its label"),
    Field("type", STR, doc="the class name (StateMachine, Concurrence, CBState, ...)"),
    Field("container", BOOL, doc="whether it holds children"),
    Field("outcomes", LIST_STR, doc="registered outcomes, sorted"),
    Field("input_keys", LIST_STR, doc="sorted"), Field("output_keys", LIST_STR, doc="sorted"),
    Field("remapping", MAP_STR, doc="its parent's remapping for it: {its key: the parent's key}"),
    Field("doc", STR, required=False, doc="the first paragraph of its class's docstring (at most %d characters); "
                                          "absent when the class has none or is one of fsm's own" % MAX_DOC),
)
CONTAINER_FIELDS = (
    Field("initial", LIST_STR, doc="initial states"), Field("transitions", _list_of(Type("a transition", lambda t: _fields_problem(
        t, TRANSITION_FIELDS)), "a list of transitions"), doc="its edges (below)"),
    Field("children", _simple("a list", (list,)), doc="nodes, in add order"),
    Field("default_outcome", OPT_STR, required=False, doc="a Concurrence's"),
    Field("outcome_map", _object_of(MAP_STR, "an object of objects of strings"), required=False,
          doc="a Concurrence's {container outcome: {child: outcome}}"),
)


def node_problem(node: Any, path: str | None = None) -> str | None:
    """What is wrong with a structure tree (None when nothing): fields, paths, depth and size."""
    count = [0]

    def walk(n: Any, expected: str | None, depth: int) -> str | None:
        where = expected or "root"
        if depth > MAX_STRUCTURE_DEPTH:
            return "the structure is deeper than %d levels" % MAX_STRUCTURE_DEPTH
        count[0] += 1
        if count[0] > MAX_STRUCTURE_NODES:
            return "the structure has more than %d states" % MAX_STRUCTURE_NODES
        problem = _fields_problem(n, NODE_FIELDS, "node %s" % where)
        if problem:
            return problem
        if expected is not None and n["path"] != expected:
            return "node path %r should be %r (its parent's path, '/', its label)" % (n["path"], expected)
        if not n["container"]:
            return None
        problem = _fields_problem(n, CONTAINER_FIELDS, "container %s" % n["path"])
        if problem:
            return problem
        for child in n["children"]:
            label = child.get("label") if type(child) is dict else None
            problem = walk(child, n["path"] + "/" + label if type(label) is str else n["path"] + "/?", depth + 1)
            if problem:
                return problem
        return None

    return walk(node, path, 0)


NODE = Type("a structure node (below)", lambda v: node_problem(v))

LAST_TRANSITION_FIELDS = (Field("from", STR, doc="the state that returned"), Field("outcome", STR),
                          Field("to", OPT_STR, doc="the next state, or the container's outcome when it ended"),
                          Field("seq", SEQ, doc="the event's"))
CONTAINER_STATUS_FIELDS = (Field("active", LIST_STR, doc="active children's labels"),
                           Field("initial", LIST_STR, doc="initial children's labels"),
                           Field("userdata", OBJECT, doc="its userdata, encoded"),
                           Field("running", BOOL), Field("outcome", OPT_STR, doc="its last outcome"),
                           Field("last", _nullable(Type("a transition", lambda v: _fields_problem(
                               v, LAST_TRANSITION_FIELDS))), required=False,
                               doc="its last transition in this run: {from, outcome, to, seq}"),
                           Field("changes", _object_of(OBJECT, "an object of {old, new} objects"), required=False,
                                 doc="the keys its last transition wrote: {key: {old (absent: a new key), new}}"),
                           Field("written", BOOL, required=False,
                                 doc="its userdata was written since its last transition"))
DEBUG_ACTIONS = ("mode", "hold", "release", "forced", "breakpoints")
BREAKPOINT_FIELDS = (Field("state", PATH, doc="the state's path"), Field("at", _one_of("before", "after")),
                     Field("outcome", OPT_STR, doc="after: only this outcome"),
                     Field("when", OPT_STR, doc="a condition over the container's userdata"))
HOLD_FIELDS = (Field("path", PATH, doc="the holding container's"), Field("state", STR), Field("at", _one_of("before", "after")),
               Field("outcome", OPT_STR), Field("reason", STR), Field("detail", STR), Field("seq", SEQ, doc="the hold event's"))
DEBUG_STATUS_FIELDS = (Field("mode", _one_of("run", "pause", "step")), Field("level", _nullable(PATH)),
                       Field("holds", _list_of(Type("a hold", lambda h: _fields_problem(h, HOLD_FIELDS)),
                                               "a list of holds"), doc="{path, state, at, outcome, reason, detail, seq}"),
                       Field("breakpoints", _list_of(Type("a breakpoint", lambda b: _fields_problem(b, BREAKPOINT_FIELDS)),
                                                     "a list of breakpoints"), doc="{state, at, outcome, when}"))
POSE_FIELDS = (Field("seq", SEQ, doc="the pose event's"), Field("t", NUMBER),
               Field("joints", MAP_NUMBER), Field("bodies", MAP_BODY_POSE, required=False))
PREEMPT_FIELDS = (Field("seq", SEQ, doc="the preempt event's"), Field("t", NUMBER, doc="when it was requested"),
                  Field("path", PATH, doc="of the container it was requested of"),
                  Field("serviced", LIST_STR, doc="paths of the states that serviced it so far"))
STATUS_FIELDS = (
    Field("run", OPT_STR, required=False, doc="the current (or last) run"),
    Field("root_path", _nullable(PATH), required=False), Field("structure", _nullable(NODE), required=False),
    Field("containers", _object_of(Type("a container status", lambda c: _fields_problem(
        c, CONTAINER_STATUS_FIELDS)), "an object of container statuses")),
    Field("running", BOOL, doc="the root is running"), Field("outcome", OPT_STR, doc="the root's last outcome"),
    Field("error", _nullable(OBJECT), required=False, doc="the last error event's fields"),
    Field("last_seq", SEQ, required=False), Field("last_t", OPT_NUMBER, required=False),
    Field("run_seq", SEQ, required=False, doc="the seq of the current run's first event"),
    Field("preempt", _nullable(Type("a pending preempt", lambda v: _fields_problem(v, PREEMPT_FIELDS))),
          required=False, doc="a preempt requested and not over yet (below)"),
    Field("pose", _nullable(Type("a pose", lambda v: _fields_problem(v, POSE_FIELDS))), required=False,
          doc="the robot's last recorded pose: {seq, t, joints, bodies}"),
    Field("debug", _nullable(Type("a debugger's state", lambda v: _fields_problem(v, DEBUG_STATUS_FIELDS))),
          required=False, doc="null until a debug event: {mode, level, holds, breakpoints} (below)"),
)
STATUS = Type("a machine status (fsm.observation.status.Status.to_dict())",
              lambda v: _fields_problem(v, STATUS_FIELDS))


# The envelope every event has, and each kind's own fields.

ENVELOPE = (
    Field("v", _simple("the integer %d" % VERSION, (int,), lambda v: v == VERSION), doc="schema version"),
    Field("seq", SEQ, doc="per machine, strictly increasing, never reset while the process lives"),
    Field("t", NUMBER, doc="wall-clock seconds (time.time())"),
    Field("run", OPT_STR, required=False, doc="id of one top-level execution (null before the first)"),
    Field("machine", NAME, doc="the machine's name, unique within a process or server"),
    Field("kind", STR, doc="one of the kinds below"),
    Field("path", PATH, doc="the container (for feedback: the state) the event is about"),
)

KINDS: dict[str, Kind] = {k.name: k for k in (
    Kind("structure", "The whole container tree.", (
        Field("root", NODE, doc="the root container's node; its path is the event's path"),)),
    Kind("start", "A container began executing.", (
        Field("initial", LIST_STR), Field("active", LIST_STR, doc="a Concurrence: all its children"),
        Field("userdata", OBJECT, doc="the container's whole userdata, encoded"))),
    Kind("transition", "The container's active states changed.", (
        Field("from", STR, doc="the state that returned"), Field("outcome", STR, doc="what it returned"),
        Field("to", OPT_STR, doc="the next state; null when a Concurrence child finished"),
        Field("active", LIST_STR, doc="the container's active states now"))),
    Kind("terminate", "A container finished.", (
        Field("last", LIST_STR, doc="the last active state(s)"),
        Field("outcome", OPT_STR, doc="null: ended without an outcome"), Field("active", LIST_STR, required=False),
        Field("state_outcome", OPT_STR, required=False, doc="the outcome the last state returned"),
        Field("outcomes", MAP_OPT_STR, required=False, doc="a Concurrence's children's outcomes"),
        Field("error", OPT_STR, required=False, doc="'ExceptionClass: message' when it failed"))),
    Kind("userdata", "Keys of a container's userdata written since the last such event.", (
        Field("changes", OBJECT, doc="{key: encoded value}"),)),
    Kind("preempt", "A preempt was requested of, or serviced by, the state at path.", (
        Field("phase", _one_of("requested", "serviced")),)),
    Kind("error", "A state raised, or a container failed.", (
        Field("state", OPT_STR, doc="the child that raised"), Field("exc_type", STR, doc="the root cause's class"),
        Field("message", STR), Field("traceback", STR, required=False, doc="the whole chain"),
        Field("wrapped_as", STR, required=False, doc="the SMACH exception that carried it"))),
    Kind("log", "A log line the other events do not already say.", (
        Field("level", _one_of("debug", "info", "warn", "error")), Field("msg", STR))),
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
        Field("action", _one_of(*DEBUG_ACTIONS)),
        Field("mode", _one_of("run", "pause", "step"), required=False, doc="mode: what it is now"),
        Field("level", _nullable(PATH), required=False, doc="mode step: the container whose next transition "
                                                            "ends the step (null: the next anywhere)"),
        Field("state", STR, required=False, doc="hold, release, forced: the child's label"),
        Field("at", _one_of("before", "after"), required=False,
              doc="hold, release: before the child runs, or after it returned (the transition held)"),
        Field("outcome", OPT_STR, required=False, doc="hold: the outcome to be taken; release, forced: the one taken"),
        Field("returned", OPT_STR, required=False, doc="forced: what the state returned (null: it did not run)"),
        Field("reason", _one_of("pause", "step", "breakpoint"), required=False, doc="hold: why"),
        Field("detail", STR, required=False, doc="hold: in words ('hit breakpoint before PICK/CLOSE when ...')"),
        Field("by", OPT_STR, required=False, doc="mode, forced, breakpoints: who asked; release: what ended the "
                                                  "hold (resume, step, force, preempt, shutdown, detach)"),
        Field("breakpoints", _list_of(Type("a breakpoint", lambda b: _fields_problem(b, BREAKPOINT_FIELDS)),
                                      "a list of breakpoints"), required=False, doc="breakpoints: the whole set"))),
    Kind("pose", "The robot's pose, sampled at the rate the 3D view draws it (the demo: 30 Hz).", (
        Field("joints", MAP_NUMBER, doc="joint positions by joint name (radians, metres)"),
        Field("bodies", MAP_BODY_POSE, required=False,
              doc="free bodies' poses by name: [x, y, z, qw, qx, qy, qz] in the world frame"))),
    Kind("snapshot", "The full rebuilt state of one machine at seq.", (
        Field("status", STATUS, doc="the machine's state after the event seq"),)),
)}


def event(seq: int, t: float, run: str | None, machine: str, kind: str, path: str,
          fields: dict | None = None) -> dict:
    """An event: the envelope, then the kind's fields (the one place an event dict is made)."""
    if fields:
        return {"v": VERSION, "seq": seq, "t": t, "run": run, "machine": machine, "kind": kind, "path": path,
                **fields}
    return {"v": VERSION, "seq": seq, "t": t, "run": run, "machine": machine, "kind": kind, "path": path}


_MISSING = object()
Compiled = tuple[tuple[str, "tuple | None", "Callable[[Any], bool] | None", bool], ...]


def _compile(fields: tuple[Field, ...]) -> Compiled:
    def fast(t: Type) -> Callable[[Any], bool] | None:
        if t.ok is not None or t.types is not None:
            return t.ok
        return lambda v: t.check(v) is None
    return tuple((f.name, f.type.types, fast(f.type), f.required) for f in fields)


def _fits(ev: dict, compiled: Compiled) -> bool:
    """The fast yes: every field present when required and of its type (no words when not)."""
    get = ev.get
    for name, types, ok, required in compiled:
        v = get(name, _MISSING)
        if v is _MISSING:
            if required:
                return False
        elif (types is not None and type(v) not in types) or (ok is not None and not ok(v)):
            return False
    return True


_ENVELOPE = _compile(ENVELOPE)
_KIND_FIELDS = {name: _compile(k.fields) for name, k in KINDS.items()}


def _structure_problem(ev: dict) -> str | None:
    if ev["root"]["path"] != ev["path"]:
        return "structure.root.path %r differs from the event's path %r" % (ev["root"]["path"], ev["path"])
    return None


# What each debug action needs besides the fields every debug event may have.
DEBUG_NEEDS = {"mode": ("mode",), "hold": ("state", "at", "reason", "detail"), "release": ("state", "at"),
               "forced": ("state", "outcome"), "breakpoints": ("breakpoints",)}


def _debug_problem(ev: dict) -> str | None:
    missing = [name for name in DEBUG_NEEDS[ev["action"]] if name not in ev]
    return "debug %s lacks '%s'" % (ev["action"], missing[0]) if missing else None


# Checks across fields, for the kinds that have them: None when the event is right.
_ACROSS: dict[str, Callable[[dict], "str | None"]] = {"structure": _structure_problem, "debug": _debug_problem}


def validate(ev: Any) -> str | None:
    """What is wrong with ``ev``, in words; None when it is a well-formed event of this schema."""
    if type(ev) is dict:
        kind = ev.get("kind")
        fields = _KIND_FIELDS.get(kind) if type(kind) is str else None
        if fields is not None and _fits(ev, _ENVELOPE) and _fits(ev, fields):
            across = _ACROSS.get(kind)
            if across is None or across(ev) is None:
                return None
    return _problem(ev)


def _problem(ev: Any) -> str | None:
    problem = _fields_problem(ev, ENVELOPE, "event")
    if problem:
        return problem
    spec = KINDS.get(ev["kind"])
    if spec is None:
        return "unknown kind %r" % ev["kind"][:50]
    problem = _fields_problem(ev, spec.fields, ev["kind"])
    if problem:
        return problem
    across = _ACROSS.get(spec.name)
    return across(ev) if across is not None else None


# Graph element ids (docs/api.md). A path can hold any character; XML cannot hold control
# characters, so those (and '%', to keep the mapping one to one) are percent-escaped.

ID_PREFIXES = {"state": "s:", "container": "c:", "outcome": "o:", "edge": "e:"}
ID_ESCAPES = {c: "%%%02X" % c for c in [*range(0x20), 0x25, 0x7F]}
ID_ESCAPES.update({c: "%%u%04X" % c for c in (0xFFFE, 0xFFFF)})


def id_text(text: str) -> str:
    """``text`` safe for an XML attribute: control characters and '%' percent-escaped."""
    return text.translate(ID_ESCAPES)


def state_id(path: str) -> str:
    return "s:" + id_text(path)


def container_id(path: str) -> str:
    return "c:" + id_text(path)


def outcome_id(path: str, outcome: str) -> str:
    return "o:%s:%s" % (id_text(path), id_text(outcome))


def edge_id(path: str, frm: str, outcome: str) -> str:
    return "e:%s:%s:%s" % (id_text(path), id_text(frm), id_text(outcome))
