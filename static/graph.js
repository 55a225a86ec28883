// The machine graph: the server's Graphviz SVG (one layout per structure + expand set),
// sanitized and inlined; status only toggles CSS classes on the stable ids of docs/api.md
// (s:PATH, c:PATH, o:PATH:OUTCOME, e:PATH:FROM:OUTCOME, escaped as static/schema.js says), so
// the layout never moves when only the status changes; the marks are drawn by an overlay of copies
// (graph_marks.js), so the drawing itself never repaints. Pan (drag) and zoom (wheel) act on the
// viewBox of both. One module (about 300 lines): loading, marking and pan/zoom all act on the same
// inlined SVG and its element index.

import { GraphMarks } from "./graph_marks.js";
import { containerId, outcomeId, stateId } from "./schema.js";
import { parentPath } from "./status.js";

const SVG_NS = "http://www.w3.org/2000/svg";
const MAX_FIT_SCALE = 1.7; // px per SVG unit (pt): about 1.3 times Graphviz's natural size
const DROP_ELEMENTS = new Set(["script", "foreignobject", "iframe", "object", "embed", "image", "use", "animate",
  "set", "animatemotion", "animatetransform", "handler", "listener", "style"]);

/** Remove anything active from a parsed SVG: scripts, foreign content, event handlers, external links. */
export function sanitizeSvg(root) {
  const doomed = [];
  for (const el of [root, ...root.querySelectorAll("*")]) {
    if (DROP_ELEMENTS.has(el.localName.toLowerCase())) {
      doomed.push(el);
      continue;
    }
    for (const attr of [...el.attributes]) {
      const name = attr.name.toLowerCase();
      const value = attr.value.trim().toLowerCase();
      if (name.startsWith("on")
          || ((name === "href" || name.endsWith(":href") || name === "src") && !value.startsWith("#"))
          || (name === "style" && (value.includes("url(") || value.includes("javascript:")))) {
        el.removeAttribute(attr.name);
      }
    }
  }
  for (const el of doomed) el.remove();
  // Graphviz prefixes ids with "pageX,Y_" when it paginates; the contract's ids are without.
  for (const el of root.querySelectorAll("[id]")) {
    const m = /^page\d+,\d+_([scoe]:.*)$/s.exec(el.id);
    if (m) el.id = m[1];
  }
  return root;
}

/** Parse SVG text into a sanitized <svg> element of this document (never innerHTML). */
export function parseSvg(text) {
  const doc = new DOMParser().parseFromString(text, "image/svg+xml");
  const svg = doc.documentElement;
  if (!svg || svg.localName !== "svg" || svg.namespaceURI !== SVG_NS || doc.querySelector("parsererror")) {
    throw new Error("the server's graph is not valid SVG");
  }
  sanitizeSvg(svg);
  return document.importNode(svg, true);
}

export class GraphView {
  /**
   * @param {HTMLElement} host the element the SVG goes in
   * @param {object} handlers {select(path), contextmenu(path, x, y), toggle(path), userPanned()}
   */
  constructor(host, handlers) {
    this.host = host;
    this.handlers = handlers;
    this.svg = null;
    this.marks = null; // the overlay that draws the classes set on this.svg's elements
    this.base = null; // the layout's own viewBox {x, y, w, h}
    this.vb = null;
    this.key = null; // what the current SVG was laid out for
    this.classed = new Map(); // class name -> Set of element ids
    this.pathOf = new Map(); // element id -> the path of the state or container it stands for
    this.follow = true;
    this.loadToken = 0;
    this._bindPointer();
  }

  /** Load the layout for `key` (a string naming structure + expand set) unless already shown. */
  async load(key, fetchSvg) {
    if (key === this.key) return false;
    const token = ++this.loadToken;
    const text = await fetchSvg();
    if (token !== this.loadToken) return false; // a newer load started meanwhile
    const svg = parseSvg(text);
    const vb = svg.viewBox.baseVal;
    let base;
    if (vb && vb.width > 0) {
      base = { x: vb.x, y: vb.y, w: vb.width, h: vb.height };
    } else {
      base = { x: 0, y: 0, w: parseFloat(svg.getAttribute("width")) || 100, h: parseFloat(svg.getAttribute("height")) || 100 };
    }
    svg.setAttribute("width", "100%");
    svg.setAttribute("height", "100%");
    svg.setAttribute("preserveAspectRatio", "xMidYMid meet");
    svg.removeAttribute("style");
    svg.classList.add("graph-svg");
    this.svg = svg;
    this.marks = new GraphMarks(svg);
    this.base = base;
    this.key = key;
    this.classed = new Map();
    this.host.replaceChildren(svg, this.marks.svg);
    this.fit();
    return true;
  }

