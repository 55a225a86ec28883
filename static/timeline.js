// The timeline under the dashboard (issue 9): the machine's run on one time axis, a band row per
// container, ticks for errors, preempts and controls, the playhead. The page owns the clock
// (static/timetravel.js) and fetches /timeline; this component draws what it is given and turns
// drags, clicks, the wheel, its buttons and the keyboard into the page's handlers. It redraws in
// requestAnimationFrame only, so a drag moves the playhead at once and asks the page for at most
// one seek per frame. Data: timeline_data.js; drawing: timeline_draw.js.

import { h } from "./dom.js";
import { NO_LABEL, TimelineData } from "./timeline_data.js";
import { LAYOUT, Painter, clockText, rowsTop, tOf } from "./timeline_draw.js";

export const SPEEDS = [0.1, 0.25, 0.5, 1, 2, 5, 10];
const CLICK_SLOP = 3; // px a press may move and still be a click
const TICK_HIT = 4; // px either side of a tick
const ZOOM_STEP = 1.5;
const RANGE_DELAY = 150; // ms of quiet wheel before the page is asked for the zoomed range
const MIN_SPAN = 0.01; // s: the narrowest zoom

const button = (text, title, cls) => h("button", { type: "button", text, title, class: cls });

export class Timeline {
  /**
   * @param {HTMLElement} host the pane it fills (its children are replaced)
   * @param {object} handlers what the page does: seek({t} | {seq}), range({since_t, until_t}) (null, null:
   *   the whole run), play(), pause(), speed(x), step(direction -1 | 1, level: container path | null), live()
   */
  constructor(host, handlers) {
    this.host = host;
    this.handlers = handlers;
    this.data = null;
    this.zoomed = null; // [v0, v1] the user zoomed to, or null: the whole run
    this.instant = { seq: null, t: null, live: false, behind: null, playing: false };
    this.liveMachine = false;
    this.selected = null; // the container path of the selected row
    this.drag = null; // {mode: "press" | "scrub" | "range", x0, y0}
    this.scrubT = null; // the playhead the user dragged to, until the page shows an instant
    this.pendingSeek = null; // a time to seek to at the next frame
    this.rangeSel = null; // [ta, tb] while shift-dragging
    this.rangeTimer = 0;
    this.hovered = false;
    this.queued = false;
    this.dpr = 0;
    this._build();
    this.painter = new Painter(this.canvas.getContext("2d"));
    this._bind();
    this.resize();
  }

  // ------------------------------------------------------------------ what the page gives

  /** The /timeline answer for the machine shown (the whole run or the range last asked). */
  setData(resp) {
    this.data = new TimelineData(resp);
    if (this.selected && !this.data.rows.some((r) => r.path === this.selected)) this.selected = null;
    this.sizer.style.height = Math.max(0, this._contentHeight() - this.body.clientHeight) + "px";
    this._showText();
    this.queue();
  }

  /**
   * The instant shown: {seq, t, live, behind?: events after it, playing?, liveMachine?: the machine
   * streams live (then "back to live" shows while looking back; kept when not given)}.
   */
  setInstant({ seq = null, t = null, live = false, behind = null, playing, liveMachine } = {}) {
    this.instant = { seq, t, live: Boolean(live), behind, playing: playing ?? this.instant.playing };
    if (liveMachine !== undefined) this.liveMachine = Boolean(liveMachine);
    else if (live) this.liveMachine = true;
    if (!this.drag) this.scrubT = null;
    this._showText();
    this.queue();
  }

  /** Stop listening to the document (the host's elements go with the host). */
  destroy() {
    document.removeEventListener("keydown", this._onKey, { capture: true });
    this.observer.disconnect();
    clearTimeout(this.rangeTimer);
  }

  // ------------------------------------------------------------------ the page's elements

  _build() {
    this.el = {
      play: button("▶", "Play (Space)", "tl-play"),
      speed: h("select", { title: "Playback speed" },
        ...SPEEDS.map((x) => h("option", { value: String(x), text: `${x}x`, selected: x === 1 }))),
      start: button("⇤", "Start of the run (Home)"),
      prev: button("◂", "Previous transition (←); of the selected row's container: Shift+←"),
      next: button("▸", "Next transition (→); of the selected row's container: Shift+→"),
      end: button("⇥", "End of the run (End)"),
      status: h("span", { class: "tl-status" }),
      kept: h("span", { class: "tl-kept muted" }),
      zoomOut: button("−", "Zoom out (-)"),
      zoomIn: button("+", "Zoom in (+)"),
      whole: button("whole run", "Show the whole run (double-click the timeline)"),
      live: button("back to live", "Back to the live machine (End)", "tl-live"),
    };
    const e = this.el;
    e.live.hidden = true;
    this.canvas = h("canvas", { class: "tl-canvas" });
    this.sizer = h("div", { class: "tl-sizer" });
    this.body = h("div", { class: "tl-body", tabIndex: 0, "aria-label": "Timeline" }, this.canvas, this.sizer);
    const bar = h("div", { class: "toolbar tl-bar" }, h("span", { class: "title", text: "Timeline" }),
      e.start, e.prev, e.play, e.next, e.end, e.speed, e.status, e.kept, e.live, h("span", { class: "spacer" }),
      e.zoomOut, e.zoomIn, e.whole);
    this.host.replaceChildren(bar, this.body);
  }

