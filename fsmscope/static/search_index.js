// The search palette's index and matching, pure (no DOM): built once per structure, so a keystroke
// only scans flat arrays of lower-cased names (a 2,000-state machine answers in a few ms; a browser
// test times it). Userdata keys come from the status and are indexed again only when they change.

import { allNodes } from "./status.js";

export const MAX_RESULTS = 50;

// Ranks, best first: the name is the query, starts with it, holds it; the path holds it; the path
// holds its characters in order (fuzzy).
const EXACT = 0;
const PREFIX = 1;
const NAME = 2;
const PATH = 3;
const FUZZY = 4;

/** @typedef {{kind: "state"|"container"|"key"|"outcome", name: string, path: string, type?: string}} Entry
 *  `path`: the state or container it stands for (a key's: its container; an outcome's: its state). */

/** Whether the characters of `query` appear in `text` in order. */
function subsequence(query, text) {
  let i = 0;
  for (let j = 0; j < text.length && i < query.length; j++) if (text[j] === query[i]) i++;
  return i === query.length;
}

/** How well `entry` (its lower-cased name and path) matches `q` (lower-cased), or -1. */
function rank(q, name, path) {
  if (name === q) return EXACT;
  const at = name.indexOf(q);
  if (at === 0) return PREFIX;
  if (at > 0) return NAME;
  if (path.includes(q)) return PATH;
  return subsequence(q, path) ? FUZZY : -1;
}

export class SearchIndex {
  /** @param {object|null} root the structure's root node */
  constructor(root) {
    this.entries = []; // Entry, states, containers and outcomes then keys
    this.names = []; // lower-cased, parallel to entries
    this.paths = [];
    for (const node of allNodes(root)) {
      this._add({ kind: node.container ? "container" : "state", name: node.label, path: node.path, type: node.type });
      for (const outcome of node.outcomes || []) this._add({ kind: "outcome", name: outcome, path: node.path });
    }
    this.fixed = this.entries.length;
    this.keysKey = "";
  }

  _add(entry) {
    this.entries.push(entry);
    this.names.push(entry.name.toLowerCase());
    this.paths.push(entry.path.toLowerCase());
  }

  /** Index the userdata keys of `containers` (a status's {path: {userdata}}), unless they are those indexed. */
  setKeys(containers) {
    const keys = Object.entries(containers || {}).flatMap(([path, c]) => Object.keys(c.userdata || {}).map((k) => [path, k]));
    const key = JSON.stringify(keys);
    if (key === this.keysKey) return;
    this.keysKey = key;
    for (const list of [this.entries, this.names, this.paths]) list.length = this.fixed;
    for (const [path, name] of keys) this._add({ kind: "key", name, path });
  }

  /**
   * The entries matching `query` (case-insensitive), best first: exact name, prefix, substring of the
   * name, substring of the path, fuzzy subsequence of the path; within a rank, shorter paths first.
   * @returns {{results: Entry[], total: number}} at most `limit` results, and how many matched
   */
  search(query, limit = MAX_RESULTS) {
    const q = query.trim().toLowerCase();
    if (!q) return { results: [], total: 0 };
    const hits = [];
    const { names, paths } = this;
    for (let i = 0; i < names.length; i++) {
      const r = rank(q, names[i], paths[i]);
      if (r >= 0) hits.push([r, paths[i].length, i]);
    }
    hits.sort((a, b) => a[0] - b[0] || a[1] - b[1] || a[2] - b[2]);
    return { results: hits.slice(0, limit).map(([, , i]) => this.entries[i]), total: hits.length };
  }
}
