// The timeline under the dashboard (issue 9): the machine's run on one time axis, a band row per
// container, ticks for errors, preempts and controls, the playhead. The page owns the clock
// (static/timetravel.js) and fetches /timeline; this component draws what it is given and turns the
// user's drags, clicks, wheel, buttons and keys into the page's handlers. It draws in
// requestAnimationFrame only: a drag moves the playhead at once and asks the page for at most one
// seek per frame. Its parts: timeline_data.js (the answer as typed arrays), timeline_draw.js (a
// frame), timeline_pointer.js (the canvas's pointer), timeline_controls.js (toolbar and keys).

import { h } from "./dom.js";
import { TimelineData } from "./timeline_data.js";
import { LAYOUT, Painter, rowsTop } from "./timeline_draw.js";
import { TimelineControls } from "./timeline_controls.js";
import { TimelinePointer } from "./timeline_pointer.js";

export { SPEEDS } from "./timeline_controls.js";

const RANGE_DELAY = 150; // ms of quiet zooming before the page is asked for the zoomed range
const MIN_SPAN = 0.01; // s: the narrowest range shown

export class Timeline {
  /**
   * @param {HTMLElement} host the pane it fills (its children are replaced)
   * @param {object} handlers what the page does: seek({t} | {seq}), range({since_t, until_t}) (both null:
   *   the whole run), play(), pause(), speed(x), step(direction -1 | 1, level: a container path | null), live()
   */
  constructor(host, handlers) {
    this.host = host;
    this.handlers = handlers;
    this.data = null;
    this.zoomed = null; // [v0, v1] the user zoomed to, or null: the whole run
    this.instant = { seq: null, t: null, live: false, behind: null, playing: false };
    this.liveMachine = false;
    this.selected = null; // the container path of the selected row
    this.scrubT = null; // where the user put the playhead, until the page shows an instant
    this.pendingSeek = null; // a time to ask the page for at the next frame
    this.rangeSel = null; // [ta, tb] while shift-dragging
    this.rangeTimer = 0;
    this.queued = false;
    this.dpr = 0;
    this.canvas = h("canvas", { class: "tl-canvas" });
    this.sizer = h("div", { class: "tl-sizer" });
    this.body = h("div", { class: "tl-body", tabIndex: 0, "aria-label": "Timeline" }, this.canvas, this.sizer);
    this.controls = new TimelineControls(this);
    this.pointer = new TimelinePointer(this);
    host.replaceChildren(this.controls.bar, this.body);
    this.painter = new Painter(this.canvas.getContext("2d"));
    this.body.addEventListener("scroll", () => this.queue());
    this.observer = new ResizeObserver(() => this.resize());
    this.observer.observe(this.body);
    this.resize();
  }

  // ------------------------------------------------------------------ what the page gives

  /** The /timeline answer for the machine shown (the whole run, or the range last asked). */
  setData(resp) {
    this.data = new TimelineData(resp);
    if (this.selected && !this.data.rows.some((r) => r.path === this.selected)) this.selected = null;
    this.sizer.style.height = Math.max(0, this.contentHeight() - this.body.clientHeight) + "px";
    this.showText();
    this.queue();
  }

  /**
   * The instant shown: {seq, t, live, behind?: events after it, playing?, liveMachine?: the machine
   * streams live, so "back to live" shows while looking back (kept when not given; live implies it)}.
   */
  setInstant({ seq = null, t = null, live = false, behind = null, playing, liveMachine } = {}) {
    this.instant = { seq, t, live: Boolean(live), behind, playing: playing ?? this.instant.playing };
    if (liveMachine !== undefined) this.liveMachine = Boolean(liveMachine);
    else if (live) this.liveMachine = true;
    if (!this.pointer.drag) this.scrubT = null;
    this.showText();
    this.queue();
  }

  /** Show the playback speed (e.g. a replay's own) in the speed select; the page sets it on its clock. */
  showSpeed(x) {
    this.controls.showSpeed(x);
  }

  /** Stop listening to the document and the host's size. */
  destroy() {
    this.controls.destroy();
    this.observer.disconnect();
    clearTimeout(this.rangeTimer);
  }

  // ------------------------------------------------------------------ actions

  call(name, ...args) {
    this.handlers[name]?.(...args);
  }

  showText() {
    this.controls.show(this.instant, this.liveMachine, this.data);
  }

  togglePlay() {
    const playing = !this.instant.playing;
    this.instant.playing = playing;
    this.showText();
    this.call(playing ? "play" : "pause");
  }

  toStart() {
    if (this.data?.first) this.call("seek", { seq: Math.max(this.data.first.seq, this.data.historyFrom ?? 0) });
  }

  toEnd() {
    if (this.liveMachine) this.call("live");
    else if (this.data?.last) this.call("seek", { seq: this.data.last.seq });
  }