  _bind() {
    const e = this.el;
    e.play.addEventListener("click", () => this.togglePlay());
    e.speed.addEventListener("change", () => this._call("speed", Number(e.speed.value)));
    e.prev.addEventListener("click", () => this._call("step", -1, null));
    e.next.addEventListener("click", () => this._call("step", 1, null));
    e.start.addEventListener("click", () => this.toStart());
    e.end.addEventListener("click", () => this.toEnd());
    e.live.addEventListener("click", () => this._call("live"));
    e.zoomIn.addEventListener("click", () => this.zoom(1 / ZOOM_STEP));
    e.zoomOut.addEventListener("click", () => this.zoom(ZOOM_STEP));
    e.whole.addEventListener("click", () => this.wholeRun());
    const c = this.canvas;
    c.addEventListener("pointerdown", (ev) => this._down(ev));
    c.addEventListener("pointermove", (ev) => this._move(ev));
    c.addEventListener("pointerup", (ev) => this._up(ev));
    c.addEventListener("pointercancel", () => this._cancel());
    c.addEventListener("pointerenter", () => { this.hovered = true; });
    c.addEventListener("pointerleave", () => { this.hovered = false; });
    c.addEventListener("dblclick", () => this.wholeRun());
    c.addEventListener("wheel", (ev) => this._wheel(ev), { passive: false });
    this.body.addEventListener("scroll", () => this.queue());
    this.observer = new ResizeObserver(() => this.resize());
    this.observer.observe(this.body);
    this._onKey = (ev) => this._key(ev);
    document.addEventListener("keydown", this._onKey, { capture: true }); // before the page's +/- (graph zoom)
  }

  _call(name, ...args) {
    this.handlers[name]?.(...args);
  }

  _showText() {
    const { t, live, behind, playing } = this.instant;
    const s = this.el.status;
    if (live) s.textContent = "live";
    else if (t === null) s.textContent = this.data && !this.data.first ? "no events yet" : "";
    else s.textContent = `viewing the past: ${clockText(t)}` + (behind === null ? "" : `, ${behind} event${behind === 1 ? "" : "s"} behind`);
    s.classList.toggle("past", !live && t !== null);
    const d = this.data;
    const bounded = d && d.keptFrom !== null && d.keptFrom > 1;
    const from = bounded && d.first && d.first.seq === d.keptFrom ? ` (${clockText(d.first.t)})` : "";
    this.el.kept.textContent = bounded ? `history reaches back to seq ${d.keptFrom}${from}` : "";
    this.el.live.hidden = live || !this.liveMachine;
    this.el.play.textContent = playing ? "❚❚" : "▶";
    this.el.play.title = playing ? "Pause (Space)" : "Play (Space)";
  }

  // ------------------------------------------------------------------ actions (buttons, keys)

  togglePlay() {
    const playing = !this.instant.playing;
    this.instant.playing = playing;
    this._showText();
    this._call(playing ? "play" : "pause");
  }

  toStart() {
    if (this.data?.first) this._call("seek", { seq: this.data.first.seq });
  }

  toEnd() {
    if (this.liveMachine) this._call("live");
    else if (this.data?.last) this._call("seek", { seq: this.data.last.seq });
  }

  /** Zoom the visible range by `factor` (< 1: in) around time `at` (default: the playhead, else the middle). */
  zoom(factor, at = null) {
    const v = this._range();
    if (!v) return;
    const [v0, v1] = v;
    const play = this.scrubT ?? this.instant.t;
    const centre = at ?? (play !== null && play >= v0 && play <= v1 ? play : (v0 + v1) / 2);
    const span = Math.max(MIN_SPAN, (v1 - v0) * factor);
    const a = centre - ((centre - v0) / (v1 - v0)) * span;
    this._zoomTo([a, a + span]);
  }

  /** Back to the whole run (the page fetches it again). */
  wholeRun() {
    clearTimeout(this.rangeTimer);
    this.zoomed = null;
    this.queue();
    this._call("range", { since_t: null, until_t: null });
  }

