// The drawing of the machine shown, each time its structure changes (store.js says "structure"): the
// server's layout of it with the containers depth.js opens, then the hierarchy's rows, and what the
// graph, the depth selector and the userdata's picker know of its nodes.

import { containers } from "./status.js";

const TREE_WAIT_MS = 250; // the hierarchy's rows wait this long at most for the drawing

export class MachineDrawing {
  /**
   * @param {Store} store the page's store
   * @param {object} api the REST API (api.js): graphSvg(name, expand)
   * @param {object} views {graph, depth, tree, userdata} (graph.js, depth.js, tree.js, userdata.js)
   * @param {() => void} redraw asks for the page to be drawn again (the marks on a new drawing)
   */
  constructor(store, api, views, redraw) {
    this.store = store;
    this.api = api;
    this.views = views;
    this.redraw = redraw;
  }

  /** A new structure (`state`: the store's). */
  restructured({ live, nodes }) {
    const { graph, depth, tree, userdata } = this.views;
    const root = live.structure;
    graph.index(nodes.values());
    depth.restructured();
    // The drawing first: a big machine's hierarchy takes longer to build and lay out than the server's
    // drawing takes to come, so its rows wait for the drawing (at most TREE_WAIT_MS).
    const drawn = this.load();
    Promise.race([drawn, new Promise((done) => setTimeout(done, TREE_WAIT_MS))]).then(() => {
      if (this.store.state.live?.structure !== root) return; // another machine or structure since
      tree.build(root);
      this.redraw();
    });
    userdata.setContainers([...containers(root)]);
    if (!userdata.path || !nodes.has(userdata.path)) userdata.show(root ? root.path : null);
  }

  /** Draw the layout of the structure with the containers `depth` opens (the server lays it out);
   * `semantic`: opened or closed as the machine moved: what the user looks at stays where it is. */
  async load(semantic = false) {
    const { graph, depth } = this.views;
    const { name, live, structureKey } = this.store.state;
    if (!live.structure) return;
    const expand = depth.paths();
    const key = JSON.stringify([name, structureKey, expand]);
    try {
      const anchor = semantic ? () => this.store.state.selected || graph.activePath : null;
      if (await graph.load(key, () => this.api.graphSvg(name, expand), anchor)) {
        depth.laidOut();
        this.redraw();
      }
    } catch (err) {
      if (name !== this.store.state.name) return;
      const text = "Could not draw the graph: " + (err.detail || err.message);
      if (err.status === 404 && graph.key) this.store.say(text, "warn"); // that drawing is missing: keep the one shown
      else graph.clear(text);
    }
  }
}
