// The side panel's tree of the hierarchy.
// Every name, value and message goes in as text (createElement + textContent), never as HTML.

import { h } from "./dom.js";

/** The tree of the hierarchy; rows are built once per structure, status only toggles classes. */
export class TreeView {
  constructor(host, handlers) {
    this.host = host;
    this.handlers = handlers;
    this.rows = new Map(); // path -> row element
    this.collapsed = new Set();
    this.selected = null;
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
    this.revealed = null;
    if (!structure) {
      this.host.replaceChildren(h("p", { class: "empty", text: "No structure yet." }));
      return;
    }
    const ul = h("ul", { class: "tree", role: "tree" });
    ul.append(this._node(structure, 0));
    this.host.replaceChildren(ul);
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
    const failedSet = new Set(failed);
    const breakpoints = new Set(marks.breakpoints);
    const held = new Set(marks.held);
    for (const [path, row] of this.rows) {
      row.classList.toggle("active", active.has(path));
      row.classList.toggle("failed", failedSet.has(path));
      row.classList.toggle("breakpoint", breakpoints.has(path));
      row.classList.toggle("held", held.has(path));
      const entry = status.containers[path];
      const out = row.lastElementChild;
      const text = entry && !entry.running && entry.outcome ? "→ " + entry.outcome : "";
      if (out.textContent !== text) out.textContent = text;
    }
  }

  /** Scroll the row of `path` into the middle of the tree when it is out of view (Follow active);
   * a collapsed branch stays collapsed. */
  reveal(path) {
    if (path === this.revealed) return;
    this.revealed = path;
    const row = this.rows.get(path);
    if (!row || !row.offsetParent) return;
    const box = row.getBoundingClientRect();
    const view = this.host.getBoundingClientRect();
    if (box.top >= view.top && box.bottom <= view.bottom) return;
    this.host.scrollTop += box.top - view.top - (view.height - box.height) / 2;
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
