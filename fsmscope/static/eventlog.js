// The event log: every event as SMACH's line (transcript.js), filtered by kind and text.
// Every name, value and message goes in as text (createElement + textContent), never as HTML.

import { clockText } from "./clocktext.js";
import { h } from "./dom.js";
import { followUserScrolls } from "./log_follow.js";
import { KINDS } from "./schema.js";
import { Transcript } from "./transcript.js";

const MAX_EVENTS = 5000;
const MAX_ROWS = 800; // at least; up to MAX_ROWS + BLOCK_ROWS
// Rows are kept in blocks of this many: adding a row lays out its block only, the oldest rows go a
// block at a time (dropping rows one by one at the top moved and repainted every row at each frame),
// and a block out of view is neither laid out nor painted (style.css).
const BLOCK_ROWS = 100;
// Under a flood only the newest rows of each frame are drawn (about what the pane shows), after a
// line that says how many were not: a row costs the page about 0.4 ms of layout, and 120 a frame were
// half of a 600-state machine's frame at 1,000 events/s (bench/big_machine_browser.py).
const MAX_ROWS_PER_FRAME = 40;
const HIDDEN_AT_FIRST = new Set(["pose"]); // 30 a second: shown only when asked for

function selectionOf(ev) {
  const path = ev.path;
  if (ev.kind === "transition") return path + "/" + (ev.to ?? ev.from);
  if (ev.kind === "start" && ev.active?.length === 1) return path + "/" + ev.active[0];
  if (ev.kind === "error" && ev.state) return path + "/" + ev.state;
  return path;
}

/** The words of an event the text filter searches besides its transcript line: the states and outcomes it names. */
function searchedWords(ev) {
  const words = [ev.kind, ev.path, ev.from, ev.to, ev.state, ev.outcome, ev.state_outcome,
    ...[].concat(ev.active ?? [], ev.last ?? []), ...Object.entries(ev.outcomes ?? {}).flat()];
  return words.filter((w) => typeof w === "string");
}

/** An event's transcript `line` and the text the filter searches for it. */
function described(ev, line) {
  return { line, text: [...searchedWords(ev), line.text].join("\n").toLowerCase() };
}

/** The kinds the log shows: a checkbox per kind in a <details> popover, closed by Escape or a click elsewhere. */
class KindFilter {
  constructor(details, changed) {
    this.summary = details.querySelector("summary");
    this.boxes = KINDS.map((kind) => h("input", { type: "checkbox", value: kind, checked: !HIDDEN_AT_FIRST.has(kind) }));
    details.querySelector(".kinds-actions").before(...this.boxes.map((box) => h("label", {}, box, " " + box.value)));
    this._read();
    const update = () => {
      this._read();
      changed();
    };
    details.addEventListener("change", update);
    details.addEventListener("click", (e) => {
      const button = e.target.closest("button[data-check]");
      if (!button) return;
      for (const box of this.boxes) box.checked = button.dataset.check === "all";
      update();
    });
    details.addEventListener("keydown", (e) => {
      if (e.key !== "Escape" || !details.open) return;
      details.open = false;
      this.summary.focus();
    });
    document.addEventListener("click", (e) => {
      if (!details.contains(e.target)) details.open = false;
    });
  }

  _read() {
    this.hidden = new Set(this.boxes.filter((b) => !b.checked).map((b) => b.value)); // the kinds not shown
    const shown = this.boxes.length - this.hidden.size;
    const asAtFirst = this.hidden.size === HIDDEN_AT_FIRST.size && [...HIDDEN_AT_FIRST].every((k) => this.hidden.has(k));
    this.summary.textContent = !this.hidden.size ? "all kinds" : asAtFirst ? `all kinds but ${[...HIDDEN_AT_FIRST].join(", ")}`
      : shown ? `${shown} of ${this.boxes.length} kinds` : "no kinds";
  }
}

/** The event log, filtered by kinds and by text; clicking a row selects the state it is about and
 * jumps to its event. Looking back, it shows the events around the instant instead of the newest. */
