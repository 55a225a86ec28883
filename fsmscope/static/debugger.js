// The debugger's bar: a banner saying where and why the machine holds, in the transcript's words,
// with Resume, Step, Step over and Force outcome; and Pause in the top bar. Like the other controls
// (controls.js) they are hidden from a viewer; they are disabled while the page does not show the
// live machine (looking back, a replay), when the banner shows the hold of the instant shown.

import { api } from "./api.js";
import { showMenu } from "./dialogs.js";
import { setText } from "./dom.js";
import { shownStatus, showsLive } from "./shown.js";
import { debugLine } from "./transcript.js";

const $ = (id) => document.getElementById(id);
const BUTTONS = ["pause-btn", "resume-btn", "step-btn", "step-over-btn", "force-btn"];

// Why a deadman paused the machine, for a pause hold whose words name it as who paused ("paused by
// deadman"): the server's, when the page in control stopped beating (server/lease_control.py DEADMAN),
// or a publishing process's or a fleet robot's own, when it lost the dashboard (DEADMAN_CLIENT of
// server/publisher.py and fleet/control.py). `after`: the deadman's seconds (the lease's,
// static/lease.js), when this page knows them.
const lostTheDashboard = (after) => "its process lost its connection to the dashboard" + (after ? ` for ${after} s` : "");
const DEADMAN_WHY = {
  deadman: (after) => after ? `the page in control sent no heartbeat for ${after} s` : "the page in control stopped sending heartbeats",
  publisher: lostTheDashboard,
  robot: lostTheDashboard,
};

/** The words the banner adds to `hold`'s: why a deadman paused the machine; "" when none did. */
function deadmanWhy(hold, after) {
  const by = hold.reason === "pause" && hold.detail.startsWith("paused by ") ? hold.detail.slice("paused by ".length) : null;
  return Object.hasOwn(DEADMAN_WHY, by) ? ` (${DEADMAN_WHY[by](after)})` : "";
}

/** What the banner says of a debugger's state `debug` ({mode, level, holds}): each hold, or the mode
 * when nothing holds yet; null when it runs free. `deadmanAfter`: the deadman's seconds, if known. */
export function pausedText(debug, deadmanAfter = null) {
  if (!debug) return null;
  if (debug.holds.length) {
    return "Paused " + debug.holds.map((hold) =>
      `in ${hold.path}: ${debugLine({ action: "hold", ...hold }).text}${deadmanWhy(hold, deadmanAfter)}`).join("; ");
  }
  return debug.mode === "run" ? null : debugLine({ action: "mode", mode: debug.mode, level: debug.level }).text;
}

export class DebugBar {
  /**
   * @param {Store} store the page's store (store.js)
   * @param {Controls} controls its controls (controls.js): the page's role, why it may not control, `ask`
   */
  constructor(store, controls) {
    this.store = store;
    this.controls = controls;
    $("pause-btn").addEventListener("click", () => controls.ask("Pause", api.pause));
    $("resume-btn").addEventListener("click", () => controls.ask("Resume", api.resume));
    $("step-btn").addEventListener("click", () => controls.ask("Step", api.step));
    $("step-over-btn").addEventListener("click", () => {
      const level = this._holds()[0]?.path;
      if (level) controls.ask("Step over", (name) => api.step(name, level));
    });
    $("force-btn").addEventListener("click", (e) => {
      const box = e.currentTarget.getBoundingClientRect();
      showMenu(box.left, box.bottom + 2, "Force an outcome", this._forceItems());
    });
  }

  /** Show the debugger's state at the instant shown of `state` (the store's) and enable what the live
   * machine accepts now. */
  update(state) {
    const text = pausedText(shownStatus(state)?.debug, state.lease?.deadman?.after);
    const bar = $("debug-bar");
    bar.hidden = text === null;
    const what = bar.querySelector(".debug-text");
    if (text !== null) setText(what, text);
    const now = state.live?.debug ?? { mode: "run", holds: [] };
    const paused = now.mode !== "run" || now.holds.length > 0;
    const can = showsLive(state) && !this.controls.refusal();
    const never = this.store.current()?.cannot?.pause; // its host takes no debugger control: say why
    const limits = $("debug-limits");
    limits.hidden = !never || this.controls.viewer;
    if (never) setText(limits, never);
    const enabled = {
      "pause-btn": !paused && Boolean(state.live?.running),
      "resume-btn": paused,
      "step-btn": paused,
      "step-over-btn": now.holds.length > 0,
      "force-btn": this._forceTargets().length > 0,
    };
    for (const id of BUTTONS) {
      $(id).hidden = this.controls.viewer || Boolean(never);
      $(id).disabled = !can || !enabled[id];
    }
  }

  _holds() {
    return this.store.state.live?.debug?.holds ?? [];
  }

  /** The states whose outcome may be forced: the held ones, or, when none holds, the active leaves. */
  _forceTargets() {
    const status = this.store.state.live;
    if (!status?.running) return [];
    const held = this._holds().map((hold) => hold.path + "/" + hold.state);
    return (held.length ? held : status.activeLeaves()).filter((path) => this.store.state.nodes.get(path)?.outcomes.length);
  }

  /** An item per registered outcome of each of those states. */
  _forceItems() {
    return this._forceTargets().flatMap((path) => {
      const node = this.store.state.nodes.get(path);
      return node.outcomes.map((outcome) => ({
        label: `${node.label} → ${outcome}`, title: path,
        action: () => this.controls.ask(`Force '${outcome}' of ${path}`, (name) => api.force(name, path, outcome)),
      }));
    });
  }
}
