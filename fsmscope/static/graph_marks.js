// The graph's marks (active, reached, last edge, failed, selected, breakpoint, held) drawn over the
// drawing, so the drawing itself never repaints when the instant changes. The drawing's elements
// keep their classes (the contract of docs/api.md: `#graph g.node.active` is the drawn state), but
// no style reads them; each marked element gets a copy in an overlay <svg> with the same viewBox (both fixed: graph.js moves them together),
// placed by its ancestors' transforms, and only the copies are styled. Their classes are the
// element's with "m-" in front, so no selector meant for the drawing ever matches a copy.
//
// Why: Chromium repaints and re-layerizes a whole SVG when any of its elements changes style; at
// 606 states (1,400 elements) that was 15 ms of every frame (bench/timetravel_browser.py), and
// the overlay holds a few elements.

import { ownBox, placement } from "./graph_geometry.js";

const SVG_NS = "http://www.w3.org/2000/svg";
const KINDS = ["cluster", "edge", "node"]; // the overlay's layers, drawn in this order

/** What a copy draws: a node's or an edge's shapes and label; a cluster's frame and label only (its
 * children are drawn, and marked, on their own). */
function drawnParts(el, kind) {
  const parts = kind === "cluster" ? el.querySelectorAll(":scope > polygon.frame, :scope > text") : el.children;
  return [...parts].filter((part) => part.localName !== "title").map((part) => {
    const copy = part.cloneNode(true);
    for (const named of [copy, ...copy.querySelectorAll("[id]")]) named.removeAttribute("id");
    return copy;
  });
}

// A state's debugger marks, also drawn as badges at its corners: a dot for a breakpoint (top left),
// a pause sign where the machine holds (top right). Their classes show them (style.css).
const BADGED = ["breakpoint", "held"];

function svgElement(name, attributes) {
  const el = document.createElementNS(SVG_NS, name);
  for (const [key, value] of Object.entries(attributes)) el.setAttribute(key, value);
  return el;
}

/** The badges of the drawing's element `el`, in its own coordinates (measured once per element). */
function badges(el) {
  const box = ownBox(el);
  const r = Math.max(3, Math.min(6, box.h / 4));
  const group = svgElement("g", { class: "badges" });
  group.append(svgElement("circle", { class: "bp-badge", cx: box.x + r / 2, cy: box.y + r / 2, r }));
  const held = svgElement("g", { class: "held-badge" });
  const [x, y] = [box.x + box.w - r / 2, box.y + r / 2];
  held.append(svgElement("circle", { cx: x, cy: y, r: r * 1.2 }),
    svgElement("rect", { x: x - r * 0.5, y: y - r * 0.6, width: r * 0.35, height: r * 1.2 }),
    svgElement("rect", { x: x + r * 0.15, y: y - r * 0.6, width: r * 0.35, height: r * 1.2 }));
  group.append(held);
  return group;
}

export class GraphMarks {
  /** @param {SVGSVGElement} drawing the inlined drawing the marks go over */
  constructor(drawing) {
    this.drawing = drawing;
    this.svg = document.createElementNS(SVG_NS, "svg");
    for (const [name, value] of [["class", "graph-marks"], ["aria-hidden", "true"], ["width", "100%"],
      ["height", "100%"], ["viewBox", drawing.getAttribute("viewBox")],
      ["preserveAspectRatio", drawing.getAttribute("preserveAspectRatio")]]) {
      this.svg.setAttribute(name, value);
    }
    this.layers = new Map(KINDS.map((kind) => [kind, this.svg.appendChild(document.createElementNS(SVG_NS, "g"))]));
    this.copies = new Map(); // drawing element id -> its copy
    this.places = new Map(KINDS.map((kind) => [kind, new Map()])); // kind -> (drawing element -> its <g> here)
  }

  /** The overlay's group, in the layer of `kind`, whose coordinates are those of the drawing's
   * element `frame`; made once and kept, so that marking an element adds no transform (Chromium then
   * updates only what was repainted, not the whole page's layers). */
  _place(kind, frame) {
    const groups = this.places.get(kind);
    let group = groups.get(frame);
    if (!group) {
      group = document.createElementNS(SVG_NS, "g");
      group.setAttribute("transform", placement(frame, this.drawing).toString());
      this.layers.get(kind).append(group);
      groups.set(frame, group);
    }
    return group;
  }

  /** Draw a copy of exactly the elements whose ids are in `ids`, with their current classes; only
   * what changed is touched. */
  show(ids) {
    for (const [id, copy] of this.copies) {
      if (!ids.has(id)) {
        copy.remove();
        this.copies.delete(id);
      }
    }
    for (const id of ids) {
      const el = document.getElementById(id);
      if (!el || !this.drawing.contains(el)) continue;
      const classes = [...el.classList].map((name) => "m-" + name).join(" ");
      let copy = this.copies.get(id);
      if (!copy) {
        const kind = KINDS.find((k) => el.classList.contains(k)) || "node";
        copy = document.createElementNS(SVG_NS, "g");
        copy.append(...drawnParts(el, kind));
        // A copy's parts are drawn in the element's own coordinates: its parent's, unless it moves them.
        this._place(kind, el.hasAttribute("transform") ? el : el.parentElement).append(copy);
        this.copies.set(id, copy);
      }
      if (copy.getAttribute("class") === classes) continue;
      copy.setAttribute("class", classes);
      if (!copy.lastElementChild?.classList.contains("badges") && BADGED.some((name) => el.classList.contains(name))) {
        copy.append(badges(el));
      }
    }
  }
}
