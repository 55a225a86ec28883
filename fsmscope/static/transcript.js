// An event as the SMACH log line it stands for (docs/events.md: the runtime's start,
// transition, termination and Concurrence lines are rebuilt from events, word for word), in
// the words of fsm/logfiles/transcript.py; an event that stands for none is described instead.
// Returns plain text; the caller puts it in the page with textContent.

import { containerKind } from "./schema.js";
import { allNodes } from "./status.js";

/** Python's repr() of a str. */
export function pyStr(s) {
  s = String(s);
  const quote = s.includes("'") && !s.includes('"') ? '"' : "'";
  let out = quote;
  for (const ch of s) {
    const code = ch.codePointAt(0);
    if (ch === "\\") out += "\\\\";
    else if (ch === quote) out += "\\" + ch;
    else if (ch === "\n") out += "\\n";
    else if (ch === "\r") out += "\\r";
    else if (ch === "\t") out += "\\t";
    else if (code < 0x20 || code === 0x7f) out += "\\x" + code.toString(16).padStart(2, "0");
    else out += ch;
  }
  return out + quote;
}

/** Python's repr() of a JSON value (str/None/bool/number/list/dict). */
export function pyRepr(value) {
  if (value === null || value === undefined) return "None";
  if (value === true) return "True";
  if (value === false) return "False";
  if (typeof value === "string") return pyStr(value);
  if (typeof value === "number") return Number.isInteger(value) && !Object.is(value, -0) ? String(value) : pyFloat(value);
  if (Array.isArray(value)) return "[" + value.map(pyRepr).join(", ") + "]";
  if (typeof value === "object") {
    return "{" + Object.entries(value).map(([k, v]) => pyStr(k) + ": " + pyRepr(v)).join(", ") + "}";
  }
  return String(value);
}

function pyFloat(x) {
  const s = String(x);
  return /[.eE]/.test(s) || !Number.isFinite(x) ? s : s + ".0";
}

/** A short one-line rendering of an encoded userdata value (docs/events.md "Encoding values"). */
export function valueText(value, max = 200) {
  let text;
  if (value && typeof value === "object" && !Array.isArray(value)) {
    if (typeof value.$repr === "string") text = value.$repr;
    else if (value.$truncated) text = `${value.repr ?? ""}… (${value.size} bytes, truncated)`;
  }
  if (text === undefined) text = JSON.stringify(value);
  if (text === undefined) text = String(value);
  return text.length > max ? text.slice(0, max) + "…" : text;
}

const SERVICED_PREEMPT = "Concurrence serviced preempt.";

/** Python's str() of a JSON value: what SMACH's '%s' writes. */
function pyS(value) {
  return typeof value === "string" ? value : pyRepr(value);
}

/** The container class behind an event's path, from its structure node or, without one, guessed
 * from the event (fsm/logfiles/structure_index.py's container_type: the same rules). */
export function containerType(ev, node) {
  if (node) return containerKind(node);
  if (ev.kind === "transition" && (ev.to === null || ev.to === undefined)) return "Concurrence";
  if (ev.kind === "terminate" && "outcomes" in ev) return "Concurrence";
  if (ev.kind === "transition" && ev.from === ev.to) return "Iterator";
  return "StateMachine";
}

/**
 * Events, fed one at a time in order, as the SMACH log lines they stand for: the lines of
 * fsm/logfiles/transcript.py's Transcript, word for word (tests/browser/test_browser_transcript.py
 * compares them over a recorded run of every example). A Concurrence that logged
 * "Concurrence serviced preempt." prints no "Concurrent Outcomes" line: that needs the events before.
 */
export class Transcript {
  /** @param {(path: string) => object|undefined} [nodeOf] the structure node at a path; without
   * it, the structure comes from the events' own `structure` and `snapshot` events */
  constructor(nodeOf) {
    this.own = new Map(); // machine + "\n" + container path -> structure node (without nodeOf)
    this.nodeOf = nodeOf ?? ((path, machine) => this.own.get(machine + "\n" + path));
    this.indexing = !nodeOf;
    this.serviced = new Set(); // machine + "\n" + path of the Concurrences that logged a serviced preempt
  }

  /** @returns {{level: string, text: string}[]} the lines the event stands for (none or one) */
  lines(ev) {
    if (this.indexing) this._index(ev);
    const line = this._line(ev);
    return line ? [line] : [];
  }

  /** The event log's row of the event: its SMACH line, or else a description of the event; a
   * transition or terminate followed by the keys its step wrote (an older log's userdata event before it). */
  row(ev) {
    const row = this.lines(ev)[0] ?? description(ev);
    return ev.changes && ev.kind !== "userdata" ? { level: row.level, text: row.text + " · " + writesText(ev.changes) } : row;
  }

  _index(ev) {
    const root = ev.kind === "structure" ? ev.root : ev.kind === "snapshot" ? ev.status?.structure : null;
    if (!root) return;
    for (const node of allNodes(root)) if (node.container) this.own.set(ev.machine + "\n" + node.path, node);
  }

