// Which containers the graph draws open: the depth selector (auto, 1..N, custom) and a double-click
// that opens or closes one container. "auto" is the server's default (every container open) when
// that default opens everything; when it does not (a big machine), semantic zoom (semantic_zoom.js).

import { h } from "./dom.js";
import { SemanticZoom } from "./semantic_zoom.js";
import { containers, parentPath } from "./status.js";

export class Depth {
  /**
   * @param {HTMLSelectElement} select the depth selector
   * @param {Store} store the page's store (store.js): the machine shown
   * @param {() => string[]} drawnOpen the containers the graph shown draws open
   * @param {(semantic: boolean) => Promise<unknown>} changed called when another set of containers is
   *   to be drawn open (`semantic`: by semantic zoom, as the machine moves); resolves when it is drawn
   * @param {boolean} anyOpenSet whether any set can be drawn (a server lays it out); else "auto" is the
   *   default drawing, no semantic zoom (an exported file holds the depth menu's drawings only)
   */
  constructor(select, store, drawnOpen, changed, anyOpenSet) {
    this.anyOpenSet = anyOpenSet;
    this.select = select;
    this.store = store;
    this.drawnOpen = drawnOpen;
    this.changed = changed;
    this.expand = null; // null: "auto"; else a Set of container paths drawn open
    // A re-layout semantic zoom had scheduled is dropped once the user has chosen what is open: it would
    // replace the drawing the user asked for (a search's choice) with one anchored elsewhere.
    this.semantic = new SemanticZoom(() => (this.expand ? Promise.resolve() : changed(true)));
    this.semanticOn = false; // "auto" is semantic zoom: the server's default left containers closed
    select.addEventListener("change", () => this._chosen(select.value));
  }

  /** The containers to draw open, sorted; null: the server's default. */
  paths() {
    if (this.expand) return [...this.expand].sort();
    return this.semanticOn ? this.semantic.paths() : null;
  }

  /** Another machine is shown: back to the server's default. */
  reset() {
    this.expand = null;
    this.semanticOn = false;
    this.semantic.reset(null);
  }

  /** A drawing is in: under "auto", one that leaves containers closed turns semantic zoom on. */
  laidOut() {
    if (!this.anyOpenSet || this.expand || this.semanticOn || !this.store.state.live.structure) return;
    const all = [...containers(this.store.state.live.structure)].length;
    if (this.drawnOpen().length >= all) return;
    this.semanticOn = true;
    this.semantic.reset(this.store.state.live.root_path);
  }

  /** The instant shown (its running containers, the selection): semantic zoom follows it. */
  show(running, selected) {
    if (this.semanticOn && !this.expand) this.semantic.show(running, selected);
  }

  /** A new structure: forget the containers it no longer has, offer one depth per level of them. */
  restructured() {
    const nodes = this.store.state.nodes;
    this.semanticOn = false;
    this.semantic.reset(null);
    if (this.expand) this.expand = new Set([...this.expand].filter((p) => nodes.has(p)));
    const max = [...containers(this.store.state.live.structure)].reduce((m, n) => Math.max(m, this._depthOf(n.path) + 1), 1);
    const current = this.select.value;
    const values = ["auto", ...Array.from({ length: max }, (_, i) => String(i + 1)), "custom"];
    this.select.replaceChildren(...values.map((value) => h("option", { value, text: value, hidden: value === "custom" })));
    this.select.value = values.includes(current) ? current : "auto";
  }

  /** Draw open every container on the way to `path` (a search's choice, to be shown); resolves when it
   * is drawn, at once when they are drawn open already. */
  reveal(path) {
    const open = new Set(this.drawnOpen());
    const needed = [];
    for (let p = parentPath(path); p; p = parentPath(p)) if (!open.has(p) && this.store.state.nodes.has(p)) needed.push(p);
    if (!needed.length) return Promise.resolve();
    if (!this.expand) this.expand = new Set([...open, this.store.state.live.root_path]);
    for (const p of needed) this.expand.add(p);
    this.select.value = "custom";
    return Promise.resolve(this.changed(false));
  }

  /** Open the container at `path` or close it (`isCluster`: it is drawn open). */
  toggle(path, isCluster) {
    const root = this.store.state.live.root_path;
    const node = this.store.state.nodes.get(path);
    if (!node || !node.container || path === root) return;
    if (!this.expand) {
      // From the server's default: open what it opened.
      this.expand = new Set(this.drawnOpen());
      this.expand.add(root);
    }
    if (isCluster || this.expand.has(path)) {
      for (const p of [...this.expand]) if (p === path || p.startsWith(path + "/")) this.expand.delete(p);
    } else {
      for (let p = path; p; p = parentPath(p)) this.expand.add(p);
    }
    this.select.value = "custom";
    this.changed(false);
  }

  _chosen(value) {
    if (value === "auto") {
      this.expand = null;
      if (this.semanticOn) this.semantic.reset(this.store.state.live.root_path);
    } else if (value !== "custom") {
      const d = Number(value);
      this.expand = new Set([...containers(this.store.state.live.structure)].map((n) => n.path).filter((p) => this._depthOf(p) < d));
    }
    this.changed(false);
  }

  _depthOf(path) {
    const root = this.store.state.live.root_path || "";
    return path === root ? 0 : path.slice(root.length).split("/").length - 1;
  }
}
