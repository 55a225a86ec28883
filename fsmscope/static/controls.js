// What controls the machine shown: Preempt, Start, "Stop after this run" and "Set as initial state…",
// each disabled (the menu item saying why) when the server would refuse it, and none of them shown
// to a viewer (a page opened with the viewer's token: it may watch, not control).

import { api } from "./api.js";
import { confirmPreempt, editInitialState } from "./dialogs.js";
import { setText } from "./dom.js";
import { heldText } from "./loop.js";
import { controlRefusal } from "./machines.js";
import { containerKind } from "./schema.js";
import { parentPath } from "./status.js";

const $ = (id) => document.getElementById(id);

export class Controls {
  /**
   * @param {Store} store the page's store (store.js): the machine shown, its entry, this page's role
   * @param {RunNotices} notices what the notice says of its runs (notice.js)
   */
  constructor(store, notices) {
    this.store = store;
    this.notices = notices;
    $("preempt-btn").addEventListener("click", () => this._preempt());
    $("start-btn").addEventListener("click", () => this.ask("Start", api.start));
    $("hold-btn").addEventListener("click", () => this.ask("Stop after this run", api.hold, ": then the loop waits for Start"));
  }

  /** Whether this page has a viewer's token: it sees no control. */
  get viewer() {
    return this.store.state.role === "viewer";
  }

  /** Why the machine shown takes no control from this page now; "" when it does. */
  refusal() {
    return this.viewer ? "this page has a viewer's token: it may watch, not control" : controlRefusal(this.store.current());
  }

  /** Enable what the machine shown accepts now (`state`: the store's); show whether its loop is held. */
  update(state) {
    const entry = this.store.current();
    const running = state.live ? state.live.running : false;
    const live = state.machines.online && state.connection === "live";
    const controllable = !this.refusal();
    $("preempt-btn").disabled = !live || !running || !controllable;
    $("start-btn").disabled = !live || running || !controllable || !entry.can_start;
    $("preempt-btn").hidden = this.viewer;
    $("start-btn").hidden = this.viewer;
    const hold = $("hold-btn");
    hold.hidden = this.viewer || !entry?.can_hold;
    hold.disabled = !live || !running || !controllable || entry.held;
    const loop = $("loop-state");
    loop.hidden = !entry?.held;
    setText(loop, heldText(running));
  }

  /** The menu item "Set as initial state…" for the state at `path`. */
  initialStateItem(path) {
    const nodes = this.store.state.nodes;
    const node = nodes.get(path);
    const container = parentPath(path);
    const parent = container ? nodes.get(container) : null;
    const refusal = this.refusal();
    const kind = parent ? containerKind(parent) : null;
    const takesInitial = kind === "StateMachine" || kind === "Sequence";
    return {
      label: "Set as initial state…",
      disabled: !node || !parent || !takesInitial || Boolean(refusal),
      title: !parent ? "the root has no parent container" : !takesInitial ? `a ${kind} has no initial state to choose` : refusal,
      action: () => this._setInitial(container, node.label),
    };
  }

  async _setInitial(container, state) {
    const name = this.store.state.name;
    const ok = await editInitialState({
      container, state, userdata: this.store.state.live.containers[container]?.userdata || {},
      submit: (value) => api.setInitialState(name, container, [state], value),
    });
    if (ok) this._say(name, `Initial state of ${container} set to ${state} (next run)`, "ok");
  }

  async _preempt() {
    const name = this.store.state.name;
    const answer = await confirmPreempt(name);
    if (!answer) return;
    this.notices.preemptSent();
    try {
      const ack = await api.preempt(name, answer.reason);
      if (name === this.store.state.name) this.notices.preemptAccepted(ack.seq);
    } catch (err) {
      if (name === this.store.state.name) this.notices.preemptFailed(err);
    }
  }

  /** Ask the server for `what` by `call(name)` (the debugger's controls too); a notice says how it
   * answered: the event the control caused, or the server's refusal (a 409 says why). */
  async ask(what, call, then = "") {
    const name = this.store.state.name;
    try {
      const ack = await call(name);
      const event = ack.seq === undefined ? "" : ` (event ${ack.seq})`;
      this._say(name, `${what} accepted${event}${then}`, "ok");
    } catch (err) {
      this._say(name, `${what} failed: ` + (err.detail || err.message), "error", true);
    }
  }

  /** A notice about machine `name`, dropped when the page has moved to another machine meanwhile. */
  _say(name, text, level, sticky) {
    if (name === this.store.state.name) this.store.say(text, level, sticky);
  }
}