  _line(ev) {
    const key = ev.machine + "\n" + ev.path;
    if (ev.kind === "log") {
      if (ev.msg === SERVICED_PREEMPT) this.serviced.add(key);
      return { level: ev.level || "info", text: String(ev.msg ?? "") };
    }
    if (ev.kind === "control") return controlLine(ev);
    if (ev.kind === "debug") return debugLine(ev);
    if (!["start", "transition", "terminate"].includes(ev.kind)) return null;
    const type = containerType(ev, this.nodeOf(ev.path, ev.machine));
    if (type === "Iterator") return null; // SMACH's Iterator prints only "Iterating ..." (a log event)
    const info = (text) => ({ level: "info", text });
    if (ev.kind === "start") {
      this.serviced.delete(key);
      const keys = pyRepr(Object.keys(ev.userdata || {}));
      if (type === "Concurrence") return info("Concurrence starting with userdata: \n\t" + keys);
      const initial = (ev.initial?.length ? ev.initial : ev.active?.length ? ev.active : ["None"])[0];
      return info(`State machine starting in initial state '${pyS(initial)}' with userdata: \n\t${keys}`);
    }
    if (ev.kind === "transition") {
      return type === "Concurrence"
        ? info(`Concurrent state '${pyS(ev.from)}' returned outcome '${pyS(ev.outcome)}' on termination.`)
        : info(`State machine transitioning '${pyS(ev.from)}':'${pyS(ev.outcome)}'-->'${pyS(ev.to)}'`);
    }
    if (ev.outcome === null || ev.outcome === undefined) return null; // the runtime logs failures itself
    if (type === "Concurrence") {
      const serviced = ev.outcome === "preempted" && this.serviced.has(key);
      return serviced ? null : info("Concurrent Outcomes: " + pyRepr(ev.outcomes || {}));
    }
    const last = ev.last?.length ? ev.last[0] : "None";
    const stateOutcome = "state_outcome" in ev ? ev.state_outcome : ev.outcome;
    return info(`State machine terminating '${pyS(last)}':'${pyS(stateOutcome)}':'${pyS(ev.outcome)}'`);
  }
}

function controlLine(ev) {
  const reason = ev.reason ? ` (${ev.reason})` : "";
  const params = ev.params && Object.keys(ev.params).length ? " " + valueText(ev.params, 120) : "";
  const result = ev.result === "accepted" ? "accepted" : `refused: ${ev.result}`;
  return {
    level: ev.result === "accepted" ? "info" : "warn",
    text: `Control ${ev.action ?? "?"}${params} from ${ev.client ?? "?"}${reason}: ${result}`,
  };
}

const MODE_WORDS = { run: "running", pause: "pausing at the next transition", step: "stepping one transition" };

/** A debug event's line, in the words of fsm/logfiles/transcript.py's debug_message. */
export function debugLine(ev) {
  const by = ev.by ? ` by ${ev.by}` : "";
  switch (ev.action) {
    case "mode": {
      const level = ev.level ? ` (the step ends at ${ev.level}'s next transition)` : "";
      return { level: "info", text: `Debugger ${MODE_WORDS[ev.mode] ?? ev.mode}${level}${by}` };
    }
    case "hold": {
      const outcome = ev.outcome !== null && ev.outcome !== undefined ? `:'${ev.outcome}'` : "";
      return { level: "warn", text: `Holding ${ev.at} '${ev.state}'${outcome}: ${ev.detail}` };
    }
    case "release":
      return { level: "info", text: `Released '${ev.state}' (${ev.by ?? "?"})` };
    case "forced": {
      const said = ev.returned === null || ev.returned === undefined ? "it did not run" : `it returned '${ev.returned}'`;
      return { level: "warn", text: `Forced outcome '${ev.outcome}' of '${ev.state}' (${said})${by}` };
    }
  }
  const listed = (ev.breakpoints ?? []).map(breakpointText).join("; ") || "none";
  return { level: "info", text: `Breakpoints: ${listed}${by}` };
}

/** `before /SM_ROOT/PICK/CLOSE when attempts > 2`, as fsm/logfiles/transcript.py's breakpoint_text. */
export function breakpointText(bp) {
  let text = `${bp.at} ${bp.state}`;
  if (bp.outcome !== null && bp.outcome !== undefined) text += ` with outcome '${bp.outcome}'`;
  if (bp.when) text += ` when ${bp.when}`;
  return text;
}

/** Written userdata keys (a userdata event's or a step's `changes`), for the event log. */
function writesText(changes) {
  return "Userdata: " + Object.entries(changes).map(([k, v]) => `${k} = ${valueText(v, 80)}`).join(", ");
}

/** An event that stands for no SMACH line, described for the event log. */
function description(ev) {
  switch (ev.kind) {
    case "structure":
      return { level: "debug", text: `Structure of ${ev.path}: ${ev.root ? [...allNodes(ev.root)].length : 0} states` };
    case "terminate":
      if (ev.outcome === null || ev.outcome === undefined) {
        return { level: "error", text: `Container ${ev.path} ended without an outcome` + (ev.error ? `: ${ev.error}` : ".") };
      }
      break;
    case "userdata":
      return { level: "debug", text: writesText(ev.changes || {}) };
    case "preempt":
      return ev.phase === "serviced"
        ? { level: "info", text: `Preempt serviced by ${ev.path}` }
        : { level: "info", text: `Preempt requested on ${ev.path}` };
    case "error":
      return {
        level: "error",
        text: `State ${pyStr(ev.state ?? "None")} failed to execute. ${ev.exc_type ?? "Error"}: ${ev.message ?? ""}`,
      };
    case "feedback":
      return { level: "debug", text: `Feedback (${ev.action ?? "action"}): ${valueText(ev.feedback, 160)}` };
  }
  return { level: "debug", text: `${ev.kind} ${ev.path}` };
}
