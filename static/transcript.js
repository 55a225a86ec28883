// An event as the SMACH log line it stands for (docs/events.md: the runtime's start,
// transition, termination and Concurrence lines are rebuilt from events, word for word).
// Returns plain text; the caller puts it in the page with textContent.

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

function lastStateOutcome(node, last, containerOutcome) {
  // The terminate event carries the container outcome; the state's own outcome is the
  // transition that leads there (the first, if several do).
  for (const tr of node?.transitions || []) {
    if (tr.from === last && (tr.to === containerOutcome || (tr.to === null && tr.outcome === containerOutcome))) {
      return tr.outcome;
    }
  }
  return containerOutcome;
}

/**
 * @param {object} ev an event
 * @param {(path: string) => object|undefined} nodeOf the structure node at a path
 * @returns {{level: string, text: string}}
 */
export function transcript(ev, nodeOf = () => undefined) {
  const node = nodeOf(ev.path);
  const type = node?.type;
  switch (ev.kind) {
    case "structure": {
      let n = 0;
      const count = (nd) => { n += 1; (nd.children || []).forEach(count); };
      if (ev.root) count(ev.root);
      return { level: "debug", text: `Structure of ${ev.path}: ${n} states` };
    }
    case "start": {
      const keys = pyRepr(Object.keys(ev.userdata || {}));
      if (type === "Concurrence") return { level: "info", text: "Concurrence starting with userdata: \n\t" + keys };
      if (type === "Iterator") return { level: "info", text: `Iterator starting with userdata: \n\t${keys}` };
      const first = (ev.active && ev.active[0]) ?? (ev.initial && ev.initial[0]) ?? "None";
      return { level: "info", text: `State machine starting in initial state ${pyStr(first)} with userdata: \n\t${keys}` };
    }
    case "transition":
      if (ev.to === null || ev.to === undefined) {
        return { level: "info", text: `Concurrent state ${pyStr(ev.from)} returned outcome ${pyStr(ev.outcome)} on termination.` };
      }
      return { level: "info", text: `State machine transitioning ${pyStr(ev.from)}:${pyStr(ev.outcome)}-->${pyStr(ev.to)}` };
    case "terminate": {
      if (ev.outcome === null || ev.outcome === undefined) {
        return { level: "error", text: `Container ${ev.path} ended without an outcome` + (ev.error ? `: ${ev.error}` : ".") };
      }
      if (type === "Concurrence" || ev.outcomes) {
        return { level: "info", text: "Concurrent Outcomes: " + pyRepr(ev.outcomes || {}) };
      }
      const last = (ev.last && ev.last[0]) ?? "None";
      const outcome = lastStateOutcome(node, last, ev.outcome);
      return { level: "info", text: `State machine terminating ${pyStr(last)}:${pyStr(outcome)}:${pyStr(ev.outcome)}` };
    }
    case "userdata":
      return {
        level: "debug",
        text: "Userdata: " + Object.entries(ev.changes || {}).map(([k, v]) => `${k} = ${valueText(v, 80)}`).join(", "),
      };
    case "preempt":
      return ev.phase === "serviced"
        ? { level: "info", text: `Preempt serviced by ${ev.path}` }
        : { level: "info", text: `Preempt requested on ${ev.path}` };
    case "error":
      return {
        level: "error",
        text: `State ${pyStr(ev.state ?? "None")} failed to execute. ${ev.exc_type ?? "Error"}: ${ev.message ?? ""}`,
      };
    case "log":
      return { level: ev.level || "info", text: String(ev.msg ?? "") };
    case "feedback":
      return { level: "debug", text: `Feedback (${ev.action ?? "action"}): ${valueText(ev.feedback, 160)}` };
    case "control": {
      const reason = ev.reason ? ` (${ev.reason})` : "";
      const params = ev.params && Object.keys(ev.params).length ? " " + valueText(ev.params, 120) : "";
      const result = ev.result === "accepted" ? "accepted" : `refused: ${ev.result}`;
      return {
        level: ev.result === "accepted" ? "info" : "warn",
        text: `Control ${ev.action ?? "?"}${params} from ${ev.client ?? "?"}${reason}: ${result}`,
      };
    }
    default:
      return { level: "debug", text: `${ev.kind} ${ev.path}` };
  }
}