  clear(message) {
    this.svg = null;
    this.marks = null;
    this.key = null;
    this.classed = new Map();
    const p = document.createElement("p");
    p.className = "graph-empty";
    p.textContent = message || "";
    this.host.replaceChildren(p);
  }

  el(id) {
    return this.svg ? document.getElementById(id) : null;
  }

  /** Learn the element ids of a structure's nodes: an id is escaped text, looked up here, never parsed. */
  index(nodes) {
    this.pathOf = new Map();
    for (const node of nodes) {
      this.pathOf.set(stateId(node.path), node.path);
      if (!node.container) continue;
      this.pathOf.set(containerId(node.path), node.path);
      for (const outcome of node.outcomes) this.pathOf.set(outcomeId(node.path, outcome), node.path);
    }
  }

  /** The paths of the containers drawn open (as clusters). */
  openPaths() {
    const clusters = this.svg ? [...this.svg.querySelectorAll("g.cluster")] : [];
    return clusters.map((g) => this.pathOf.get(g.id)).filter((path) => path !== undefined);
  }

  /** The element that stands for a state path: itself, or the closest collapsed ancestor. */
  stateElement(path) {
    for (let p = path; p; p = parentPath(p)) {
      const el = this.el(stateId(p)) || this.el(containerId(p));
      if (el) return el;
    }
    return null;
  }

  /** Set `cls` on exactly the elements whose ids are in `ids` (touching only what changed). */
  _setClass(cls, ids) {
    const before = this.classed.get(cls) || new Set();
    for (const id of before) {
      if (!ids.has(id)) this.el(id)?.classList.remove(cls);
    }
    const now = new Set();
    for (const id of ids) {
      const el = this.el(id);
      if (!el) continue;
      el.classList.add(cls);
      now.add(id);
    }
    this.classed.set(cls, now);
  }

  /**
   * @param {object} view {active: [paths], running: [container paths], reached: [o: ids],
   *   lastEdges: [e: ids], failed: [paths], selected: path|null, breakpoints: [paths with one],
   *   held: [paths where the machine holds]}
   */
  apply(view) {
    if (!this.svg) return;
    const active = new Set();
    let deepest = null;
    for (const path of view.active) {
      const el = this.stateElement(path);
      if (!el) continue;
      active.add(el.id);
      if (!deepest || path.length > deepest.path.length) deepest = { path, el };
    }
    // Measured before anything is written, so reading the layout forces no style or layout.
    const pan = this.follow && deepest ? this._panFor(deepest.el) : null;
    for (const path of view.running) {
      if (this.el(containerId(path))) active.add(containerId(path));
    }
    this._setClass("active", active);
    this._setClass("reached", new Set(view.reached));
    this._setClass("last", new Set(view.lastEdges));
    this._setClass("failed", this._drawnIds(view.failed));
    this._setClass("selected", this._drawnIds(view.selected ? [view.selected] : []));
    this._setClass("breakpoint", this._drawnIds(view.breakpoints));
    this._setClass("held", this._drawnIds(view.held));
    this.marks.show(new Set([...this.classed.values()].flatMap((ids) => [...ids])));
    if (pan) this._setViewBox(pan);
  }

  /** The ids of the elements standing for `paths` (each itself or its closest drawn ancestor). */
  _drawnIds(paths) {
    const ids = new Set();
    for (const path of paths) {
      const el = this.stateElement(path);
      if (el) ids.add(el.id);
    }
    return ids;
  }

  /** Pan (never zoom) so that `el` is inside the view, when it is not already. */
  reveal(el) {
    const pan = this.svg && el ? this._panFor(el) : null;
    if (pan) this._setViewBox(pan);
  }

  /** The viewBox that brings `el` into the view, or null when it is in already (or cannot be). */
  _panFor(el) {
    const box = el.getBoundingClientRect();
    const view = this.host.getBoundingClientRect();
    if (!view.width || !view.height) return null;
    const margin = 2;
    if (box.width > view.width - 2 * margin || box.height > view.height - 2 * margin) return null;
    const inside = box.left >= view.left + margin && box.right <= view.right - margin
      && box.top >= view.top + margin && box.bottom <= view.bottom - margin;
    if (inside) return null;
    const ctm = this.svg.getScreenCTM();
    if (!ctm) return null;
    const k = ctm.a || 1;
    const dx = (box.left + box.width / 2 - (view.left + view.width / 2)) / k;
    const dy = (box.top + box.height / 2 - (view.top + view.height / 2)) / k;
    return { ...this.vb, x: this.vb.x + dx, y: this.vb.y + dy };
  }

