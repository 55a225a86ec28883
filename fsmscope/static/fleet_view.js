// What the fleet overview shows of its tiles (server/overview.py): which ones, in which order, and
// how each says when it was last seen. Pure functions of the tiles and the page's choices.

import { TILE_STATES } from "./schema.js";

/** @typedef {import("./schema.js").Tile} Tile */

/** The states a tile can be in, in the order "by state" sorts them (what needs a look first). */
export const STATES = TILE_STATES;

const SORTS = {
  robot: (a, b) => compareText(a.robot ?? "", b.robot ?? "") || compareText(a.machine, b.machine),
  machine: (a, b) => compareText(a.machine, b.machine) || compareText(a.robot ?? "", b.robot ?? ""),
  state: (a, b) => STATES.indexOf(a.state) - STATES.indexOf(b.state) || SORTS.robot(a, b),
  seen: (a, b) => (b.last_seen ?? -Infinity) - (a.last_seen ?? -Infinity) || SORTS.robot(a, b),
  rate: (a, b) => b.rate - a.rate || SORTS.robot(a, b),
};

function compareText(a, b) {
  return a.localeCompare(b, undefined, { numeric: true });
}

/**
 * The tiles to show: those in `state` ("" for all) whose robot, machine or active state contains
 * `text` (case-insensitive), sorted by `sort` (robot, machine, state, seen, rate).
 * @param {Tile[]} tiles
 * @returns {Tile[]}
 */
export function visibleTiles(tiles, { text = "", state = "", sort = "robot" } = {}) {
  const needle = text.trim().toLowerCase();
  const shown = tiles.filter((t) => (!state || t.state === state)
    && (!needle || [t.robot ?? "", t.machine, ...t.active].some((s) => s.toLowerCase().includes(needle))));
  return shown.sort(SORTS[sort] || SORTS.robot);
}

/** How many tiles are in each state. @param {Tile[]} tiles */
export function countStates(tiles) {
  const counts = Object.fromEntries(STATES.map((s) => [s, 0]));
  for (const t of tiles) counts[t.state] += 1;
  return counts;
}

/** "just now", "12 s ago", "3 min ago", "2 h ago", or "never", for a tile last seen `age` seconds ago. */
export function agoText(age) {
  if (age === null || age === undefined) return "never";
  if (age < 2) return "just now";
  if (age < 120) return `${Math.floor(age)} s ago`;
  if (age < 7200) return `${Math.floor(age / 60)} min ago`;
  return `${Math.floor(age / 3600)} h ago`;
}

/** A state path as a tile shows it: without the root's name, which every path of the machine shares. */
export function shortPath(path) {
  const parts = path.split("/").filter(Boolean);
  return parts.length > 1 ? parts.slice(1).join(" / ") : parts.join("");
}