  /** Zoom by `factor` (< 1: in) around time `at` (default: the playhead if shown, else the middle). */
  zoom(factor, at = null) {
    const v = this.visible();
    if (!v) return;
    const [v0, v1] = v;
    const play = this.scrubT ?? this.instant.t;
    const centre = at ?? (play !== null && play >= v0 && play <= v1 ? play : (v0 + v1) / 2);
    const span = Math.max(MIN_SPAN, (v1 - v0) * factor);
    const a = centre - ((centre - v0) / (v1 - v0)) * span;
    this.zoomTo([a, a + span]);
  }

  /** Show [v0, v1] now; ask the page for its data once the zooming pauses. */
  zoomTo(v) {
    this.zoomed = v;
    this.queue();
    clearTimeout(this.rangeTimer);
    this.rangeTimer = setTimeout(() => this.call("range", { since_t: v[0], until_t: v[1] }), RANGE_DELAY);
  }

  /** Back to the whole run (the page fetches it again). */
  wholeRun() {
    clearTimeout(this.rangeTimer);
    this.zoomed = null;
    this.queue();
    this.call("range", { since_t: null, until_t: null });
  }

  /** Select a row (its container is the level of Shift+arrows), or none. */
  selectRow(path) {
    this.selected = path;
    this.queue();
  }

  /** Put the playhead at time t (within the run) now; the page is asked at the next frame. */
  scrub(t) {
    const d = this.data;
    if (d?.first && d.last) t = Math.min(Math.max(t, d.first.t), d.last.t);
    this.scrubT = t;
    this.pendingSeek = t;
    this.queue();
  }

  flushSeek() {
    if (this.pendingSeek === null) return;
    const t = this.pendingSeek;
    this.pendingSeek = null;
    this.call("seek", { t });
  }

  /** Seek event `seq` (at time t, where the playhead goes until the page answers). */
  seekSeq(seq, t) {
    this.scrubT = t;
    this.queue();
    this.call("seek", { seq });
  }

  // ------------------------------------------------------------------ geometry and frames

  contentHeight() {
    return rowsTop() + (this.data ? this.data.rows.length : 0) * LAYOUT.rowH;
  }

  /** The row at y (canvas px), or null. */
  rowAt(y) {
    const i = Math.floor((y - rowsTop() + this.body.scrollTop) / LAYOUT.rowH);
    return y >= rowsTop() && this.data && i >= 0 && i < this.data.rows.length ? this.data.rows[i] : null;
  }

  /** The visible range [v0, v1]: the zoom, or the whole run (up to the instant when live), or null. */
  visible() {
    if (this.zoomed) return this.zoomed;
    const d = this.data;
    if (!d?.first || !d.last) return null;
    const v0 = d.first.t;
    const v1 = this.instant.live && this.instant.t !== null ? Math.max(d.last.t, this.instant.t) : d.last.t;
    return v1 - v0 < MIN_SPAN ? [v0 - 0.5, v0 + 0.5] : [v0, v1];
  }

  /** A frame's geometry and marks (timeline_draw.js Painter.frame), or null when there is no range. */
  geometry() {
    const v = this.visible();
    if (!v) return null;
    const { live, t } = this.instant, last = this.data?.last;
    return {
      w: this.body.clientWidth, h: this.body.clientHeight, v0: v[0], v1: v[1], scrollTop: this.body.scrollTop,
      selected: this.selected, range: this.rangeSel,
      playT: this.scrubT ?? (live ? null : t),
      liveT: this.liveMachine && last ? Math.max(last.t, live && t !== null ? t : last.t) : null,
    };
  }

  resize() {
    const w = this.body.clientWidth, hgt = this.body.clientHeight;
    this.dpr = window.devicePixelRatio || 1;
    this.canvas.style.width = w + "px";
    this.canvas.style.height = hgt + "px";
    this.canvas.width = Math.round(w * this.dpr);
    this.canvas.height = Math.round(hgt * this.dpr);
    this.sizer.style.height = Math.max(0, this.contentHeight() - hgt) + "px";
    this.draw();
  }

  /** Draw at the next animation frame (once, however often asked); a pending seek goes first. */
  queue() {
    if (this.queued) return;
    this.queued = true;
    requestAnimationFrame(() => {
      this.queued = false;
      this.flushSeek();
      this.draw();
    });
  }

  /** Draw one frame now. */
  draw() {
    if ((window.devicePixelRatio || 1) !== this.dpr) return this.resize();
    this.canvas.getContext("2d").setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    const g = this.geometry() || { w: this.body.clientWidth, h: this.body.clientHeight, v0: 0, v1: 0 };
    this.painter.frame(g, this.data);
  }
}
