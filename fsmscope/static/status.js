// The state of one machine rebuilt from its events: a line-for-line mirror of fsm/observation/status.py,
// so that the browser, the recorder and replay cannot disagree.

/** @typedef {import("./schema.js").MachineStatus} MachineStatus */
/** @typedef {import("./schema.js").ContainerStatus} ContainerStatus */

const REDUCED = new Set(["start", "transition", "userdata", "terminate", "error"]);

/** @returns {ContainerStatus} */
function containerEntry(initial) {
  return {
    active: [], initial: [...(initial || [])], userdata: {}, running: false, outcome: null,
    last: null, changes: {}, written: false,
  };
}

/** Keys of the container's userdata were written (a userdata event, or the `changes` a transition or
 * terminate carries, applied before it): the values, and what its next transition changed. */
function write(entry, written) {
  const userdata = entry.userdata;
  if (!entry.written) {
    entry.changes = {};
    entry.written = true;
  }
  for (const [key, value] of Object.entries(written)) {
    let change = entry.changes[key];
    if (change === undefined) change = entry.changes[key] = Object.hasOwn(userdata, key) ? { old: userdata[key] } : {};
    change.new = value;
  }
  Object.assign(userdata, written);
}

/** The container left a state: its last transition is `last`, and the keys written since the
 * previous one are what this one changed (none when nothing was written). */
function settle(entry, last) {
  if (!entry.written) entry.changes = {};
  entry.written = false;
  entry.last = last;
}

/** The path of the container holding `path` (null for the root). */
export function parentPath(path) {
  const i = path.lastIndexOf("/");
  return i > 0 ? path.slice(0, i) : null;
}

/** Every container node of a structure tree, parents first. */
export function* containers(node) {
  if (node && node.container) {
    yield node;
    for (const child of node.children || []) yield* containers(child);
  }
}

/** Every node (containers and leaves) of a structure tree, parents first. */
export function* allNodes(node) {
  if (!node) return;
  yield node;
  for (const child of node.children || []) yield* allNodes(child);
}

export class Status {
  constructor(machine) {
    this.machine = machine;
    this.run = null;
    this.root_path = null;
    this.structure = null;
    this.containers = {};
    this.running = false;
    this.outcome = null;
    this.error = null;
    this.last_seq = 0;
    this.last_t = null;
    this.run_seq = 0; // the seq of the current run's first event: where its history starts
    // A preempt requested and not over yet: {seq, t, path, serviced: [paths that serviced it]}.
    this.preempt = null;
    this.pose = null; // the last pose event's {seq, t, joints, bodies}
    this.debug = null; // the debugger's {mode, level, holds, breakpoints}, from its events
  }

  apply(event) {
    const kind = event.kind;
    const path = event.path;
    this.last_seq = event.seq;
    this.last_t = event.t === undefined ? null : event.t;
    const run = "run" in event ? event.run : this.run;
    if (run !== this.run) {
      this.run = run;
      this.run_seq = event.seq;
    }
    if (kind === "snapshot") {
      this._load(event.status);
      return;
    }
    if (kind === "structure") {
      this._setStructure(path, event.root);
      return;
    }
    if (kind === "preempt") {
      this._preempt(event);
      return;
    }
    if (kind === "pose") {
      this.pose = { seq: event.seq, t: event.t, joints: event.joints, bodies: event.bodies || {} };
      return;
    }
    if (kind === "debug") {
      this._debug(event);
      return;
    }
    if (!REDUCED.has(kind)) return;
    let entry = this.containers[path];
    if (entry === undefined) entry = this.containers[path] = containerEntry();
    const root = path === this.root_path;
    if (kind === "start") {
      if (root) { // a new run: what the previous one reached no longer describes the machine
        this.running = true;
        this.outcome = null;
        this.error = null;
        this.preempt = null;
        if (this.debug !== null) this.debug.holds = []; // a run never starts holding
        for (const other of Object.values(this.containers)) {
          Object.assign(other, { active: [], running: false, outcome: null, last: null, changes: {}, written: false });
        }
      }
      Object.assign(entry, {
        active: [...event.active], initial: [...event.initial],
        userdata: { ...event.userdata }, running: true, outcome: null, last: null, changes: {}, written: false,
      });
    } else if (kind === "transition") {
      if (event.changes != null) write(entry, event.changes); // the keys its step wrote
      entry.active = [...event.active];
      settle(entry, { from: event.from, outcome: event.outcome, to: event.to, seq: event.seq });
    } else if (kind === "userdata") {
      if (event.changes != null) write(entry, event.changes);
    } else if (kind === "terminate") {
      if (event.changes != null) write(entry, event.changes);
      const last = event.last;
      const stateOutcome = event.state_outcome;
      settle(entry, last.length === 1 && stateOutcome
        ? { from: last[0], outcome: stateOutcome, to: event.outcome, seq: event.seq } : entry.last);
      Object.assign(entry, { active: [], running: false, outcome: event.outcome });
      if (root) {
        this.running = false;
        this.outcome = event.outcome;
        this.preempt = null;
        if (event.error && this.error === null) this.error = { path, message: event.error };
      }
    } else if (kind === "error") {
      this.error = {};
      for (const k of ["path", "state", "exc_type", "message", "traceback"]) {
        this.error[k] = event[k] === undefined ? null : event[k];
      }
    }
  }

