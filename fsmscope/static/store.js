// The page's one store: what the dashboard knows of the machine shown and of its server is
// `store.state`, and every change goes through one of the store's methods, which tells the
// subscribers which part changed. The parts: the machine shown (its name, its live status as its
// stream says, the structure's nodes, the selection), the instant looked at (timetravel.js moves
// it), the served machines (machines.js polls them), the stream's connection, this page's role and
// who holds the lease (lease.js), the notice line and the banner. The views draw from the state
// (app.js wires which draws on what change) and keep only what they draw (the log's rows, the
// timeline's bands); nothing is read back from the page's elements.

import { Status, allNodes } from "./status.js";

const NOTICE_MS = 8000; // a notice that is not sticky goes after this long

/** The instant of a machine not looked back at: the page draws the stream's present. */
export const presentOf = (replay) => ({ past: false, status: null, window: null, playing: false, replay });

export class Store {
  constructor() {
    this.listeners = new Set();
    this.noticeTimer = null;
    this.state = {
      name: null, // the machine shown
      live: null, // its Status as its stream says (null: no machine shown)
      nodes: new Map(), // its structure's nodes by path
      structureKey: null, // the structure they index (its JSON)
      selected: null, // the path selected
      // The instant looked at: past (else the live status is drawn), its Status and the log's events
      // around it ({events, seq}) when past, whether it plays, whether the machine is a replay.
      instant: presentOf(false),
      // /api/machines, whether the server answers, and {seq, error} by name of the other machines
      // that ended without an outcome
      machines: { list: [], online: true, endings: new Map() },
      connection: "idle", // the state of the stream of the machine shown (stream.js)
      role: "operator", // "viewer": this page may watch, not control
      lease: null, // who holds the lease of the machine shown ({holder, yours, deadman}; null: unknown)
      notice: { text: "", level: "" },
      banner: "",
    };
  }

  /** Call `listener(state, part)` after each change; `part` names what changed: "machine" (another
   * machine shown), "live", "structure", "selection", "instant", "machines", "connection", "role",
   * "lease", "notice" (the notice line or the banner). Returns the function that unsubscribes it. */
  subscribe(listener) {
    this.listeners.add(listener);
    return () => this.listeners.delete(listener);
  }

  _changed(part) {
    for (const listener of this.listeners) listener(this.state, part);
  }

  /** The /api/machines entry of the machine shown, or null. */
  current() {
    const { name, machines } = this.state;
    return machines.list.find((m) => m.name === name) || null;
  }

  // ---------------------------------------------------------------- the machine shown

  /** Show machine `name` from nothing (its stream has said nothing yet, nor its playhead, nor its lease). */
  open(name) {
    Object.assign(this.state, {
      name, live: name === null ? null : new Status(name), nodes: new Map(), structureKey: null, selected: null,
      instant: presentOf(false), connection: "idle", lease: null,
    });
    this._changed("machine");
  }

  /** A snapshot: the status it carries replaces the live one. */
  load(status) {
    this.state.live = Status.fromDict({ machine: this.state.name, ...status });
    this._restructure();
    this._changed("live");
  }

  /** Events of the stream, applied to the live status in order ("structure" told at once when one
   * changes the structure). */
  apply(events) {
    for (const ev of events) {
      this.state.live.apply(ev);
      if (ev.kind === "structure") this._restructure();
    }
    this._changed("live");
  }

  /** When the structure is another than the one indexed so far, index its nodes and say so. */
  _restructure() {
    const root = this.state.live.structure;
    const key = root ? JSON.stringify(root) : null;
    if (key === this.state.structureKey) return;
    this.state.structureKey = key;
    this.state.nodes = new Map([...allNodes(root)].map((node) => [node.path, node]));
    this._changed("structure");
  }

  select(path) {
    this.state.selected = path || null;
    this._changed("selection");
  }

  /** The instant looked at changed (timetravel.js): `instant` has the fields that changed. */
  setInstant(instant) {
    this.state.instant = { ...this.state.instant, ...instant };
    this._changed("instant");
  }

  setConnection(connection) {
    this.state.connection = connection;
    this._changed("connection");
  }

  // ---------------------------------------------------------------- the server and this page's rights

  /** An answer of /api/machines (`list`), or none (`online` false). */
  setMachines(list, online) {
    if (list) this.state.machines.list = list;
    this.state.machines.online = online;
    this._changed("machines");
  }

  /** How machine `name`, one of the others, ended: `ending` {seq, error} (error null: not known yet,
   * or none); null: to be asked again. */
  setEnding(name, ending) {
    if (ending) this.state.machines.endings.set(name, ending);
    else this.state.machines.endings.delete(name);
    this._changed("machines");
  }

  /** Whether the loop of the machine shown is held (its stream said so before the next poll). */
  setHeld(held) {
    const entry = this.current();
    if (!entry) return;
    entry.held = held;
    this._changed("machines");
  }

  setRole(role) {
    this.state.role = role;
    this._changed("role");
  }

  setLease(lease) {
    this.state.lease = lease;
    this._changed("lease");
  }

  // ---------------------------------------------------------------- what the page says

  /** Say `text` (level info, ok, warn or error); a notice that is not `sticky` goes after NOTICE_MS. */
  say(text, level = "info", sticky = false) {
    clearTimeout(this.noticeTimer);
    this.state.notice = { text, level };
    if (!sticky) this.noticeTimer = setTimeout(() => this.clearNotice(), NOTICE_MS);
    this._changed("notice");
  }

  clearNotice() {
    clearTimeout(this.noticeTimer);
    this.state.notice = { text: "", level: "" };
    this._changed("notice");
  }

  /** The line above the page (empty `text`: none). */
  setBanner(text) {
    this.state.banner = text || "";
    this._changed("notice");
  }
}
