// The machine graph, one piece on purpose: loading, marking and the view box all act on the same
// inlined SVG, its element index and the boxes measured on it. The SVG is the server's Graphviz
// drawing (one layout per structure + expand set), sanitized and inlined; status only toggles CSS
// classes on the stable ids of docs/api.md (s:PATH, c:PATH, o:PATH:OUTCOME, e:PATH:FROM:OUTCOME,
// escaped as static/schema.js says), so the layout never moves when only the status changes; the
// marks are drawn by an overlay of copies (graph_marks.js), so the drawing itself never repaints.
// Both lie on a stage the size of the drawing at the scale shown: a pan (drag, Follow) moves the
// stage (a CSS transform, which Chromium composites without laying out or painting the drawing
// again: changing the viewBox of a 600-state drawing laid its text out again, 15 ms a frame), a
// zoom resizes it. `vb`, the view box shown, is the one abstraction the rest of the page reads. A
// fit keeps labels readable (graph_geometry.js), a new layout of the same machine can keep one
// element where it was on screen (semantic zoom). It tells its host what changed ("graph:layout",
// "graph:view", "graph:focus", "graph:fit" events), which the minimap and the breadcrumb
// (minimap.js, breadcrumb.js) follow; its pointer is graph_pointer.js's.

import { anchorAfter, anchorBefore, partView, readableFit } from "./graph_fit.js";
import { COMFORT_SCALE, READABLE_SCALE, ZOOM_STEP, clusterBoxes, fitView, userBox } from "./graph_geometry.js";
import { GraphMarks } from "./graph_marks.js";
import { bindPointer } from "./graph_pointer.js";
import { markExactly } from "./dom.js";
import { containerId, outcomeId, stateId } from "./schema.js";
import { parentPath } from "./status.js";
import { parseSvg } from "./svg_safe.js";

export { parseSvg, sanitizeSvg } from "./svg_safe.js";

export class GraphView {
  /**
   * @param {HTMLElement} host the element the SVG goes in
   * @param {object} handlers {select(path), contextmenu(path, x, y), toggle(path), userPanned()}
   */
  constructor(host, handlers) {
    this.host = host;
    this.svg = null;
    this.marks = null; // the overlay that draws the classes set on this.svg's elements
    this.base = null; // the layout's own viewBox {x, y, w, h}
    this.vb = null;
    this.key = null; // what the current SVG was laid out for
    this.classed = new Map(); // class name -> Set of element ids
    this.pathOf = new Map(); // element id -> the path of the state or container it stands for
    this.follow = true;
    this.loadToken = 0;
    this.clusters = []; // the open containers' frames in user space ({path, box}), parents first
    this.activePath = null; // the deepest active state
    this.selectedPath = null;
    this.stage = null; // the element that holds the drawing and its marks, moved and sized by the view
    this.stageScale = null; // px per SVG unit the stage is sized for
    this.size = null; // the host's size in px, kept by a ResizeObserver (reading it would force a layout)
    this.boxes = new Map(); // element id -> its box in user space (measured once per drawing)
    this.fitted = null; // the view box the last fit showed, while it is shown
    this.note = ""; // what that fit says it shows ("": the whole graph, or no fit shown)
    this.inset = 0; // px at the bottom of the host a part of the drawing is kept clear of (the minimap)
    new ResizeObserver(() => {
      this.size = null;
      if (this.vb && this.vb === this.fitted) this.fit(); // a fit shown stays one: what it shows may change
      else if (this.vb) this.setViewBox(this.vb);
    }).observe(host);
    bindPointer(this, handlers);
  }

  _emit(type, detail) {
    this.host.dispatchEvent(new CustomEvent("graph:" + type, { detail }));
  }

