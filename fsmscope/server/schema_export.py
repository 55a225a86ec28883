"""The schema (fsm/observation/schema/) as the browser and the docs read it.

``fsmscope/static/schema.js`` (its constants, and JSDoc typedefs of every event, frame and shape), the field
tables of ``docs/events.md`` and the frame tables of ``docs/api.md`` are generated from the one
definition in ``fsm.observation.schema``; ``tests/unit/test_schema_export.py`` regenerates them and
fails on any difference. After changing the
schema: ``python -m fsmscope.server.schema_export``.
"""

from __future__ import annotations

import json
import os
import re

from fsm.observation import names, schema, vocabularies

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
JS_PATH = os.path.join(ROOT, "fsmscope", "static", "schema.js")
DOC_PATH = os.path.join(ROOT, "docs", "events.md")
API_DOC_PATH = os.path.join(ROOT, "docs", "api.md")
# The websocket frames docs/api.md lists, a table per websocket they travel on.
SOCKETS = {"stream_frames": ("snapshot", "events", "missed", "pace"), "overview_frames": ("overview",),
           "ingest_frames": ("hello", "control", "answer", "lease", "rejected")}
_BLOCK = re.compile(r"(<!-- schema:(\w+) -->\n).*?(<!-- /schema -->)", re.S)


def _pascal(name: str) -> str:
    return "".join(part.capitalize() for part in name.replace("-", "_").split("_"))


def _typedef(name: str, doc: str, fields: tuple[schema.Field, ...], constants: tuple[tuple[str, str], ...] = ()) -> str:
    """A JSDoc typedef of an object: ``constants`` (field, its one value as JS) first, then ``fields``."""
    lines = ["/**", " * " + doc, " * @typedef {Object} " + name]
    lines += [" * @property {%s} %s" % (value, field) for field, value in constants]
    lines += [(" * @property {%s} %s %s" % (f.type.js, f.name if f.required else "[%s]" % f.name, f.doc)).rstrip()
              for f in fields]
    return "\n".join(lines + [" */"]) + "\n"


def typedefs() -> str:
    """JSDoc typedefs of every event kind (``TransitionEvent``, ..., ``FsmEvent``), every frame
    (``SnapshotFrame``, ..., ``Frame``) and every shape they hold (``MachineStatus``, ``Breakpoint``, ...)."""
    out = []
    for name, kind in schema.KINDS.items():
        this_kind = schema.Type(name, lambda v: None, js='"%s"' % name)
        envelope = tuple(schema.Field(f.name, this_kind) if f.name == "kind" else f for f in schema.ENVELOPE)
        out.append(_typedef(_pascal(name) + "Event", kind.doc, envelope + kind.fields))
    out.append("/** @typedef {%s} FsmEvent */\n" % "|".join(_pascal(n) + "Event" for n in schema.KINDS))
    for name, message in schema.MESSAGES.items():
        out.append(_typedef(_pascal(name) + "Frame", "%s (%s)." % (message.doc[:-1], message.sender), message.fields,
                            (("type", '"%s"' % name),)))
    out.append("/** @typedef {%s} Frame */\n" % "|".join(_pascal(n) + "Frame" for n in schema.MESSAGES))
    for js, shape in sorted(schema.SHAPES.items()):
        out.append(_typedef(js, shape.name[0].upper() + shape.name[1:] + ".", shape.shape))
    return "\n".join(out)