export class EventLog {
  constructor(host, controls, handlers) {
    this.host = host;
    // {kinds: <details> of checkboxes, text: input, count: element, clear: button, partial: the note on a history cut short}
    this.controls = controls;
    this.handlers = handlers;
    this.events = [];
    this.shown = 0; // how many of this.events pass the filters
    this.pending = []; // events not drawn yet
    this.undrawn = 0; // events the filters show that a flood left out of the rows since the last flush
    this.rowCount = 0; // rows drawn
    this.described = new WeakMap(); // event -> {line, text}: its transcript line and the text the filter searches
    this.needle = ""; // the text filter, lower case
    this.stick = true; // follow the newest row (false once the user scrolls up)
    this.scrollDue = false; // rows were drawn while following: followNewest() scrolls to them
    followUserScrolls(host, (stick) => { this.stick = stick; });
    this.nodeOf = () => undefined;
    this.transcript = new Transcript((path) => this.nodeOf(path)); // fed every event in order
    this.selectedRow = null;
    this.past = null; // {events, seq}: the window around the instant shown, when looking back
    this.frozen = false; // looking back: the newest events are kept, not drawn
    this.kinds = new KindFilter(controls.kinds, () => this.redraw());
    controls.text.addEventListener("input", () => this.redraw());
    controls.clear.addEventListener("click", () => this.reset());
    host.addEventListener("click", (e) => {
      const row = e.target.closest(".log-row");
      if (!row) return;
      this.selectedRow?.classList.remove("selected");
      row.classList.add("selected");
      this.selectedRow = row;
      this.handlers.select(row.dataset.select, Number(row.dataset.seq));
    });
  }

  reset() {
    this.events = [];
    this.transcript = new Transcript((path) => this.nodeOf(path));
    this.controls.partial.hidden = true;
    this.redraw();
  }

  /** A new connection's history: the current run's events up to its snapshot; `complete` false when
   * the server no longer keeps the run's earliest events. */
  history({ complete, events }) {
    this.add(events);
    this.redraw(this.stick); // all its rows at once, not only the newest of one frame; a log the user
    // scrolled away from its end (a resynchronisation after missed events) stays there
    const note = this.controls.partial;
    note.hidden = complete;
    if (!complete) {
      const from = events.length ? ` (the log starts at event ${events[0].seq})` : "";
      note.textContent = `Earlier events of this run are not kept by the server${from}.`;
    }
  }

  /** An event's transcript line and the text the filter searches, worked out as it arrives: a line
   * can depend on the events before it (no "Concurrent Outcomes" after a serviced preempt). */
  _describe(ev) {
    let d = this.described.get(ev);
    if (!d) {
      d = described(ev, this.transcript.row(ev));
      this.described.set(ev, d);
    }
    return d;
  }

  _matches(ev) {
    return !this.kinds.hidden.has(ev.kind) && (!this.needle || this._describe(ev).text.includes(this.needle));
  }

  _row(ev) {
    const line = this._describe(ev).line;
    return h("div", { class: `log-row kind-${ev.kind} level-${line.level}`, "data-select": selectionOf(ev), "data-seq": String(ev.seq) },
      h("span", { class: "seq", text: String(ev.seq) }),
      h("span", { class: "time", text: clockText(ev.t) }),
      h("span", { class: "kind", text: ev.kind }),
      h("span", { class: "path", title: ev.path }, h("bdi", { text: ev.path })),
      h("span", { class: "msg", text: line.text, title: ev.kind === "error" && ev.traceback ? ev.traceback : line.text }));
  }

  /** Keep events; their rows are drawn by the next flush() (once per animation frame, however fast they come). */
  add(events) {
    for (const ev of events) {
      this._describe(ev);
      this.events.push(ev);
      if (this._matches(ev)) this.shown += 1;
    }
    const dropped = this.events.length > MAX_EVENTS ? this.events.splice(0, this.events.length - MAX_EVENTS) : [];
    for (const ev of dropped) if (this._matches(ev)) this.shown -= 1;
    for (const ev of events) this.pending.push(ev);
    if (this.pending.length > 4 * MAX_ROWS_PER_FRAME) {
      const left = this.pending.splice(0, this.pending.length - MAX_ROWS_PER_FRAME);
      this.undrawn += left.filter((ev) => this._matches(ev)).length;
    }
  }

  flush() {
    if (!this.pending.length || this.frozen) return;
    const events = this.pending;
    this.pending = [];
    const stick = this.stick;
    const matching = events.filter((ev) => this._matches(ev));
    const fresh = matching.slice(-MAX_ROWS_PER_FRAME).map((ev) => this._row(ev));
    const undrawn = this.undrawn + matching.length - fresh.length;
    this.undrawn = 0;
    if (undrawn) {
      fresh.unshift(h("div", { class: "log-gap",
        text: `… ${undrawn} events not drawn: they came faster than the page draws (time travel has every one)` }));
    }
    if (fresh.length) {
      this.host.querySelector(".empty")?.remove();
      this._append(fresh);
      for (let first = this.host.firstElementChild; this.rowCount - first.childElementCount >= MAX_ROWS;
        first = this.host.firstElementChild) {
        this.rowCount -= first.childElementCount;
        first.remove();
      }
    }
    this._count();
    this.scrollDue = stick;
  }