  /**
   * Load the layout for `key` (a string naming structure + expand set) unless already shown.
   * @param {(() => string|null)|null} anchorOf the state to keep (or its closest drawn ancestor) where
   *   it is on screen, at the same scale, asked when the drawing has come (the user may have selected
   *   another meanwhile); null: fit the new drawing
   */
  async load(key, fetchSvg, anchorOf = null) {
    const token = ++this.loadToken; // any later request, even for the drawing shown, outdates one in flight
    if (key === this.key) return false;
    const text = await fetchSvg();
    if (token !== this.loadToken) return false; // a newer load started meanwhile
    const svg = parseSvg(text);
    const anchorPath = anchorOf && this.svg ? anchorOf() : null;
    const anchor = anchorPath ? anchorBefore(this, anchorPath) : null;
    const vb = svg.viewBox.baseVal;
    let base;
    if (vb && vb.width > 0) {
      base = { x: vb.x, y: vb.y, w: vb.width, h: vb.height };
    } else {
      base = { x: 0, y: 0, w: parseFloat(svg.getAttribute("width")) || 100, h: parseFloat(svg.getAttribute("height")) || 100 };
    }
    svg.setAttribute("width", "100%");
    svg.setAttribute("height", "100%");
    svg.setAttribute("viewBox", `${base.x} ${base.y} ${base.w} ${base.h}`);
    svg.setAttribute("preserveAspectRatio", "xMidYMid meet");
    svg.removeAttribute("style");
    svg.classList.add("graph-svg");
    this.svg = svg;
    this.marks = new GraphMarks(svg);
    this.base = base;
    this.key = key;
    this.classed = new Map();
    this.boxes = new Map();
    this.stage = document.createElement("div");
    this.stage.className = "graph-stage";
    this.stageScale = null;
    this.stage.append(svg, this.marks.svg);
    this.host.replaceChildren(this.stage);
    this.clusters = clusterBoxes(svg, this.pathOf);
    const anchored = anchor ? anchorAfter(this, anchor) : null;
    if (anchored) this.setViewBox(anchored);
    else this.fit();
    this._emit("layout");
    return true;
  }

