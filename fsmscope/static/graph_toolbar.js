// The graph's toolbar and keys (graph.js): Fit (f), zoom in (+) and out (-), labels readable (r), and
// Follow, which keeps the active state in view until the user moves the view elsewhere.

const $ = (id) => document.getElementById(id);

export class GraphToolbar {
  /**
   * @param {import("./graph.js").GraphView} graph
   * @param {() => void} followChanged told when the user turns Follow on or off
   */
  constructor(graph, followChanged) {
    this.graph = graph;
    this.follow = $("follow");
    $("fit").addEventListener("click", () => graph.fit());
    $("zoom-in").addEventListener("click", () => graph.zoomStep(1));
    $("zoom-out").addEventListener("click", () => graph.zoomStep(-1));
    $("zoom-readable").addEventListener("click", () => graph.zoomReadable());
    this.follow.addEventListener("change", () => {
      graph.follow = this.follow.checked;
      followChanged();
    });
    document.addEventListener("keydown", (e) => {
      if (e.target.closest("input, textarea, select, dialog")) return;
      if (e.key === "f") graph.fit();
      else if (e.key === "+" || e.key === "=") graph.zoomStep(1);
      else if (e.key === "-") graph.zoomStep(-1);
      else if (e.key === "r") graph.zoomReadable();
    });
  }

  /** The user looks elsewhere than the active state: Follow stops. */
  stopFollowing() {
    this.follow.checked = false;
    this.graph.follow = false;
  }
}
