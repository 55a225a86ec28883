// Where the graph pane is: the breadcrumb of the container in view (the active state's container
// while following, else the deepest open container whose frame holds the view's centre), each crumb
// fitting its container, and what the last fit shows when the whole graph would be unreadable. It
// follows the GraphView's events (graph.js), at most once per animation frame, and rebuilds its
// crumbs only when the container changes. The fit's note offers the whole graph, one click away.

import { h } from "./dom.js";
import { clusterAt } from "./graph_geometry.js";
import { parentPath } from "./status.js";

export class Breadcrumb {
  /**
   * @param {HTMLElement} host the breadcrumb's bar
   * @param {HTMLElement} fitButton its title says what a fit shows
   * @param {import("./graph.js").GraphView} graph
   * @param {{label: (path: string) => string, fit: (path: string) => void, whole: () => void}} handlers
   *   a container's name; fit a container (a crumb was clicked); show the whole graph (the note's button)
   */
  constructor(host, fitButton, graph, handlers) {
    this.graph = graph;
    this.handlers = handlers;
    this.crumbs = host.appendChild(h("ol", { class: "crumbs", "aria-label": "Container in view" }));
    this.note = host.appendChild(h("span", { class: "fit-note", role: "status" }));
    this.whole = host.appendChild(h("button", { type: "button", class: "fit-whole", text: "whole graph",
      title: "Show the whole graph, however small its labels", hidden: true }));
    this.whole.addEventListener("click", () => handlers.whole());
    this.fitButton = fitButton;
    this.fitTitle = fitButton.title;
    this.shown = undefined; // the container path the crumbs name
    this.queued = false;
    for (const type of ["graph:view", "graph:focus", "graph:layout"]) graph.host.addEventListener(type, () => this._queue());
    graph.host.addEventListener("graph:fit", (e) => this._fitted(e.detail));
    this.crumbs.addEventListener("click", (e) => {
      const crumb = e.target.closest("button[data-path]");
      if (crumb) this.handlers.fit(crumb.dataset.path);
    });
  }

  _queue() {
    if (this.queued) return;
    this.queued = true;
    requestAnimationFrame(() => {
      this.queued = false;
      this._update();
    });
  }

  /** The container the view shows: the active state's while following, else the one at its centre. */
  container() {
    const g = this.graph;
    if (!g.vb) return null;
    if (g.follow && g.activePath) return parentPath(g.activePath) || g.activePath;
    return clusterAt(g.clusters, g.vb.x + g.vb.w / 2, g.vb.y + g.vb.h / 2)?.path ?? null;
  }

  _update() {
    const path = this.container();
    if (path === this.shown) return;
    this.shown = path;
    const chain = [];
    for (let p = path; p; p = parentPath(p)) chain.unshift(p);
    this.crumbs.replaceChildren(...chain.map((p) => h("li", {},
      h("button", { type: "button", "data-path": p, text: this.handlers.label(p), title: "Fit " + p }))));
  }

  /** What the fit shown shows ("": the whole graph, or the view is no fit): said beside the crumbs and
   * in the Fit button's title. */
  _fitted(note) {
    this.note.textContent = note;
    this.whole.hidden = !note;
    this.fitButton.title = note ? this.fitTitle + ". " + note : this.fitTitle;
  }
}
