// The timeline's toolbar and keyboard: play / pause, speed, step, start / end, zoom, "back to live", "copy link",
// and the line that says which instant is shown ("live" or "viewing the past: ..."). Buttons and keys
// call the same Timeline actions; the keys work anywhere in the page but in a text field.

import { h, setText } from "./dom.js";
import { clockText } from "./clocktext.js";

export const SPEEDS = [0.1, 0.25, 0.5, 1, 2, 5, 10];
export const ZOOM_STEP = 1.5;

const button = (text, title, cls) => h("button", { type: "button", text, title, class: cls });

/** How far back the server's history reaches (when not to seq 1) and from where its detail is whole. */
function keptText(first, keptFrom, historyFrom) {
  const reach = historyFrom !== null && historyFrom > first.seq ? `history reaches back to seq ${historyFrom}`
    : first.seq > 1 ? `history reaches back to ${clockText(first.t)} (seq ${first.seq})` : "";
  const coarse = keptFrom !== null && keptFrom > first.seq ? `full detail from seq ${keptFrom}` : "";
  return [reach, coarse].filter(Boolean).join("; ");
}

export class TimelineControls {
  /** @param {Timeline} timeline whose actions the buttons and keys call */
  constructor(timeline) {
    this.timeline = timeline;
    const tl = timeline;
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
      live: button("back to live", "Back to the live machine (End)", "tl-live"),
      copy: button("copy link", "Copy a link to this machine at the instant shown (it holds no token)", "tl-copy"),
      zoomOut: button("−", "Zoom out (-)"),
      zoomIn: button("+", "Zoom in (+)"),
      whole: button("whole run", "Show the whole run (double-click the timeline)"),
    };
    const e = this.el;
    e.live.hidden = true;
    this.bar = h("div", { class: "toolbar tl-bar" }, h("span", { class: "title", text: "Timeline" }),
      e.start, e.prev, e.play, e.next, e.end, e.speed, e.status, e.kept, e.live, e.copy, h("span", { class: "spacer" }),
      e.zoomOut, e.zoomIn, e.whole);
    e.play.addEventListener("click", () => tl.togglePlay());
    e.speed.addEventListener("change", () => tl.call("speed", Number(e.speed.value)));
    e.prev.addEventListener("click", () => tl.call("step", -1, null));
    e.next.addEventListener("click", () => tl.call("step", 1, null));
    e.start.addEventListener("click", () => tl.toStart());
    e.end.addEventListener("click", () => tl.toEnd());
    e.live.addEventListener("click", () => tl.call("live"));
    e.copy.addEventListener("click", () => tl.call("copyLink"));
    e.zoomIn.addEventListener("click", () => tl.zoom(1 / ZOOM_STEP));
    e.zoomOut.addEventListener("click", () => tl.zoom(ZOOM_STEP));
    e.whole.addEventListener("click", () => tl.wholeRun());
    this.onKey = (ev) => this.key(ev);
    document.addEventListener("keydown", this.onKey, { capture: true }); // before the page's +/- (graph zoom)
  }

  destroy() {
    document.removeEventListener("keydown", this.onKey, { capture: true });
  }

  /** Show the instant ({t, live, behind, playing}), whether the machine is live, and how far back `data` reaches. */
  show(instant, liveMachine, data) {
    const { t, live, behind, playing } = instant;
    const e = this.el;
    if (live) setText(e.status, "live");
    else if (t === null) setText(e.status, data && !data.first ? "no events yet" : "");
    else {
      const count = behind === null ? "" : `, ${behind} event${behind === 1 ? "" : "s"} behind`;
      setText(e.status, `viewing the past: ${clockText(t)}${count}`);
    }
    e.status.classList.toggle("past", !live && t !== null);
    setText(e.kept, data?.first ? keptText(data.first, data.keptFrom, data.historyFrom) : "");
    e.live.hidden = live || !liveMachine;
    setText(e.play, playing ? "❚❚" : "▶");
    e.play.title = playing ? "Pause (Space)" : "Play (Space)";
  }

  /** Show playback speed x in the select (added to its choices when it is none of them), without calling speed(). */
  showSpeed(x) {
    const select = this.el.speed;
    const value = String(x);
    if (![...select.options].some((o) => o.value === value)) {
      const after = [...select.options].find((o) => Number(o.value) > x);
      select.insertBefore(h("option", { value, text: `${x}x` }), after || null);
    }
    select.value = value;
  }

  /** The shortcuts: Space, ←/→ (Shift: the selected row's container), Home/End, +/- (over or in the timeline). */
  key(e) {
    const tl = this.timeline;
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    if (!tl.host.isConnected || tl.host.getClientRects().length === 0) return; // not shown
    const target = e.target instanceof Element ? e.target : null;
    if (target?.closest("input, textarea, select, dialog, [contenteditable]")) return;
    const dir = { ArrowLeft: -1, ArrowRight: 1 }[e.key];
    const zoom = { "+": 1 / ZOOM_STEP, "=": 1 / ZOOM_STEP, "-": ZOOM_STEP, _: ZOOM_STEP }[e.key];
    if (e.key === " " && !target?.closest("button")) tl.togglePlay();
    else if (dir) tl.call("step", dir, e.shiftKey ? tl.selected : null);
    else if (e.key === "Home") tl.toStart();
    else if (e.key === "End") tl.toEnd();
    else if (zoom && (tl.pointer.over || tl.host.contains(document.activeElement))) {
      e.stopPropagation(); // the timeline's zoom, not the graph's
      tl.zoom(zoom);
    } else return;
    e.preventDefault();
  }
}