def javascript() -> str:
    """The text of fsmscope/static/schema.js."""
    escapes = {chr(code): text for code, text in schema.ID_ESCAPES.items()}
    pattern = "".join("\\u%04x" % ord(c) for c in escapes)
    return """// Generated from fsm/observation/schema/ by `python -m fsmscope.server.schema_export`: do not edit by hand
// (tests/unit/test_schema_export.py fails when this file and the Python definition differ).
// One piece because it is the page's copy of that one definition: constants, rules and typedefs.

/** The event schema version this page reads. */
export const SCHEMA_VERSION = %(version)d;

/** Every event kind. */
export const KINDS = Object.freeze(%(kinds)s);

/** Where a served machine's events come from. */
export const SOURCES = Object.freeze(%(sources)s);

/** A fleet overview tile's states, in the order that needs a look first. */
export const TILE_STATES = Object.freeze(%(tile_states)s);

// Graph element ids: a path can hold any character; control characters and '%%' are
// percent-escaped (one to one), as the server's SVG writes them.
const ESCAPED = new Map(Object.entries(%(escapes)s));
const NEEDS_ESCAPE = /[%(pattern)s]/;

export function idText(text) {
  text = String(text);
  if (!NEEDS_ESCAPE.test(text)) return text;
  let out = "";
  for (const ch of text) out += ESCAPED.get(ch) ?? ch;
  return out;
}

export const stateId = (path) => "%(s)s" + idText(path);
export const containerId = (path) => "%(c)s" + idText(path);
export const outcomeId = (path, outcome) => `%(o)s${idText(path)}:${idText(outcome)}`;
export const edgeId = (path, from, outcome) => `%(e)s${idText(path)}:${idText(from)}:${idText(outcome)}`;

// Which of SMACH's containers a structure node is: its type when it is one of these, else (a
// user's subclass) the kind whose own field it carries, else a state machine.
const CONTAINER_TYPES = Object.freeze(%(container_types)s);
const KIND_FIELDS = Object.freeze(%(kind_fields)s);

export function containerKind(node) {
  const type = node.type ?? "StateMachine";
  if (CONTAINER_TYPES.includes(type)) return type;
  return KIND_FIELDS.find(([field]) => field in node)?.[1] ?? "StateMachine";
}

// A machine's name (fsm/observation/names.py): 1 to MAX_NAME characters, none of / * $ ? # or a
// control character, no space at either end; valid wherever a name travels.
export const MAX_NAME = %(max_name)d;
const NAME_FORBIDDEN = /[%(name_forbidden)s]/;

export function isMachineName(name) {
  return typeof name === "string" && name.length > 0 && [...name].length <= MAX_NAME && !name.startsWith(" ")
    && !name.endsWith(" ") && !NAME_FORBIDDEN.test(name);
}

// The words the server and the page share (fsm/observation/vocabularies.py).

/** A machine's run states. */
export const RUN_STATES = Object.freeze(%(run_states)s);

/** The run state of a machine: `running`, `outcome` and `error` from its status, `connected` from its
 * /api/machines entry (false: its process left). Mirrors vocabularies.run_state. */
export function runState(running, outcome, error, connected) {
  if (running) return connected === false ? RUN_STATES.gone : RUN_STATES.running;
  if (outcome !== null && outcome !== undefined) return RUN_STATES.done;
  if (error !== null && error !== undefined) return RUN_STATES.failed;
  return connected === false ? RUN_STATES.gone : RUN_STATES.idle;
}

/** The kinds of the timeline's ticks: an event of one of these kinds, or a run's start (the last). */
export const TICK_KINDS = Object.freeze(%(tick_kinds)s);

// The shapes: every event, every websocket frame, a machine's status and what it holds
// (import one with /** @typedef {import("./schema.js").NAME} NAME */).

%(typedefs)s""" % {"typedefs": typedefs(), "version": schema.VERSION, "kinds": json.dumps(list(schema.KINDS)),
       "sources": json.dumps({s: s for s in schema.SOURCES}), "tile_states": json.dumps(list(schema.TILE_STATES)),
       "escapes": json.dumps(escapes), "pattern": pattern,
       "s": schema.ID_PREFIXES["state"], "c": schema.ID_PREFIXES["container"], "o": schema.ID_PREFIXES["outcome"],
       "e": schema.ID_PREFIXES["edge"], "container_types": json.dumps(list(schema.CONTAINER_TYPES)),
       "kind_fields": json.dumps([list(pair) for pair in schema.KIND_FIELDS]),
       "max_name": names.MAX_NAME, "name_forbidden": "".join("\\u%04x" % ord(c) for c in names.FORBIDDEN),
       "run_states": json.dumps({state: state for state in vocabularies.RUN_STATES}),
       "tick_kinds": json.dumps(list(vocabularies.TICK_KINDS))}


