// Generated from fsm/observation/schema.py by `python -m server.schema_export`: do not edit by hand
// (tests/test_schema_export.py fails when this file and the Python definition differ).

/** The event schema version this page reads. */
export const SCHEMA_VERSION = 1;

/** Every event kind. */
export const KINDS = Object.freeze(["structure", "start", "transition", "terminate", "userdata", "preempt", "error", "log", "feedback", "control", "debug", "pose", "snapshot"]);

/** Where a served machine's events come from. */
export const SOURCES = Object.freeze({"local": "local", "ingest": "ingest", "replay": "replay"});

// Graph element ids: a path can hold any character; control characters and '%' are
// percent-escaped (one to one), as the server's SVG writes them.
const ESCAPED = new Map(Object.entries({"\u0000": "%00", "\u0001": "%01", "\u0002": "%02", "\u0003": "%03", "\u0004": "%04", "\u0005": "%05", "\u0006": "%06", "\u0007": "%07", "\b": "%08", "\t": "%09", "\n": "%0A", "\u000b": "%0B", "\f": "%0C", "\r": "%0D", "\u000e": "%0E", "\u000f": "%0F", "\u0010": "%10", "\u0011": "%11", "\u0012": "%12", "\u0013": "%13", "\u0014": "%14", "\u0015": "%15", "\u0016": "%16", "\u0017": "%17", "\u0018": "%18", "\u0019": "%19", "\u001a": "%1A", "\u001b": "%1B", "\u001c": "%1C", "\u001d": "%1D", "\u001e": "%1E", "\u001f": "%1F", "%": "%25", "\u007f": "%7F", "\ufffe": "%uFFFE", "\uffff": "%uFFFF"}));
const NEEDS_ESCAPE = /[\u0000\u0001\u0002\u0003\u0004\u0005\u0006\u0007\u0008\u0009\u000a\u000b\u000c\u000d\u000e\u000f\u0010\u0011\u0012\u0013\u0014\u0015\u0016\u0017\u0018\u0019\u001a\u001b\u001c\u001d\u001e\u001f\u0025\u007f\ufffe\uffff]/;

export function idText(text) {
  text = String(text);
  if (!NEEDS_ESCAPE.test(text)) return text;
  let out = "";
  for (const ch of text) out += ESCAPED.get(ch) ?? ch;
  return out;
}

export const stateId = (path) => "s:" + idText(path);
export const containerId = (path) => "c:" + idText(path);
export const outcomeId = (path, outcome) => `o:${idText(path)}:${idText(outcome)}`;
export const edgeId = (path, from, outcome) => `e:${idText(path)}:${idText(from)}:${idText(outcome)}`;

// Which of SMACH's containers a structure node is: its type when it is one of these, else (a
// user's subclass) the kind whose own field it carries, else a state machine.
const CONTAINER_TYPES = Object.freeze(["StateMachine", "Sequence", "Concurrence", "Iterator"]);
const KIND_FIELDS = Object.freeze([["outcome_map", "Concurrence"], ["exhausted_outcome", "Iterator"]]);

export function containerKind(node) {
  const type = node.type ?? "StateMachine";
  if (CONTAINER_TYPES.includes(type)) return type;
  return KIND_FIELDS.find(([field]) => field in node)?.[1] ?? "StateMachine";
}

// A machine's name (fsm/observation/names.py): 1 to MAX_NAME characters, none of / * $ ? # or a
// control character, no space at either end; valid wherever a name travels.
export const MAX_NAME = 200;
const NAME_FORBIDDEN = /[\u002f\u002a\u0024\u003f\u0023\u0000\u0001\u0002\u0003\u0004\u0005\u0006\u0007\u0008\u0009\u000a\u000b\u000c\u000d\u000e\u000f\u0010\u0011\u0012\u0013\u0014\u0015\u0016\u0017\u0018\u0019\u001a\u001b\u001c\u001d\u001e\u001f\u007f]/;

export function isMachineName(name) {
  return typeof name === "string" && name.length > 0 && [...name].length <= MAX_NAME && !name.startsWith(" ")
    && !name.endsWith(" ") && !NAME_FORBIDDEN.test(name);
}

// The words the server and the page share (fsm/observation/vocabularies.py).

/** A machine's run states. */
export const RUN_STATES = Object.freeze({"running": "running", "done": "done", "failed": "failed", "idle": "idle", "gone": "gone"});

/** The run state of a machine: `running`, `outcome` and `error` from its status, `connected` from its
 * /api/machines entry (false: its process left). Mirrors vocabularies.run_state. */
export function runState(running, outcome, error, connected) {
  if (running) return connected === false ? RUN_STATES.gone : RUN_STATES.running;
  if (outcome !== null && outcome !== undefined) return RUN_STATES.done;
  if (error !== null && error !== undefined) return RUN_STATES.failed;
  return connected === false ? RUN_STATES.gone : RUN_STATES.idle;
}

/** The kinds of the timeline's ticks: an event of one of these kinds, or a run's start (the last). */
export const TICK_KINDS = Object.freeze(["error", "preempt", "control", "debug", "run"]);
