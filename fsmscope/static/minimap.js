// The minimap: the whole drawing's outline (its open containers' frames, drawn once per layout), the
// rectangle the graph pane shows and the active state's box (at least a few px, never more than the
// state); a click or a drag on it pans there. It lies over the graph pane's bottom right corner, so it
// is shown only while the view shows part of the drawing (the whole needs no map) and its checkbox is
// ticked, and the graph keeps what it fits or follows clear of it (GraphView.inset).
// It follows the GraphView's events (graph.js), redrawn at most once per animation frame, and reads
// the active state's box once per element and layout (from the drawing's attributes), so following a
// fast machine costs a few attribute writes a frame.

import { userBox } from "./graph_geometry.js";

const SVG_NS = "http://www.w3.org/2000/svg";
// Px at the bottom of the graph pane the minimap takes (style.css: its height, borders and padding
// included, its offset) and a gap.
export const MINIMAP_INSET = 104 + 8 + 4;

function svgEl(name, attributes = {}) {
  const el = document.createElementNS(SVG_NS, name);
  for (const [key, value] of Object.entries(attributes)) el.setAttribute(key, String(value));
  return el;
}

export class Minimap {
  /**
   * @param {HTMLElement} host the minimap's box (over the graph pane)
   * @param {HTMLInputElement} toggle its checkbox: unticked, it is never shown
   * @param {import("./graph.js").GraphView} graph
   * @param {(x: number, y: number) => void} pan centre the graph on this point of its user space
   */
  constructor(host, toggle, graph, pan) {
    this.host = host;
    this.toggle = toggle;
    this.graph = graph;
    this.svg = host.appendChild(svgEl("svg", { preserveAspectRatio: "xMidYMid meet", "aria-hidden": "true" }));
    this.outline = this.svg.appendChild(svgEl("g", { class: "mm-outline" }));
    this.view = this.svg.appendChild(svgEl("rect", { class: "mm-view" }));
    this.mark = this.svg.appendChild(svgEl("rect", { class: "mm-active", width: 0, height: 0 }));
    this.boxes = new Map(); // element id -> its box in user space, for this layout
    this.queued = false;
    graph.inset = MINIMAP_INSET;
    toggle.addEventListener("change", () => {
      graph.inset = toggle.checked ? MINIMAP_INSET : 0;
      this._queue();
    });
    graph.host.addEventListener("graph:layout", () => this._draw());
    for (const type of ["graph:view", "graph:focus"]) graph.host.addEventListener(type, () => this._queue());
    this._bindPointer(pan);
  }

  /** The outline of the layout shown, once per layout. */
  _draw() {
    const { base, clusters } = this.graph;
    this.boxes = new Map();
    this.host.hidden = !base;
    if (!base) return;
    this.svg.setAttribute("viewBox", `${base.x} ${base.y} ${base.w} ${base.h}`);
    this.outline.replaceChildren(...clusters.map(({ box }) => svgEl("rect", { x: box.x, y: box.y, width: box.w, height: box.h })));
    this.minMark = Math.max(base.w, base.h) / 50; // ~3 px of the map
    this._queue();
  }

  _queue() {
    if (this.queued || !this.graph.base) return;
    this.queued = true;
    requestAnimationFrame(() => {
      this.queued = false;
      this._update();
    });
  }

  /** Shown or not; the viewport's rectangle and the active state's mark. */
  _update() {
    const { svg, activePath, base } = this.graph;
    const vb = this.graph.visible();
    if (!vb || !svg) return;
    const slack = 1; // user units: a fit's rounding
    const whole = vb.x <= base.x + slack && vb.y <= base.y + slack && vb.x + vb.w >= base.x + base.w - slack
      && vb.y + vb.h >= base.y + base.h - slack;
    const hidden = whole || !this.toggle.checked;
    if (this.host.hidden !== hidden) this.host.hidden = hidden;
    for (const [name, value] of [["x", vb.x], ["y", vb.y], ["width", vb.w], ["height", vb.h]]) this.view.setAttribute(name, value);
    const el = activePath ? this.graph.stateElement(activePath) : null;
    if (!el) {
      this.mark.setAttribute("width", 0);
      return;
    }
    let box = this.boxes.get(el.id);
    if (!box) this.boxes.set(el.id, box = userBox(el, svg));
    const [w, h] = [Math.max(box.w, this.minMark), Math.max(box.h, this.minMark)];
    for (const [name, value] of [["x", box.x + (box.w - w) / 2], ["y", box.y + (box.h - h) / 2], ["width", w], ["height", h]]) {
      this.mark.setAttribute(name, value);
    }
  }

  _bindPointer(pan) {
    let dragging = false;
    const panTo = (e) => {
      const ctm = this.svg.getScreenCTM();
      if (!ctm) return;
      const p = new DOMPoint(e.clientX, e.clientY).matrixTransform(ctm.inverse());
      pan(p.x, p.y);
    };
    this.svg.addEventListener("pointerdown", (e) => {
      if (e.button !== 0 || !this.graph.base) return;
      dragging = true;
      this.svg.setPointerCapture(e.pointerId);
      panTo(e);
    });
    this.svg.addEventListener("pointermove", (e) => {
      if (dragging) panTo(e);
    });
    const end = () => { dragging = false; };
    this.svg.addEventListener("pointerup", end);
    this.svg.addEventListener("pointercancel", end);
  }
}