def _table(fields: tuple[schema.Field, ...]) -> str:
    rows = ["| field | type | required | meaning |", "|---|---|---|---|"]
    for f in fields:
        rows.append("| `%s` | %s | %s | %s |" % (f.name, f.type.name, "yes" if f.required else "no", f.doc))
    return "\n".join(rows) + "\n"


def tables() -> dict[str, str]:
    """Every generated table of docs/events.md, by the name its block carries."""
    out = {name: _table(kind.fields) for name, kind in schema.KINDS.items()}
    shapes = dict(envelope=_table(schema.ENVELOPE), node=_table(schema.NODE_FIELDS),
                  container=_table(schema.CONTAINER_FIELDS), edge=_table(schema.TRANSITION_FIELDS),
                  status=_table(schema.STATUS_FIELDS), container_status=_table(schema.CONTAINER_STATUS_FIELDS),
                  pending_preempt=_table(schema.PREEMPT_FIELDS), debug_status=_table(schema.DEBUG_STATUS_FIELDS),
                  hold=_table(schema.HOLD_FIELDS), breakpoint=_table(schema.BREAKPOINT_FIELDS))
    clash = out.keys() & shapes.keys()
    if clash:  # one block would show the other's fields
        raise ValueError("a shape's table is named as a kind's: %s" % ", ".join(sorted(clash)))
    out.update(shapes)
    return out


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _frames(names: tuple[str, ...]) -> str:
    """A table of frames: each as its JSON object with its fields' types (``"name"?``: optional), who
    sends it, and what it and its fields say."""
    rows = ["| frame | from | meaning |", "|---|---|---|"]
    for name in names:
        message = schema.MESSAGES[name]
        sample = ", ".join(['"type": "%s"' % name] + ['"%s"%s: %s' % (f.name, "" if f.required else "?", f.type.js)
                                                     for f in message.fields])
        said = " ".join([message.doc] + ["`%s`: %s." % (f.name, f.doc) for f in message.fields if f.doc])
        rows.append("| `{%s}` | %s | %s |" % (_cell(sample), message.sender, _cell(said)))
    return "\n".join(rows) + "\n"


def api_tables() -> dict[str, str]:
    """Every generated table of docs/api.md: the frames of each websocket, a snapshot's history, a tile."""
    out = {name: _frames(names) for name, names in SOCKETS.items()}
    out.update(history=_table(schema.HISTORY_FIELDS), tile=_table(schema.TILE_FIELDS))
    return out


def _filled(text: str, generated: dict[str, str]) -> str:
    def fill(match: re.Match) -> str:
        return match.group(1) + generated[match.group(2)] + match.group(3)
    return _BLOCK.sub(fill, text)


def events_doc(text: str) -> str:
    """docs/events.md with every ``<!-- schema:NAME -->`` block filled from the schema."""
    return _filled(text, tables())


def api_doc(text: str) -> str:
    """docs/api.md with every ``<!-- schema:NAME -->`` block filled from the schema."""
    return _filled(text, api_tables())


def blocks(text: str) -> set[str]:
    """The names of the generated blocks a text holds."""
    return {m.group(2) for m in _BLOCK.finditer(text)}


def main() -> None:
    js = javascript()
    with open(JS_PATH, "w", encoding="utf-8") as handle:
        handle.write(js)
    for path, fill in ((DOC_PATH, events_doc), (API_DOC_PATH, api_doc)):
        with open(path, encoding="utf-8") as handle:
            doc = fill(handle.read())
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(doc)


if __name__ == "__main__":
    main()
