// What the page shows of its state (store.js): the status of the instant looked at, and view(), a
// pure function from a status to what the graph and the tree show.

import { parentPath } from "./status.js";
import { edgeId, outcomeId } from "./schema.js";

/** The status of the instant shown: the playhead's when it looks back, else the stream's present. */
export function shownStatus(state) {
  return state.instant.past ? state.instant.status : state.live;
}

/** Whether the page shows the live machine: its stream live and not looking back (the debugger
 * controls only what it shows). */
export function showsLive(state) {
  return state.connection === "live" && !state.instant.past;
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
