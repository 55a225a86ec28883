// The machines the server serves (/api/machines, polled into the store) and the picker; a machine's run state; and
// the one place that says what a machine's source (schema.js) lets this page do with it.

import { api, ApiError } from "./api.js";
import { readLink, writeLink } from "./deeplink.js";
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

/** The newest machine that the script of `shown` (an /api/machines entry) built, when `shown` ended and
 * is not it; else null. */
function newestOfScript(list, shown) {
  if (!shown.script || shown.running) return null;
  const newest = list.findLast((m) => m.script === shown.script);
  return newest === shown ? null : newest;
}

/** The /api/machines list, polled into the store (store.js), and the picker that opens one of them. */
export class Machines {
  /** @param {object} handlers {open(name): show that machine, polled(): after each poll, answered or not,
   * refused(yes): whether the server refused this page's token} */
  constructor(picker, store, handlers) {
    this.picker = picker;
    this.store = store;
    this.handlers = handlers;
    this.picked = null; // the machine the user chose (in the list, or by the address the page opened): kept shown
    picker.addEventListener("change", () => {
      this.picked = picker.value;
      handlers.open(picker.value);
    });
  }

  async poll() {
    try {
      const list = await api.machines();
      this.store.setBanner("");
      this.handlers.refused(false);
      this.store.setMachines(Array.isArray(list) ? list : [], true);
      this.checkEndings();
      this._pick();
    } catch (err) {
      const unauthorized = err instanceof ApiError && err.status === 401;
      this.store.setBanner(unauthorized ? "Not authorized: this browser holds no valid token for this dashboard." : "");
      this.store.setMachines(null, false);
      this.handlers.refused(unauthorized);
    } finally {
      this.handlers.polled();
      setTimeout(() => this.poll(), POLL_MS);
    }
  }

  /** Open the machine the address names, else a running one, else the first, unless one is shown; and
   * when the one shown ended and its script built a newer one (a script that builds a machine per loop),
   * that one, unless the user chose the one shown or looks back. */
  _pick() {
    const { name, instant, machines: { list } } = this.store.state;
    const shown = list.find((m) => m.name === name);
    if (shown) {
      const newest = name === this.picked || instant.past ? null : newestOfScript(list, shown);
      if (newest) {
        this.handlers.open(newest.name);
        this.store.say(`${name} ended: following ${newest.name}, the newest machine of ${shown.script} (choose one in the list to stay on it)`);
      }
      return;
    }
    const wanted = readLink().machine;
    const pick = list.find((m) => m.name === wanted) || list.find((m) => m.running) || list[0];
    if (pick && pick.name === wanted) this.picked = wanted;
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
    const { name, machines: { list, endings } } = this.store.state;
    for (const m of list) {
      if (m.name === name || m.running || m.outcome || endings.get(m.name)?.seq === m.last_seq) continue;
      const ending = { seq: m.last_seq, error: null };
      this.store.setEnding(m.name, ending);
      api.status(m.name).then((s) => this.store.setEnding(m.name, { ...ending, error: s.error }))
        .catch(() => this.store.setEnding(m.name, null)); // asked again at the next poll
    }
  }

  /** The picker: each machine and its run state (the stream's, fresher, for the machine shown). */
  update({ name, live, machines: { list, endings } }) {
    const have = [...this.picker.options].map((o) => o.value + "\u0000" + o.textContent).join("\u0001");
    const labels = list.map((m) => {
      const status = m.name === name && live?.structure
        ? live // the stream is fresher
        : { running: m.running, outcome: m.outcome, error: endings.get(m.name)?.error };
      const state = runState(status, m);
      const text = state === "done" ? "→ " + status.outcome : state;
      return [m.name, `${m.name}  (${text}${m.source === SOURCES.ingest ? ", remote" : ""})`];
    });
    if (labels.map(([v, t]) => v + "\u0000" + t).join("\u0001") === have) return;
    this.picker.replaceChildren(...labels.map(([value, text]) => h("option", { value, text })));
    if (name) this.picker.value = name;
  }
}
