// The panes' sizes: splitters over the layout's gaps (between the graph and the right column, between
// the right column's rows, and between the hierarchy and the userdata beside the 3D view) that resize
// the grid's tracks by dragging; the sizes are kept per browser (localStorage), one set per layout
// (with or without the 3D view), and a double-click on a splitter gives that layout its defaults back.
// The grid's templates are CSS variables (style.css: --plain-cols, --scene-rows...), so the
// stylesheet keeps the defaults and the class that switches layouts.

import { h } from "./dom.js";

const STORE_KEY = "fsmscope.panes";
const MIN_TRACK = 120; // px: a pane never gets narrower or shorter than this
const MIN_GRAPH = 240;

// Per layout, the splitters: a boundary after track `index` of `axis`, drawn across tracks `span` of
// the other axis (the graph spans every row; the 3D view and the log span the side columns).
const SPLITTERS = {
  plain: [{ axis: "col", index: 0, span: [0, 3] }, { axis: "row", index: 0, span: [1, 2] },
    { axis: "row", index: 1, span: [1, 2] }],
  scene: [{ axis: "col", index: 0, span: [0, 3] }, { axis: "col", index: 1, span: [1, 2] },
    { axis: "row", index: 0, span: [1, 3] }, { axis: "row", index: 1, span: [1, 3] }],
};

/** The resolved sizes (px) of a grid's tracks, as the computed style lists them. */
function tracks(text) {
  return text.split(" ").map(parseFloat).filter((n) => Number.isFinite(n));
}

/** The grid's templates for `sizes`: the graph's column takes what is left, rows keep their shares. */
function templates(sizes) {
  return {
    cols: ["minmax(0, 1fr)", ...sizes.cols.slice(1).map((px) => `${Math.round(px)}px`)].join(" "),
    rows: sizes.rows.map((px) => `minmax(0, ${Math.round(px)}fr)`).join(" "),
  };
}

export class Panes {
  /** @param {HTMLElement} layout the page's grid (main.layout) */
  constructor(layout) {
    this.layout = layout;
    this.handles = [];
    this.saved = this._read();
    for (const mode of Object.keys(SPLITTERS)) if (this.saved[mode]) this._apply(mode, this.saved[mode]);
    new ResizeObserver(() => this._place()).observe(layout);
    // The 3D view appears (scene.js adds "with-scene") after the page has started.
    new MutationObserver(() => this._place()).observe(layout, { attributes: true, attributeFilter: ["class"] });
    this._place();
  }

  mode() {
    return this.layout.classList.contains("with-scene") ? "scene" : "plain";
  }

  _read() {
    try {
      return JSON.parse(localStorage.getItem(STORE_KEY)) || {};
    } catch {
      return {};
    }
  }

  _apply(mode, sizes) {
    const t = templates(sizes);
    this.layout.style.setProperty(`--${mode}-cols`, t.cols);
    this.layout.style.setProperty(`--${mode}-rows`, t.rows);
  }

  /** The tracks' sizes now (px). */
  _sizes() {
    const style = getComputedStyle(this.layout);
    return { cols: tracks(style.gridTemplateColumns), rows: tracks(style.gridTemplateRows),
      gap: parseFloat(style.columnGap) || 0, pad: parseFloat(style.paddingLeft) || 0 };
  }

  /** Put a handle over each gap of the layout shown. */
  _place() {
    const specs = SPLITTERS[this.mode()];
    while (this.handles.length > specs.length) this.handles.pop().remove();
    while (this.handles.length < specs.length) {
      const handle = h("div", { class: "splitter", role: "separator", title: "Drag to resize; double-click: default sizes" });
      this._bind(handle);
      this.handles.push(this.layout.appendChild(handle));
    }
    const { cols, rows, gap, pad } = this._sizes();
    const edge = (list, i) => pad + list.slice(0, i).reduce((a, b) => a + b, 0) + gap * i; // start of track i
    specs.forEach((spec, i) => {
      const handle = this.handles[i];
      const [along, across] = spec.axis === "col" ? [cols, rows] : [rows, cols];
      const at = edge(along, spec.index + 1) - gap;
      const from = edge(across, spec.span[0]);
      const to = edge(across, spec.span[1]) - gap;
      handle.dataset.axis = spec.axis;
      handle.spec = spec;
      Object.assign(handle.style, spec.axis === "col"
        ? { left: `${at}px`, width: `${gap}px`, top: `${from}px`, height: `${to - from}px` }
        : { top: `${at}px`, height: `${gap}px`, left: `${from}px`, width: `${to - from}px` });
    });
  }

  _bind(handle) {
    let drag = null;
    handle.addEventListener("pointerdown", (e) => {
      if (e.button !== 0) return;
      e.preventDefault();
      handle.setPointerCapture(e.pointerId);
      drag = { spec: handle.spec, start: handle.spec.axis === "col" ? e.clientX : e.clientY, sizes: this._sizes() };
      handle.classList.add("dragging");
    });
    handle.addEventListener("pointermove", (e) => {
      if (!drag) return;
      const delta = (drag.spec.axis === "col" ? e.clientX : e.clientY) - drag.start;
      this._resize(drag.spec, drag.sizes, delta);
    });
    const end = () => {
      if (!drag) return;
      drag = null;
      handle.classList.remove("dragging");
      const { cols, rows } = this._sizes();
      this.saved[this.mode()] = { cols, rows };
      localStorage.setItem(STORE_KEY, JSON.stringify(this.saved));
    };
    handle.addEventListener("pointerup", end);
    handle.addEventListener("pointercancel", end);
    handle.addEventListener("dblclick", () => {
      const mode = this.mode();
      delete this.saved[mode];
      localStorage.setItem(STORE_KEY, JSON.stringify(this.saved));
      this.layout.style.removeProperty(`--${mode}-cols`);
      this.layout.style.removeProperty(`--${mode}-rows`);
    });
  }

  /** Move the boundary of `spec` by `delta` px from `sizes` (the tracks when the drag began). */
  _resize(spec, sizes, delta) {
    const cols = [...sizes.cols];
    const rows = [...sizes.rows];
    if (spec.axis === "col" && spec.index === 0) {
      // The graph's edge: the side columns share what they gain or lose, in proportion.
      const side = cols.slice(1).reduce((a, b) => a + b, 0);
      const total = cols[0] + side;
      const wanted = Math.min(Math.max(side - delta, MIN_TRACK * (cols.length - 1)), total - MIN_GRAPH);
      for (let i = 1; i < cols.length; i++) cols[i] = sizes.cols[i] * wanted / side;
    } else {
      const list = spec.axis === "col" ? cols : rows;
      const [a, b] = [spec.index, spec.index + 1];
      const d = Math.min(Math.max(delta, MIN_TRACK - list[a]), list[b] - MIN_TRACK);
      list[a] += d;
      list[b] -= d;
    }
    this._apply(this.mode(), { cols, rows });
    this._place();
  }
}