  /** After the frame's other writes (a flush, then the userdata): to the newest row when the log
   * follows it. Reading the log's height lays the page out, once for all of them. */
  followNewest() {
    if (!this.scrollDue) return;
    this.scrollDue = false;
    this.host.scrollTop = this.host.scrollHeight;
  }

  /** Looking back: show `past` ({events, seq}, the events around the instant seq), the instant's
   * row marked and scrolled to, later rows greyed; null: back to the newest events. */
  showPast(past) {
    const wasFrozen = this.frozen;
    this.frozen = past !== null;
    if (past === this.past && wasFrozen === this.frozen) return;
    this.past = past;
    this.redraw();
  }

  /** Looking back, before the window around the instant has come: keep the rows as they are. */
  freeze() {
    this.frozen = true;
  }

  /** Draw again from the kept events, or the window looked back at (the filters or the events changed);
   * live, following the newest row unless `follow` is false. */
  redraw(follow = true) {
    this.pending = [];
    this.needle = this.controls.text.value.trim().toLowerCase();
    if (this.past) {
      this._drawPast();
      return;
    }
    const matching = this.events.filter((ev) => this._matches(ev));
    this.shown = matching.length;
    const rows = matching.slice(-MAX_ROWS).map((ev) => this._row(ev));
    this._show(rows, "No events.");
    this._count();
    this.stick = follow;
    // To the newest row when the page is next laid out anyway (now would lay it all out once more),
    // and again at the frame after, when the rows then in view have their real heights (style.css).
    const toNewest = () => {
      if (this.stick && !this.past) this.host.scrollTop = this.host.scrollHeight;
    };
    requestAnimationFrame(() => {
      toNewest();
      requestAnimationFrame(toNewest);
    });
  }

  _drawPast() {
    const { events, seq } = this.past;
    const transcript = new Transcript((path) => this.nodeOf(path)); // the window's own lines, in order
    const rows = [];
    let at = null;
    for (const ev of events) {
      this.described.set(ev, described(ev, transcript.row(ev)));
      if (!this._matches(ev)) continue;
      const row = this._row(ev);
      if (ev.seq > seq) row.classList.add("later");
      else at = row;
      rows.push(row);
    }
    at?.classList.add("at");
    this._show(rows, "No events here.");
    this.controls.count.textContent = `event ${seq}`;
    this.stick = false;
    if (at) {
      this._centre(at);
      // The rows now in view get their real heights at the next frame (those out of view are
      // estimated, style.css): centre again then, unless the user scrolled meanwhile.
      const scrolled = this.host.scrollTop;
      requestAnimationFrame(() => {
        if (at.isConnected && this.host.scrollTop === scrolled) this._centre(at);
      });
    }
  }

  /** Show exactly `rows` (in blocks), or `empty` when there are none. */
  _show(rows, empty) {
    this.host.replaceChildren();
    this.rowCount = 0;
    this.selectedRow = null;
    if (rows.length) this._append(rows);
    else this.host.append(h("p", { class: "empty", text: empty }));
  }

  /** Add rows after the last, filling the last block before starting another. */
  _append(rows) {
    let block = this.host.lastElementChild;
    for (let i = 0; i < rows.length;) {
      if (!block?.classList.contains("log-block") || block.childElementCount >= BLOCK_ROWS) {
        block = this.host.appendChild(h("div", { class: "log-block" }));
      }
      const room = BLOCK_ROWS - block.childElementCount;
      block.append(...rows.slice(i, i + room));
      i += room;
    }
    this.rowCount += rows.length;
  }

  /** Scroll the log (and not the page around it) so that `row` is in its middle. */
  _centre(row) {
    const at = row.getBoundingClientRect();
    const box = this.host.getBoundingClientRect();
    this.host.scrollTop += at.top - box.top - box.height / 2 + at.height / 2;
  }

  _count() {
    this.controls.count.textContent = `${this.shown} / ${this.events.length} events`;
  }
}