  _zoomTo(v) {
    this.zoomed = v;
    this.queue();
    clearTimeout(this.rangeTimer);
    this.rangeTimer = setTimeout(() => this._call("range", { since_t: v[0], until_t: v[1] }), RANGE_DELAY);
  }

  _key(e) {
    if (e.defaultPrevented || e.ctrlKey || e.metaKey || e.altKey) return;
    if (!this.host.isConnected || this.host.getClientRects().length === 0) return; // not shown
    const target = e.target instanceof Element ? e.target : null;
    if (target?.closest("input, textarea, select, dialog, [contenteditable]")) return;
    const dir = { ArrowLeft: -1, ArrowRight: 1 }[e.key];
    const zoom = { "+": 1 / ZOOM_STEP, "=": 1 / ZOOM_STEP, "-": ZOOM_STEP, _: ZOOM_STEP }[e.key];
    if (e.key === " " && !target?.closest("button")) this.togglePlay();
    else if (dir) this._call("step", dir, e.shiftKey ? this.selected : null);
    else if (e.key === "Home") this.toStart();
    else if (e.key === "End") this.toEnd();
    else if (zoom && (this.hovered || this.host.contains(document.activeElement))) {
      e.stopPropagation(); // the timeline's zoom, not the graph's
      this.zoom(zoom);
    } else return;
    e.preventDefault();
  }

  // ------------------------------------------------------------------ pointer

  _local(e) {
    const r = this.canvas.getBoundingClientRect();
    return { x: e.clientX - r.left, y: e.clientY - r.top };
  }

  _rowAt(y) {
    const i = Math.floor((y - rowsTop() + this.body.scrollTop) / LAYOUT.rowH);
    return y >= rowsTop() && this.data && i >= 0 && i < this.data.rows.length ? this.data.rows[i] : null;
  }

  /** What is under (x, y): {tick} (an index), {row, band}, {row} (its label), or {} (the axis, nothing). */
  _hit(x, y) {
    const g = this._geometry();
    if (!g || !this.data) return {};
    if (y >= rowsTop()) {
      const row = this._rowAt(y);
      if (!row || x < LAYOUT.labelW) return { row };
      return { row, band: this.data.bandAt(row, tOf(g, x)) };
    }
    if (y >= LAYOUT.axisH && x >= LAYOUT.labelW) {
      const tolerance = (TICK_HIT * (g.v1 - g.v0)) / (g.w - LAYOUT.labelW - LAYOUT.padR);
      const tick = this.data.tickNear(tOf(g, x), tolerance);
      if (tick >= 0) return { tick };
    }
    return {};
  }

  _down(e) {
    if (e.button !== 0) return;
    this.body.focus({ preventScroll: true });
    const g = this._geometry();
    const { x, y } = this._local(e);
    if (!g) return;
    if (x < LAYOUT.labelW) {
      const row = this._rowAt(y);
      if (row) this.selectRow(row.path === this.selected ? null : row.path);
      return;
    }
    this.canvas.setPointerCapture(e.pointerId);
    const t = tOf(g, x);
    if (e.shiftKey) {
      this.drag = { mode: "range", x0: x };
      this.rangeSel = [t, t];
    } else {
      this.drag = { mode: y < LAYOUT.axisH ? "scrub" : "press", x0: x, y0: y };
      if (this.drag.mode === "scrub") this._scrub(t);
    }
  }

  _move(e) {
    const { x, y } = this._local(e);
    const g = this._geometry();
    if (!this.drag) {
      this._hover(x, y);
      return;
    }
    if (!g) return;
    const { drag } = this;
    if (drag.mode === "press" && Math.abs(x - drag.x0) > CLICK_SLOP) drag.mode = "scrub";
    if (drag.mode === "scrub") this._scrub(tOf(g, x));
    else if (drag.mode === "range") {
      this.rangeSel[1] = tOf(g, x);
      this.queue();
    }
  }

  _up(e) {
    const { drag } = this;
    if (!drag) return;
    this.drag = null;
    const { x, y } = this._local(e);
    if (drag.mode === "press") this._click(x, y);
    else if (drag.mode === "scrub") this._flushSeek();
    else if (drag.mode === "range") {
      const [a, b] = this.rangeSel;
      this.rangeSel = null;
      if (Math.abs(x - drag.x0) > CLICK_SLOP) this._zoomTo([Math.min(a, b), Math.max(a, b)]);
      this.queue();
    }
  }

  _cancel() {
    if (this.drag?.mode === "scrub") this._flushSeek();
    this.drag = null;
    this.rangeSel = null;
    this.queue();
  }

