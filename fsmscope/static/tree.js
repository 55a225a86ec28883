// The side panel's tree of the hierarchy.
// Every name, value and message goes in as text (createElement + textContent), never as HTML.

import { h, markExactly, setText } from "./dom.js";

/** The tree of the hierarchy; rows are built once per structure, status only toggles classes, on the
 * rows whose marks change (per frame the work is O(active states), never O(states)). */
export class TreeView {
  constructor(host, handlers) {
    this.host = host;
    this.handlers = handlers;
    this.rows = new Map(); // path -> row element
    this.collapsed = new Set();
    this.selected = null;
    this.marked = new Map(); // class -> the paths whose rows have it
    this.outcomes = new Map(); // container path -> the outcome its row shows
    this.revealed = null; // the path last revealed, and its row while it is watched
    this.revealedRow = null;
    // Where the row to reveal is, read when the browser has laid it out anyway (asking at once would
    // force a layout of the page in every frame that follows a new active state).
    this.watcher = new IntersectionObserver((entries) => this._scrollTo(entries), { root: host, threshold: 1 });
    host.addEventListener("click", (e) => {
      const row = e.target.closest(".tree-row");
      if (!row) return;
      const path = row.dataset.path;
      if (e.target.closest(".twisty")) {
        this.toggle(path);
        return;
      }
      this.handlers.select(path);
    });
    host.addEventListener("contextmenu", (e) => {
      const row = e.target.closest(".tree-row");
      if (!row) return;
      e.preventDefault();
      this.handlers.contextmenu(row.dataset.path, e.clientX, e.clientY);
    });
  }

  build(structure) {
    this.rows.clear();
    this.marked = new Map();
    this.outcomes = new Map();
    this.watcher.disconnect();
    this.revealed = null;
    this.revealedRow = null;
    if (!structure) {
      this.host.replaceChildren(h("p", { class: "empty", text: "No structure yet." }));
      return;
    }
    const ul = h("ul", { class: "tree", role: "tree" });
    ul.append(this._node(structure, 0));
    this.host.replaceChildren(ul);
    if (this.selected) this.rows.get(this.selected)?.classList.add("selected");
  }

  _node(node, depth) {
    const isContainer = Boolean(node.container);
    const row = h("div", { class: "tree-row" + (isContainer ? " container" : ""), "data-path": node.path, title: node.path },
      h("span", { class: "twisty", text: isContainer && node.children?.length ? "▾" : "" }),
      h("span", { class: "dot" }),
      h("span", { class: "label", text: node.label }),
      h("span", { class: "type", text: node.type }),
      h("span", { class: "outcome" }));
    row.style.paddingLeft = `${4 + depth * 14}px`;
    this.rows.set(node.path, row);
    const li = h("li", { role: "treeitem" }, row);
    if (isContainer && node.children?.length) {
      const ul = h("ul", { role: "group" });
      for (const child of node.children) ul.append(this._node(child, depth + 1));
      li.append(ul);
      if (this.collapsed.has(node.path)) li.classList.add("collapsed");
    }
    return li;
  }

  toggle(path) {
    const row = this.rows.get(path);
    if (!row) return;
    const li = row.parentElement;
    li.classList.toggle("collapsed");
    if (li.classList.contains("collapsed")) this.collapsed.add(path);
    else this.collapsed.delete(path);
  }

  /**
   * @param {string[]} failed the failing state and the containers it brought down
   * @param {{breakpoints: string[], held: string[]}} marks the states with a breakpoint, where the machine holds
   */
  update(status, failed, marks) {
    const active = new Set(status.activePaths());
    if (status.running && status.root_path) active.add(status.root_path);
    const find = (path) => this.rows.get(path);
    for (const [cls, paths] of [["active", active], ["failed", new Set(failed)],
      ["breakpoint", new Set(marks.breakpoints)], ["held", new Set(marks.held)]]) {
      this.marked.set(cls, markExactly(cls, this.marked.get(cls) || new Set(), paths, find));
    }
    const outcomes = new Map();
    for (const [path, entry] of Object.entries(status.containers)) {
      if (!entry.running && entry.outcome) outcomes.set(path, "→ " + entry.outcome);
    }
    for (const path of new Set([...this.outcomes.keys(), ...outcomes.keys()])) {
      const out = this.rows.get(path)?.lastElementChild;
      const text = outcomes.get(path) ?? "";
      if (out) setText(out, text);
    }
    this.outcomes = outcomes;
  }

  /** Scroll the row of `path` into the middle of the tree when it is out of view (Follow active),
   * once, when the browser next lays it out; a collapsed branch stays collapsed. */
  reveal(path) {
    if (path === this.revealed) return;
    this.revealed = path;
    if (this.revealedRow) this.watcher.unobserve(this.revealedRow);
    this.revealedRow = this.rows.get(path) ?? null;
    if (this.revealedRow) this.watcher.observe(this.revealedRow);
  }

  _scrollTo(entries) {
    for (const { target, boundingClientRect: box, rootBounds: view, intersectionRatio } of entries) {
      if (target !== this.revealedRow) continue;
      this.watcher.unobserve(target); // revealed once: the user may scroll away from it
      this.revealedRow = null;
      // A row in a collapsed branch has no box; one wholly in view needs no scroll.
      if (!box.height || !view || intersectionRatio >= 1) continue;
      this.host.scrollTop += box.top - view.top - (view.height - box.height) / 2;
    }
  }

  select(path) {
    if (this.selected) this.rows.get(this.selected)?.classList.remove("selected");
    this.selected = path;
    const row = path ? this.rows.get(path) : null;
    if (!row) return;
    row.classList.add("selected");
    for (let li = row.parentElement.parentElement?.closest("li"); li; li = li.parentElement?.closest("li")) {
      if (li.classList.contains("collapsed")) {
        li.classList.remove("collapsed");
        this.collapsed.delete(li.firstElementChild.dataset.path);
      }
    }
    row.scrollIntoView({ block: "nearest" });
  }
}
