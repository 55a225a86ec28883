// The machine the page shows (its status, structure nodes, selection) and view(), a pure function
// from a status to what the graph and the tree show.

import { Status, allNodes, parentPath } from "./status.js";
import { edgeId, outcomeId } from "./schema.js";

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

/** What the graph shows of `status` (a Status): active states, running containers, the outcome ids
 * reached, each container's last edge id, the failed paths. */
export function view(status) {
  const entries = Object.entries(status.containers);
  return {
    active: status.activePaths(),
    running: entries.filter(([, c]) => c.running).map(([p]) => p),
    reached: entries.filter(([, c]) => !c.running && c.outcome !== null && c.outcome !== undefined)
      .map(([p, c]) => outcomeId(p, c.outcome)),
    lastEdges: entries.filter(([, c]) => c.last).map(([p, c]) => edgeId(p, c.last.from, c.last.outcome)),
    failed: failedPaths(status),
  };
}

/** The machine shown: its name, status, structure nodes by path and selected path. */
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
  }

  /** A snapshot: the status it carries replaces ours. */
  load(status) {
    this.status = Status.fromDict({ machine: this.name, ...status });
  }

  apply(ev) {
    this.status.apply(ev);
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
