// The machines the server serves (/api/machines, polled) and the picker; a machine's run state; and
// the one place that says what a machine's source (schema.js) lets this page do with it.

import { api, ApiError } from "./api.js";
import { readLink, writeLink } from "./deeplink.js";
import { holdChange } from "./loop.js";
import { banner } from "./notice.js";
import { h, setText } from "./dom.js";
import { RUN_STATES, SOURCES, runState as schemaRunState } from "./schema.js";

const POLL_MS = 2000;

const NOT_CONTROLLABLE = {
  [SOURCES.ingest]: "this machine runs in another process whose publisher takes no control: control it there",
  [SOURCES.replay]: "this machine is a recording being replayed: nothing to control",
};

/** Why this page cannot control the machine of `entry` (its /api/machines entry; "" when it can):
 * the server would answer 409. Start and hold need the entry's `can_start` and `can_hold` too. */
export function controlRefusal(entry) {
  if (!entry) return "no such machine on the server";
  if (entry.controllable) return "";
  if (entry.connected === false) return "the process that publishes this machine is not connected: its controls are unavailable";
  return NOT_CONTROLLABLE[entry.source] || `a machine of source ${entry.source} cannot be controlled`;
}

/** Whether the events of the machine of `entry` are a recording played again (their times tell no latency). */
export const isReplay = (entry) => entry?.source === SOURCES.replay;

/** The run state (schema.js runState) of status `s` of the machine of `entry` (its /api/machines
 * entry), as the dashboard words it: a machine whose process left is "disconnected" here (the
 * fleet's tiles say "gone"). */
export function runState(s, entry) {
  const state = schemaRunState(s.running, s.outcome, s.error, entry?.connected);
  return state === RUN_STATES.gone ? "disconnected" : state;
}

/** The pill that says the run state of status `s` (null: none yet) of the machine of `entry`. */
export function showRunState(pill, s, entry) {
  const known = Boolean(s?.root_path); // its structure has been seen (a past status from the server omits the tree)
  const state = known ? runState(s, entry) : "idle";
  let text = known ? state : "—";
  if (state === "failed") text = "failed: " + (s.error.exc_type || "error");
  if (state === "done") text = "finished: " + s.outcome;
  setText(pill, text);
  pill.className = "pill " + state;
  pill.title = s?.error ? `${s.error.exc_type || ""} ${s.error.message || ""}`.trim() : "";
}

/** The /api/machines list, polled, and the picker that opens one of them. */
export class Machines {
  /** @param {object} handlers {open(name): show that machine, polled(): after each poll, answered or not} */
  constructor(picker, store, handlers) {
    this.picker = picker;
    this.store = store;
    this.handlers = handlers;
    this.list = [];
    this.endings = new Map(); // name -> {seq, error} of the other machines that ended without an outcome
    this.online = true;
    picker.addEventListener("change", () => handlers.open(picker.value));
  }

  /** The /api/machines entry of the machine shown, or null. */
  current() {
    return this.list.find((m) => m.name === this.store.name) || null;
  }

  async poll() {
    try {
      const list = await api.machines();
      this.online = true;
      banner("");
      this.list = Array.isArray(list) ? list : [];
      this.checkEndings();
      this.fillPicker();
      this._pick();
    } catch (err) {
      this.online = false;
      const unauthorized = err instanceof ApiError && err.status === 401;
      banner(unauthorized ? "Not authorized: open the address the server printed (the one with ?token=...)." : "");
    } finally {
      this.handlers.polled();
      setTimeout(() => this.poll(), POLL_MS);
    }
  }

  /** Open the machine the address names, else a running one, else the first, unless one is shown. */
  _pick() {
    const name = this.store.name;
    if (name && this.list.some((m) => m.name === name)) return;
    const wanted = readLink().machine;
    const pick = this.list.find((m) => m.name === wanted) || this.list.find((m) => m.running) || this.list[0];
    if (pick && pick.name !== name) this.handlers.open(pick.name);
  }

  /** The page now shows machine `name`: the address and the picker say so. */
  opened(name) {
    writeLink(name, readLink().machine === name ? readLink().seq : null);
    this.picker.value = name;
    this.checkEndings(); // the machine shown so far is one of the others now
  }

  /** Whether the other machines that ended without an outcome failed: /api/machines does not say,
   * their status does (asked once per change of their last_seq). */
  checkEndings() {
    for (const m of this.list) {
      if (m.name === this.store.name || m.running || m.outcome || this.endings.get(m.name)?.seq === m.last_seq) continue;
      const ending = { seq: m.last_seq, error: null };
      this.endings.set(m.name, ending);
      api.status(m.name).then((s) => {
        ending.error = s.error;
        this.fillPicker();
      }).catch(() => this.endings.delete(m.name)); // asked again at the next poll
    }
  }

  /** A hold seen on the stream of the machine shown: what the next poll will say of its loop. */
  sawHold(ev) {
    const held = holdChange(ev);
    const entry = this.current();
    if (held === null || !entry?.can_hold) return null;
    entry.held = held;
    return held;
  }

  fillPicker() {
    const { name, status } = this.store;
    const have = [...this.picker.options].map((o) => o.value + "\u0000" + o.textContent).join("\u0001");
    const labels = this.list.map((m) => {
      const live = m.name === name && status?.structure
        ? status // the stream is fresher
        : { running: m.running, outcome: m.outcome, error: this.endings.get(m.name)?.error };
      const state = runState(live, m);
      const text = state === "done" ? "→ " + live.outcome : state;
      return [m.name, `${m.name}  (${text}${m.source === SOURCES.ingest ? ", remote" : ""})`];
    });
    if (labels.map(([v, t]) => v + "\u0000" + t).join("\u0001") === have) return;
    this.picker.replaceChildren(...labels.map(([value, text]) => h("option", { value, text })));
    if (name) this.picker.value = name;
  }
}