  /** A click on a tick seeks its event, on a band its first event, elsewhere the time under it. */
  _click(x, y) {
    const g = this._geometry();
    const { tick, row, band } = this._hit(x, y);
    const d = this.data;
    if (tick !== undefined) this._seekSeq(d.ticks.seq[tick], d.ticks.t[tick]);
    else if (row && band >= 0 && row.label[band] !== NO_LABEL) this._seekSeq(row.seq[band], row.t0[band]);
    else {
      this._scrub(tOf(g, x));
      this._flushSeek();
    }
  }

  _seekSeq(seq, t) {
    this.scrubT = t;
    this.queue();
    this._call("seek", { seq });
  }

  _scrub(t) {
    const d = this.data;
    if (d?.first && d.last) t = Math.min(Math.max(t, d.first.t), d.last.t);
    this.scrubT = t;
    this.pendingSeek = t;
    this.queue();
  }

  _flushSeek() {
    if (this.pendingSeek === null) return;
    const t = this.pendingSeek;
    this.pendingSeek = null;
    this._call("seek", { t });
  }

  _hover(x, y) {
    const { tick, row, band } = this._hit(x, y);
    const d = this.data;
    let title = "", cursor = "default";
    if (tick !== undefined) [title, cursor] = [d.ticks.text[tick], "pointer"];
    else if (row && band >= 0 && row.label[band] !== NO_LABEL) {
      const label = row.label[band] < 0 ? "many states" : d.labels[row.label[band]];
      title = `${row.path}: ${label} from ${clockText(row.t0[band])} (seq ${row.seq[band]})`;
      cursor = "pointer";
    } else if (row) [title, cursor] = [row.path, x < LAYOUT.labelW ? "pointer" : "col-resize"];
    else if (x >= LAYOUT.labelW) cursor = "col-resize";
    this.canvas.title = title;
    this.canvas.style.cursor = cursor;
  }

  _wheel(e) {
    const { x } = this._local(e);
    const g = this._geometry();
    if (x < LAYOUT.labelW || !g) return; // over the labels the rows scroll
    e.preventDefault();
    const unit = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? g.h : 1;
    if (Math.abs(e.deltaX) > Math.abs(e.deltaY)) {
      const dt = (e.deltaX * unit * (g.v1 - g.v0)) / (g.w - LAYOUT.labelW - LAYOUT.padR);
      this._zoomTo([g.v0 + dt, g.v1 + dt]);
    } else this.zoom(Math.exp(e.deltaY * unit * 0.002), tOf(g, x));
  }

  /** Select a row (its container is the level of Shift+arrows), or none. */
  selectRow(path) {
    this.selected = path;
    this.queue();
  }

  // ------------------------------------------------------------------ frames

  _contentHeight() {
    return rowsTop() + (this.data ? this.data.rows.length : 0) * LAYOUT.rowH;
  }

  /** The visible range [v0, v1]: the zoom, or the whole run (up to the instant when live), or null. */
  _range() {
    if (this.zoomed) return this.zoomed;
    const d = this.data;
    if (!d?.first || !d.last) return null;
    let [v0, v1] = [d.first.t, d.last.t];
    if (this.instant.live && this.instant.t !== null) v1 = Math.max(v1, this.instant.t);
    return v1 - v0 < MIN_SPAN ? [v0 - 0.5, v0 + 0.5] : [v0, v1];
  }

  _geometry() {
    const v = this._range();
    if (!v) return null;
    const w = this.body.clientWidth, hgt = this.body.clientHeight;
    const d = this.data;
    const liveT = this.liveMachine && d?.last ? Math.max(d.last.t, this.instant.live ? this.instant.t ?? 0 : 0) : null;
    const playT = this.scrubT ?? (this.instant.live ? null : this.instant.t);
    return { w, h: hgt, v0: v[0], v1: v[1], scrollTop: this.body.scrollTop, selected: this.selected,
      playT, liveT, range: this.rangeSel };
  }

  resize() {
    const w = this.body.clientWidth, hgt = this.body.clientHeight;
    this.dpr = window.devicePixelRatio || 1;
    this.canvas.style.width = w + "px";
    this.canvas.style.height = hgt + "px";
    this.canvas.width = Math.round(w * this.dpr);
    this.canvas.height = Math.round(hgt * this.dpr);
    this.sizer.style.height = Math.max(0, this._contentHeight() - hgt) + "px";
    this.draw();
  }

  /** Redraw at the next animation frame (once, however often asked). */
  queue() {
    if (this.queued) return;
    this.queued = true;
    requestAnimationFrame(() => {
      this.queued = false;
      this._flushSeek();
      this.draw();
    });
  }

  /** Draw one frame now. */
  draw() {
    if ((window.devicePixelRatio || 1) !== this.dpr) return this.resize();
    const ctx = this.canvas.getContext("2d");
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    const g = this._geometry() || { w: this.body.clientWidth, h: this.body.clientHeight, v0: 0, v1: 0 };
    this.painter.frame(g, this.data);
  }
}
