// The machine the page shows (its status, structure nodes, run marks, selection) and view(), a pure
// function from its status and run marks to what the graph and the tree show.

import { Status, allNodes, parentPath } from "./status.js";
import { edgeId, outcomeId } from "./schema.js";

/** What the reducer does not keep but the page shows, for the current run only: each container's
 * last edge, and the keys its userdata events wrote since its previous transition. */
export class RunMarks {
  constructor() {
    this.forget();
  }

  forget() {
    this.lastEdge = new Map(); // container path -> the edge id of its last transition
    this.changed = new Map(); // container path -> Set of keys written by its last transition
    this.pending = new Map(); // container path -> Set of keys written since its last transition
  }

  /** Note event `ev` of a machine whose root is at `rootPath`. */
  apply(ev, rootPath) {
    const path = ev.path;
    if (ev.kind === "start") {
      if (path === rootPath) this.forget(); // a new run: the page shows this run only, as the reducer does
      this.pending.set(path, new Set());
      this.changed.set(path, new Set());
      this.lastEdge.delete(path);
    } else if (ev.kind === "userdata") {
      const pending = this.pending.get(path) || new Set();
      for (const key of Object.keys(ev.changes || {})) pending.add(key);
      this.pending.set(path, pending);
      this.changed.set(path, new Set(pending));
    } else if (ev.kind === "transition") {
      this._settle(path);
      this.lastEdge.set(path, edgeId(path, ev.from, ev.outcome));
    } else if (ev.kind === "terminate") {
      this._settle(path);
      const last = ev.last?.length === 1 ? ev.last[0] : null;
      if (last && ev.state_outcome) this.lastEdge.set(path, edgeId(path, last, ev.state_outcome));
    }
  }

  /** The container at `path` left a state: the keys written meanwhile are its last transition's. */
  _settle(path) {
    this.changed.set(path, this.pending.get(path) || new Set());
    this.pending.set(path, new Set());
  }
}

/** The failing state and the containers it brought down (they ended without an outcome). */
function failedPaths(status) {
  const error = status.error;
  if (!error || !error.path) return [];
  const failing = error.state ? error.path + "/" + error.state : error.path;
  const failed = [failing];
  for (let p = parentPath(failing); p; p = parentPath(p)) {
    const entry = status.containers[p];
    if (entry && !entry.running && entry.outcome === null) failed.push(p);
  }
  return failed;
}

/** What the graph shows of `status` (a Status) and `marks` (RunMarks): active states, running
 * containers, the outcome ids reached, the last edge ids, the failed paths. */
export function view(status, marks) {
  const entries = Object.entries(status.containers);
  return {
    active: status.activePaths(),
    running: entries.filter(([, c]) => c.running).map(([p]) => p),
    reached: entries.filter(([, c]) => !c.running && c.outcome !== null && c.outcome !== undefined)
      .map(([p, c]) => outcomeId(p, c.outcome)),
    lastEdges: [...marks.lastEdge.values()],
    failed: failedPaths(status),
  };
}

/** The machine shown: its name, status, structure nodes by path, run marks and selected path. */
export class Store {
  constructor() {
    this.open(null);
  }

  /** Show machine `name` from nothing (its stream has said nothing yet). */
  open(name) {
    this.name = name;
    this.status = name === null ? null : new Status(name);
    this.nodes = new Map();
    this.structureKey = null;
    this.selected = null;
    this.marks = new RunMarks();
  }

  /** A snapshot: the status it carries replaces ours; the marks of the run so far are not in it. */
  load(status) {
    this.status = Status.fromDict({ machine: this.name, ...status });
    this.marks.forget();
  }

  apply(ev) {
    this.status.apply(ev);
    this.marks.apply(ev, this.status.root_path);
  }

  /** Whether the structure is another than the one indexed so far; when it is, index its nodes. */
  restructured() {
    const root = this.status.structure;
    const key = root ? JSON.stringify(root) : null;
    if (key === this.structureKey) return false;
    this.structureKey = key;
    this.nodes = new Map();
    for (const node of allNodes(root)) this.nodes.set(node.path, node);
    return true;
  }
}