  /** Show the whole graph, but never larger than MAX_FIT_SCALE pixels per SVG unit (a tiny graph stays small). */
  fit() {
    if (!this.base) return;
    const pad = Math.max(this.base.w, this.base.h) * 0.02;
    let vb = { x: this.base.x - pad, y: this.base.y - pad, w: this.base.w + 2 * pad, h: this.base.h + 2 * pad };
    const rect = this.host.getBoundingClientRect();
    const scale = Math.min(rect.width / vb.w, rect.height / vb.h);
    if (rect.width && rect.height && scale > MAX_FIT_SCALE) {
      const w = rect.width / MAX_FIT_SCALE;
      const h = rect.height / MAX_FIT_SCALE;
      vb = { x: vb.x + vb.w / 2 - w / 2, y: vb.y + Math.min(vb.h / 2 - h / 2, 0), w, h };
    }
    this._setViewBox(vb);
  }

  zoom(factor, clientX, clientY) {
    if (!this.svg || !this.vb) return;
    const rect = this.host.getBoundingClientRect();
    if (clientX === undefined) {
      clientX = rect.left + rect.width / 2;
      clientY = rect.top + rect.height / 2;
    }
    const p = this._toUser(clientX, clientY);
    const w = Math.min(Math.max(this.vb.w / factor, this.base.w / 50), this.base.w * 20);
    const f = w / this.vb.w;
    this._setViewBox({ x: p.x - (p.x - this.vb.x) * f, y: p.y - (p.y - this.vb.y) * f, w, h: this.vb.h * f });
  }

  _toUser(clientX, clientY) {
    const ctm = this.svg.getScreenCTM();
    const pt = new DOMPoint(clientX, clientY).matrixTransform(ctm ? ctm.inverse() : new DOMMatrix());
    return { x: pt.x, y: pt.y };
  }

  _setViewBox(vb) {
    this.vb = vb;
    if (!this.svg) return;
    const text = `${vb.x} ${vb.y} ${vb.w} ${vb.h}`;
    this.svg.setAttribute("viewBox", text);
    this.marks.setViewBox(text);
  }

  _target(event) {
    const g = event.target.closest?.("g.node, g.cluster");
    if (!g || !this.svg?.contains(g)) return null;
    const path = this.pathOf.get(g.id);
    if (path === undefined) return null;
    // A cluster or a container's outcome stands for the open container (double-click closes it).
    return { path, cluster: g.id !== stateId(path), el: g };
  }

  _bindPointer() {
    const host = this.host;
    let drag = null;
    host.addEventListener("wheel", (e) => {
      if (!this.svg) return;
      e.preventDefault();
      this.zoom(Math.exp(-e.deltaY * (e.deltaMode === 1 ? 0.05 : 0.0015)), e.clientX, e.clientY);
    }, { passive: false });
    host.addEventListener("pointerdown", (e) => {
      if (!this.svg || e.button !== 0) return;
      drag = { x: e.clientX, y: e.clientY, vb: { ...this.vb }, k: this.svg.getScreenCTM()?.a || 1, moved: false };
    });
    host.addEventListener("pointermove", (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x;
      const dy = e.clientY - drag.y;
      if (!drag.moved && Math.hypot(dx, dy) < 4) return;
      if (!drag.moved) {
        drag.moved = true;
        host.setPointerCapture(e.pointerId);
        host.classList.add("dragging");
        this.handlers.userPanned?.();
      }
      this._setViewBox({ ...drag.vb, x: drag.vb.x - dx / drag.k, y: drag.vb.y - dy / drag.k });
    });
    const end = (e) => {
      if (!drag) return;
      if (drag.moved) {
        host.classList.remove("dragging");
        if (host.hasPointerCapture(e.pointerId)) host.releasePointerCapture(e.pointerId);
        // The click that follows a drag must not select anything.
        const swallow = (ev) => { ev.stopPropagation(); };
        host.addEventListener("click", swallow, { capture: true, once: true });
        setTimeout(() => host.removeEventListener("click", swallow, { capture: true }), 0);
      }
      drag = null;
    };
    host.addEventListener("pointerup", end);
    host.addEventListener("pointercancel", end);
    host.addEventListener("click", (e) => {
      const t = this._target(e);
      this.handlers.select?.(t ? t.path : null);
    });
    host.addEventListener("dblclick", (e) => {
      const t = this._target(e);
      if (t) this.handlers.toggle?.(t.path, t.cluster);
    });
    host.addEventListener("contextmenu", (e) => {
      const t = this._target(e);
      if (!t) return;
      e.preventDefault();
      this.handlers.contextmenu?.(t.path, e.clientX, e.clientY);
    });
  }
}
