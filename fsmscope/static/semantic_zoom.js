// Semantic zoom: the containers drawn open follow the machine. The active path (every running
// container) and the selection's ancestors are open, idle branches closed; a container that goes idle
// stays open LINGER_MS more, so a machine that moves fast does not re-lay out at every event. A new
// open set is asked for at most once per MIN_GAP_MS, one layout in flight at a time; per frame the
// work is O(running containers), never O(states).

import { parentPath } from "./status.js";

const LINGER_MS = 2000;
const MIN_GAP_MS = 400;

export class SemanticZoom {
  /**
   * @param {() => Promise<unknown>} relayout draws the open set now asked for (`paths()`); resolves
   *   when the drawing is in
   */
  constructor(relayout) {
    this.relayout = relayout;
    this.reset(null);
  }

  /** A machine (rooted at `root`) from nothing: only the root open. */
  reset(root) {
    this.root = root;
    this.open = new Set(root ? [root] : []); // the set drawn, or being drawn
    this.seen = new Map(); // container path -> when it was last running or held open by the selection
    this.inFlight = false;
    this.lastLayout = -Infinity;
    clearTimeout(this.timer);
    this.timer = null;
    this.wanted = { running: [], selected: null };
  }

  /** The containers drawn open, sorted (for `?expand=`). */
  paths() {
    return [...this.open].sort();
  }

  /**
   * The instant shown: its running containers and the selected path (null: none).
   * @param {string[]} running
   * @param {string|null} selected
   */
  show(running, selected) {
    this.wanted = { running, selected };
    const now = performance.now();
    for (const path of running) this.seen.set(path, now);
    for (let p = selected && parentPath(selected); p; p = parentPath(p)) this.seen.set(p, now);
    this._settle(now);
  }

  /** The open set the instant asks for: the root, what ran or was selected in the last LINGER_MS. */
  _target(now) {
    const target = new Set([this.root]);
    for (const [path, at] of this.seen) {
      if (now - at < LINGER_MS) target.add(path);
      else this.seen.delete(path);
    }
    return target;
  }

  /** Ask for the target set when it differs from the drawn one and the pace allows; else come back
   * when it does (the end of a linger, of the gap, of the layout in flight). */
  _settle(now) {
    if (!this.root || this.inFlight) return;
    const target = this._target(now);
    const next = this._nextExpiry(now);
    clearTimeout(this.timer);
    this.timer = null;
    const same = target.size === this.open.size && [...target].every((p) => this.open.has(p));
    const wait = same ? next : Math.max(0, this.lastLayout + MIN_GAP_MS - now);
    if (!same && wait === 0) {
      this._layout(target);
      return;
    }
    if (Number.isFinite(wait)) this.timer = setTimeout(() => this._settle(performance.now()), wait + 1);
  }

  /** Milliseconds until the first drawn container's linger ends (Infinity: none will). */
  _nextExpiry(now) {
    let next = Infinity;
    for (const path of this.open) {
      const at = this.seen.get(path);
      if (at !== undefined) next = Math.min(next, at + LINGER_MS - now);
    }
    return Math.max(0, next);
  }

  async _layout(target) {
    const changed = [...target].filter((p) => !this.open.has(p)).length + [...this.open].filter((p) => !target.has(p)).length;
    const start = performance.now();
    this.open = target;
    this.inFlight = true;
    try {
      await this.relayout();
    } finally {
      this.inFlight = false;
      this.lastLayout = performance.now();
      // On the page's performance timeline (the browser's profiler shows it; bench/big_machine_browser.py reads it).
      performance.measure("fsmscope:relayout", { start, end: this.lastLayout, detail: { changed } });
      this._settle(this.lastLayout);
    }
  }
}
