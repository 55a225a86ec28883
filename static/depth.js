// Which containers the graph draws open: the depth selector (auto, 1..N, custom) and a double-click
// that opens or closes one container.

import { h } from "./dom.js";
import { containers, parentPath } from "./status.js";

export class Depth {
  /**
   * @param {HTMLSelectElement} select the depth selector
   * @param {Store} store the machine shown (store.js)
   * @param {() => string[]} drawnOpen the containers the graph shown draws open
   * @param {() => void} changed called when another set of containers is to be drawn open
   */
  constructor(select, store, drawnOpen, changed) {
    this.select = select;
    this.store = store;
    this.drawnOpen = drawnOpen;
    this.changed = changed;
    this.expand = null; // null: the server's default; else a Set of container paths drawn open
    select.addEventListener("change", () => this._chosen(select.value));
  }

  /** The containers to draw open, sorted; null: the server's default. */
  paths() {
    return this.expand ? [...this.expand].sort() : null;
  }

  /** Another machine is shown: back to the server's default. */
  reset() {
    this.expand = null;
  }

  /** A new structure: forget the containers it no longer has, offer one depth per level of them. */
  restructured() {
    const nodes = this.store.nodes;
    if (this.expand) this.expand = new Set([...this.expand].filter((p) => nodes.has(p)));
    const max = [...containers(this.store.status.structure)].reduce((m, n) => Math.max(m, this._depthOf(n.path) + 1), 1);
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
    for (let p = parentPath(path); p; p = parentPath(p)) if (!open.has(p) && this.store.nodes.has(p)) needed.push(p);
    if (!needed.length) return Promise.resolve();
    if (!this.expand) this.expand = new Set([...open, this.store.status.root_path]);
    for (const p of needed) this.expand.add(p);
    this.select.value = "custom";
    return Promise.resolve(this.changed(false));
  }

  /** Open the container at `path` or close it (`isCluster`: it is drawn open). */
  toggle(path, isCluster) {
    const root = this.store.status.root_path;
    const node = this.store.nodes.get(path);
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
    this.changed();
  }

  _chosen(value) {
    if (value === "auto") this.expand = null;
    else if (value !== "custom") {
      const d = Number(value);
      this.expand = new Set([...containers(this.store.status.structure)].map((n) => n.path).filter((p) => this._depthOf(p) < d));
    }
    this.changed();
  }

  _depthOf(path) {
    const root = this.store.status.root_path || "";
    return path === root ? 0 : path.slice(root.length).split("/").length - 1;
  }
}
