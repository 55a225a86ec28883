// What the pointer does on the timeline's canvas: a drag scrubs (the playhead follows at once, the
// page is asked once per frame), a click seeks a tick's or a band's event, shift-drag selects a range
// to zoom to, the wheel zooms (over the labels it scrolls the rows), a click on a row's label selects
// it; hovering names what is under the pointer in the canvas's title.

import { NO_LABEL } from "./timeline_data.js";
import { clockText } from "./clocktext.js";
import { LAYOUT, rowsTop, tOf } from "./timeline_draw.js";

const CLICK_SLOP = 3; // px a press may move and still be a click
const TICK_HIT = 4; // px either side of a tick

export class TimelinePointer {
  /** @param {Timeline} timeline whose canvas it listens to and whose actions it calls */
  constructor(timeline) {
    this.timeline = timeline;
    this.drag = null; // {mode: "press" | "scrub" | "range", x0}
    this.over = false;
    const c = timeline.canvas;
    c.addEventListener("pointerdown", (e) => this.down(e));
    c.addEventListener("pointermove", (e) => this.move(e));
    c.addEventListener("pointerup", (e) => this.up(e));
    c.addEventListener("pointercancel", () => this.cancel());
    c.addEventListener("pointerenter", () => { this.over = true; });
    c.addEventListener("pointerleave", () => { this.over = false; });
    c.addEventListener("dblclick", () => timeline.wholeRun());
    c.addEventListener("wheel", (e) => this.wheel(e), { passive: false });
  }

  local(e) {
    const r = this.timeline.canvas.getBoundingClientRect();
    return { x: e.clientX - r.left, y: e.clientY - r.top };
  }

  /** What is under (x, y): {tick} (its index), {row, band} (band: its index or -1), {row} (its label), or {}. */
  hit(x, y) {
    const tl = this.timeline, g = tl.geometry(), d = tl.data;
    if (!g || !d) return {};
    if (y >= rowsTop()) {
      const row = tl.rowAt(y);
      if (!row || x < LAYOUT.labelW) return { row };
      return { row, band: d.bandAt(row, tOf(g, x)) };
    }
    if (y >= LAYOUT.axisH && x >= LAYOUT.labelW) {
      const tick = d.tickNear(tOf(g, x), (TICK_HIT * (g.v1 - g.v0)) / (g.w - LAYOUT.labelW - LAYOUT.padR));
      if (tick >= 0) return { tick };
    }
    return {};
  }

  down(e) {
    const tl = this.timeline;
    const g = tl.geometry();
    if (e.button !== 0 || !g) return;
    tl.body.focus({ preventScroll: true });
    const { x, y } = this.local(e);
    if (x < LAYOUT.labelW) {
      const row = tl.rowAt(y);
      if (row) tl.selectRow(row.path === tl.selected ? null : row.path);
      return;
    }
    tl.canvas.setPointerCapture(e.pointerId);
    if (e.shiftKey) {
      this.drag = { mode: "range", x0: x };
      tl.rangeSel = [tOf(g, x), tOf(g, x)];
    } else {
      this.drag = { mode: y < LAYOUT.axisH ? "scrub" : "press", x0: x };
      if (this.drag.mode === "scrub") tl.scrub(tOf(g, x));
    }
  }

  move(e) {
    const { x, y } = this.local(e);
    const { drag, timeline: tl } = this;
    const g = tl.geometry();
    if (!drag) this.hover(x, y);
    if (!drag || !g) return;
    if (drag.mode === "press" && Math.abs(x - drag.x0) > CLICK_SLOP) drag.mode = "scrub";
    if (drag.mode === "scrub") tl.scrub(tOf(g, x));
    else if (drag.mode === "range") {
      tl.rangeSel[1] = tOf(g, x);
      tl.queue();
    }
  }

  up(e) {
    const { drag, timeline: tl } = this;
    if (!drag) return;
    this.drag = null;
    const { x, y } = this.local(e);
    if (drag.mode === "press") this.click(x, y);
    else if (drag.mode === "scrub") tl.flushSeek();
    else {
      const [a, b] = tl.rangeSel;
      tl.rangeSel = null;
      if (Math.abs(x - drag.x0) > CLICK_SLOP) tl.zoomTo([Math.min(a, b), Math.max(a, b)]);
      tl.queue();
    }
  }

  cancel() {
    const tl = this.timeline;
    if (this.drag?.mode === "scrub") tl.flushSeek();
    this.drag = null;
    tl.rangeSel = null;
    tl.queue();
  }

  /** A click on a tick seeks its event, on a band its first event, elsewhere the time under it. */
  click(x, y) {
    const tl = this.timeline, d = tl.data;
    const { tick, row, band } = this.hit(x, y);
    if (tick !== undefined) tl.seekSeq(d.ticks.seq[tick], d.ticks.t[tick]);
    else if (row && band >= 0 && row.label[band] !== NO_LABEL) tl.seekSeq(row.seq[band], row.t0[band]);
    else {
      tl.scrub(tOf(tl.geometry(), x));
      tl.flushSeek();
    }
  }

  hover(x, y) {
    const { tick, row, band } = this.hit(x, y);
    const d = this.timeline.data;
    let title = "", cursor = x >= LAYOUT.labelW ? "col-resize" : "default";
    if (tick !== undefined) [title, cursor] = [d.ticks.text[tick], "pointer"];
    else if (row && band >= 0 && row.label[band] !== NO_LABEL) {
      const label = row.label[band] < 0 ? "many states" : d.labels[row.label[band]];
      [title, cursor] = [`${row.path}: ${label} from ${clockText(row.t0[band])} (seq ${row.seq[band]})`, "pointer"];
    } else if (row) [title, cursor] = [row.path, x < LAYOUT.labelW ? "pointer" : cursor];
    this.timeline.canvas.title = title;
    this.timeline.canvas.style.cursor = cursor;
  }

  wheel(e) {
    const tl = this.timeline;
    const { x } = this.local(e);
    const g = tl.geometry();
    if (x < LAYOUT.labelW || !g) return; // over the labels the rows scroll
    e.preventDefault();
    const unit = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? g.h : 1;
    if (Math.abs(e.deltaX) > Math.abs(e.deltaY)) {
      const dt = (e.deltaX * unit * (g.v1 - g.v0)) / (g.w - LAYOUT.labelW - LAYOUT.padR);
      tl.zoomTo([g.v0 + dt, g.v1 + dt]);
    } else tl.zoom(Math.exp(e.deltaY * unit * 0.002), tOf(g, x));
  }
}