  clear(message) {
    this.svg = null;
    this.activePath = null; // another machine's: its first view is fitted on its own active state
    this.marks = null;
    this.stage = null;
    this.key = null;
    this.base = null;
    this.clusters = [];
    this.classed = new Map();
    this._said("");
    this._emit("layout");
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
    this.classed.set(cls, markExactly(cls, this.classed.get(cls) || new Set(), ids, (id) => this.el(id)));
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
    let pan = this.follow && deepest ? this._panFor(deepest.el) : null;
    // The first view of a machine too big to read whole: the fit made before its active state was known
    // showed its top left; now it can show the active state's container.
    const refit = deepest && !this.activePath && this.note && this.vb === this.fitted;
    if (deepest?.path !== this.activePath || view.selected !== this.selectedPath) {
      this.activePath = deepest?.path ?? null;
      this.selectedPath = view.selected;
      this._emit("focus");
    }
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
    if (refit) this.fit();
    else if (pan) this.setViewBox(pan);
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

  /** Centre the state at `path` (or its closest drawn ancestor), zoomed in to labels of a comfortable
   * size when they are too small to read (a search's choice, "Center in graph"). */
  centrePath(path) {
    const el = this.stateElement(path);
    const rect = this._hostSize();
    if (!el || !rect || !this.vb) return;
    const box = this._box(el);
    const scale = this.scale() < READABLE_SCALE ? COMFORT_SCALE : this.scale();
    this.setViewBox(partView(box, scale, rect, this.inset));
  }

  /** An element's box in user space, measured once per drawing. */
  _box(el) {
    let box = this.boxes.get(el.id);
    if (!box) this.boxes.set(el.id, box = userBox(el, this.svg));
    return box;
  }

  /** The viewBox that brings `el` into the view, or null when it is in already (or cannot be); from
   * the drawing's geometry, so that following the active state reads no layout. */
  _panFor(el) {
    const view = this.visible();
    if (!view || !this.vb) return null;
    const box = this._box(el);
    const margin = 2 / this.scale();
    view.h -= this.inset / this.scale(); // the part under the minimap is not in view
    if (box.w > view.w - 2 * margin || box.h > view.h - 2 * margin) return null;
    const inside = box.x >= view.x + margin && box.x + box.w <= view.x + view.w - margin
      && box.y >= view.y + margin && box.y + box.h <= view.y + view.h - margin;
    if (inside) return null;
    const dx = box.x + box.w / 2 - (view.x + view.w / 2);
    const dy = box.y + box.h / 2 - (view.y + view.h / 2);
    return { ...this.vb, x: this.vb.x + dx, y: this.vb.y + dy };
  }

  /** The host's size in px, or null while it has none (hidden). */
  _hostSize() {
    if (!this.size) {
      const rect = this.host.getBoundingClientRect();
      if (rect.width && rect.height) this.size = { width: rect.width, height: rect.height };
    }
    return this.size;
  }

  /** Px per SVG unit of the view shown. */
  scale() {
    const rect = this._hostSize();
    return rect && this.vb ? Math.min(rect.width / this.vb.w, rect.height / this.vb.h) : 1;
  }

  /** What the host shows, in user space: `vb` widened to the host's proportions (it is shown centred,
   * whole); null while the host has no size. */
  visible() {
    const rect = this._hostSize();
    if (!rect || !this.vb) return null;
    const k = this.scale();
    const [w, h] = [rect.width / k, rect.height / k];
    return { x: this.vb.x + (this.vb.w - w) / 2, y: this.vb.y + (this.vb.h - h) / 2, w, h };
  }

  /**
   * Show the whole graph, never larger than MAX_FIT_SCALE (a tiny graph stays small) and never so
   * small that labels cannot be read (graph_fit.js); says what it shows ("graph:fit": a sentence, or
   * "" for the whole graph), until the view changes.
   */
  fit() {
    if (!this.base) return;
    const rect = this._hostSize();
    const { vb, note } = rect ? readableFit(this, rect) : { vb: { ...this.base }, note: "" };
    this.setViewBox(vb);
    this.fitted = vb;
    this._said(note);
  }

  /** Show the whole graph however small its labels get (the fit's note offers it). */
  fitWhole() {
    const rect = this._hostSize();
    if (this.base && rect) this.setViewBox(fitView(this.base, rect.width, rect.height));
  }

  /** Tell what the view shows when it changes ("graph:fit": the fit's sentence, "" once the view is
   * another than the fit's). */
  _said(note) {
    if (note === this.note) return;
    this.note = note;
    this._emit("fit", note);
  }

  /** Show `box` (user space) whole, centred, at most MAX_FIT_SCALE. */
  fitBox(box) {
    const rect = this._hostSize();
    if (rect) this.setViewBox(fitView(box, rect.width, rect.height));
  }

  /** Fit the open container at `path` (its frame), or the element that stands for it. */
  fitPath(path) {
    const cluster = this.clusters.find((c) => c.path === path);
    const el = cluster ? null : this.stateElement(path);
    if (cluster || el) this.fitBox(cluster ? cluster.box : userBox(el, this.svg));
  }

  /** Pan, at the same scale, so that (x, y) of user space is the view's centre. */
  centreOn(x, y) {
    if (!this.vb) return;
    this.setViewBox({ ...this.vb, x: x - this.vb.w / 2, y: y - this.vb.h / 2 });
  }

  /** `steps` zoom steps in (positive) or out (negative), about the view's centre. */
  zoomStep(steps) {
    this.zoom(ZOOM_STEP ** steps);
  }

  /** Zoom, about the view's centre, to labels of a comfortable size (13 px). */
  zoomReadable() {
    this.zoom(COMFORT_SCALE / this.scale());
  }

  zoom(factor, clientX, clientY) {
    if (!this.svg || !this.vb) return;
    const rect = this.host.getBoundingClientRect();
    if (clientX === undefined) {
      clientX = rect.left + rect.width / 2;
      clientY = rect.top + rect.height / 2;
    }
    const p = this._toUser(clientX - rect.left, clientY - rect.top);
    const w = Math.min(Math.max(this.vb.w / factor, this.base.w / 50, rect.width / 8), this.base.w * 20);
    const f = w / this.vb.w;
    this.setViewBox({ x: p.x - (p.x - this.vb.x) * f, y: p.y - (p.y - this.vb.y) * f, w, h: this.vb.h * f });
  }

  /** The user-space point at (x, y) px from the host's top left. */
  _toUser(x, y) {
    const view = this.visible();
    const k = this.scale();
    return { x: view.x + x / k, y: view.y + y / k };
  }

  /** Show `vb`: the stage resized when the scale changes (the drawing is painted again at it), else
   * only moved. */
  setViewBox(vb) {
    this.vb = vb;
    if (vb !== this.fitted) {
      this.fitted = null;
      this._said("");
    }
    const view = this.stage && this.visible();
    if (!view) return;
    const k = this.scale();
    if (k !== this.stageScale) {
      this.stageScale = k;
      this.stage.style.width = `${this.base.w * k}px`;
      this.stage.style.height = `${this.base.h * k}px`;
    }
    this.stage.style.transform = `translate(${(this.base.x - view.x) * k}px, ${(this.base.y - view.y) * k}px)`;
    this._emit("view");
  }
}