  _preempt(event) {
    if (event.phase === "requested") {
      if (this.preempt === null && this.running) {
        this.preempt = { seq: event.seq, t: event.t, path: event.path, serviced: [] };
      }
    } else if (this.preempt !== null) {
      this.preempt.serviced.push(event.path);
    }
  }

  /** Mode, holds and breakpoints as the debugger's events say (fsm/observation/status.py's _debug). */
  _debug(event) {
    if (this.debug === null) this.debug = { mode: "run", level: null, holds: [], breakpoints: [] };
    const debug = this.debug;
    if (event.action === "mode") {
      debug.mode = event.mode;
      debug.level = event.level ?? null;
    } else if (event.action === "breakpoints") {
      debug.breakpoints = event.breakpoints;
    } else if (event.action === "hold") {
      debug.mode = "pause";
      debug.level = null;
      debug.holds = [...debug.holds, {
        path: event.path, state: event.state, at: event.at, outcome: event.outcome ?? null,
        reason: event.reason, detail: event.detail, seq: event.seq,
      }];
    } else if (event.action === "release") {
      const held = debug.holds.find((h) => h.path === event.path && h.state === event.state);
      if (held) debug.holds = debug.holds.filter((h) => h !== held);
    }
  }

  /** The active states that have not serviced the pending preempt (none when there is none). */
  preemptWaitingOn() {
    if (this.preempt === null) return [];
    const serviced = new Set(this.preempt.serviced);
    return this.activeLeaves().filter((path) => !serviced.has(path));
  }

  /** The full paths of the active states that are not containers themselves. */
  activeLeaves() {
    return this.activePaths().filter((path) => !Object.hasOwn(this.containers, path));
  }

  _setStructure(path, root) {
    this.root_path = path;
    this.structure = root;
    const previous = this.containers;
    this.containers = {};
    for (const node of containers(root)) {
      const entry = previous[node.path] || containerEntry();
      entry.initial = [...(node.initial || [])];
      this.containers[node.path] = entry;
    }
  }

  /** Every active state's full path, at every level. */
  activePaths() {
    const out = [];
    for (const [p, c] of Object.entries(this.containers)) {
      for (const label of c.active) if (label !== "None") out.push(p + "/" + label);
    }
    return out;
  }

  /** @returns {MachineStatus} the schema's status (tests/browser/test_browser_dashboard.py: the same as Python's) */
  toDict() {
    return {
      machine: this.machine, run: this.run, root_path: this.root_path, structure: this.structure,
      containers: structuredClone(this.containers), running: this.running, outcome: this.outcome,
      error: this.error, last_seq: this.last_seq, last_t: this.last_t, run_seq: this.run_seq,
      preempt: structuredClone(this.preempt), pose: this.pose, debug: structuredClone(this.debug),
    };
  }

  _load(data) {
    this.run = data.run ?? null;
    this.root_path = data.root_path ?? null;
    this.structure = data.structure ?? null;
    this.containers = structuredClone(data.containers || {});
    this.running = Boolean(data.running);
    this.outcome = data.outcome ?? null;
    this.error = data.error ?? null;
    this.last_seq = data.last_seq ?? this.last_seq;
    this.last_t = data.last_t ?? this.last_t;
    this.run_seq = data.run_seq ?? 0;
    this.preempt = structuredClone(data.preempt ?? null);
    this.pose = data.pose ?? null;
    this.debug = structuredClone(data.debug ?? null);
    for (const entry of Object.values(this.containers)) { // a snapshot of an older fsmscope lacks these
      entry.last ??= null;
      entry.changes ??= {};
      entry.written ??= false;
    }
  }

  static fromDict(data) {
    const status = new Status(data.machine);
    status._load(data);
    return status;
  }
}
