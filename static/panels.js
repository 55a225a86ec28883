// The side panels: the hierarchy tree, a container's userdata, the event log.
// Every name, value and message goes in as text (createElement + textContent), never as HTML.

import { KINDS } from "./schema.js";
import { parentPath } from "./status.js";
import { transcript, valueText } from "./transcript.js";

export function h(tag, props = {}, ...children) {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (v === undefined || v === null || v === false) continue;
    if (k === "class") el.className = v;
    else if (k === "text") el.textContent = v;
    else if (k === "title") el.title = v;
    else if (k.startsWith("data-") || k.startsWith("aria-") || k === "role") el.setAttribute(k, v);
    else el[k] = v;
  }
  for (const child of children) if (child !== null && child !== undefined) el.append(child);
  return el;
}

/** The tree of the hierarchy; rows are built once per structure, status only toggles classes. */
export class TreeView {
  constructor(host, handlers) {
    this.host = host;
    this.handlers = handlers;
    this.rows = new Map(); // path -> row element
    this.collapsed = new Set();
    this.selected = null;
    host.addEventListener("click", (e) => {
      const row = e.target.closest(".tree-row");
      if (!row) return;
      const path = row.dataset.path;
      if (e.target.closest(".twisty")) {
        this.toggle(path);
        return;
      }
      this.handlers.select(path);
    });
    host.addEventListener("contextmenu", (e) => {
      const row = e.target.closest(".tree-row");
      if (!row) return;
      e.preventDefault();
      this.handlers.contextmenu(row.dataset.path, e.clientX, e.clientY);
    });
  }

  build(structure) {
    this.rows.clear();
    if (!structure) {
      this.host.replaceChildren(h("p", { class: "empty", text: "No structure yet." }));
      return;
    }
    const ul = h("ul", { class: "tree", role: "tree" });
    ul.append(this._node(structure, 0));
    this.host.replaceChildren(ul);
  }

  _node(node, depth) {
    const isContainer = Boolean(node.container);
    const row = h("div", { class: "tree-row" + (isContainer ? " container" : ""), "data-path": node.path, title: node.path },
      h("span", { class: "twisty", text: isContainer && node.children?.length ? "▾" : "" }),
      h("span", { class: "dot" }),
      h("span", { class: "label", text: node.label }),
      h("span", { class: "type", text: node.type }),
      h("span", { class: "outcome" }));
    row.style.paddingLeft = `${4 + depth * 14}px`;
    this.rows.set(node.path, row);
    const li = h("li", { role: "treeitem" }, row);
    if (isContainer && node.children?.length) {
      const ul = h("ul", { role: "group" });
      for (const child of node.children) ul.append(this._node(child, depth + 1));
      li.append(ul);
      if (this.collapsed.has(node.path)) li.classList.add("collapsed");
    }
    return li;
  }

  toggle(path) {
    const row = this.rows.get(path);
    if (!row) return;
    const li = row.parentElement;
    li.classList.toggle("collapsed");
    if (li.classList.contains("collapsed")) this.collapsed.add(path);
    else this.collapsed.delete(path);
  }

  /** @param {string[]} failed the failing state and the containers it brought down */
  update(status, failed) {
    const active = new Set(status.activePaths());
    if (status.running && status.root_path) active.add(status.root_path);
    const failedSet = new Set(failed);
    for (const [path, row] of this.rows) {
      row.classList.toggle("active", active.has(path));
      row.classList.toggle("failed", failedSet.has(path));
      const entry = status.containers[path];
      const out = row.lastElementChild;
      const text = entry && !entry.running && entry.outcome ? "→ " + entry.outcome : "";
      if (out.textContent !== text) out.textContent = text;
    }
  }

  select(path) {
    if (this.selected) this.rows.get(this.selected)?.classList.remove("selected");
    this.selected = path;
    const row = path ? this.rows.get(path) : null;
    if (!row) return;
    row.classList.add("selected");
    for (let li = row.parentElement.parentElement?.closest("li"); li; li = li.parentElement?.closest("li")) {
      if (li.classList.contains("collapsed")) {
        li.classList.remove("collapsed");
        this.collapsed.delete(li.firstElementChild.dataset.path);
      }
    }
    row.scrollIntoView({ block: "nearest" });
  }
}

/** One container's userdata, with the keys written by the last transition highlighted. */
export class UserdataPanel {
  constructor(host, picker, handlers) {
    this.host = host;
    this.picker = picker;
    this.handlers = handlers;
    this.path = null;
    this.expanded = new Set();
    this.rendered = null; // [path, userdata object, changed set] last drawn
    picker.addEventListener("change", () => this.handlers.pick(picker.value));
    host.addEventListener("click", (e) => {
      const row = e.target.closest(".ud-row");
      if (!row) return;
      const key = row.dataset.key;
      if (this.expanded.has(key)) this.expanded.delete(key);
      else this.expanded.add(key);
      this.rendered = null;
      this.handlers.redraw();
    });
  }

  setContainers(nodes) {
    const options = nodes.map((n) => h("option", { value: n.path, text: n.path }));
    this.picker.replaceChildren(...options);
    if (this.path) this.picker.value = this.path;
  }

  show(path) {
    if (path === this.path) return;
    this.path = path;
    this.expanded.clear();
    this.rendered = null;
    if (path) this.picker.value = path;
  }

  update(status, node, changed) {
    const entry = this.path ? status.containers[this.path] : null;
    const ud = entry ? entry.userdata : null;
    const r = this.rendered;
    if (r && r[0] === this.path && r[1] === JSON.stringify(ud) && r[2] === changed && r[3] === entry?.running) return;
    this.rendered = [this.path, JSON.stringify(ud), changed, entry?.running];
    if (!entry) {
      this.host.replaceChildren(h("p", { class: "empty", text: this.path ? "No data for this container yet." : "Select a container." }));
      return;
    }
    const info = h("div", { class: "ud-info" });
    if (node) {
      info.append(h("span", { class: "type", text: node.type }));
      if (node.input_keys?.length) info.append(h("span", { class: "keys", text: "in: " + node.input_keys.join(", ") }));
      if (node.output_keys?.length) info.append(h("span", { class: "keys", text: "out: " + node.output_keys.join(", ") }));
    }
    info.append(h("span", { class: "state " + (entry.running ? "running" : ""), text: entry.running ? "running" : entry.outcome ? "→ " + entry.outcome : "idle" }));
    const keys = Object.keys(ud);
    const table = h("table", { class: "ud-table" });
    const body = h("tbody");
    for (const key of keys.sort()) {
      const value = ud[key];
      const open = this.expanded.has(key);
      const valueCell = open
        ? h("td", { class: "value" }, h("pre", { text: JSON.stringify(value, null, 2) }))
        : h("td", { class: "value", text: valueText(value, 160) });
      if (value && typeof value === "object" && ("$repr" in value || "$truncated" in value)) valueCell.classList.add("repr");
      body.append(h("tr", { class: "ud-row" + (changed?.has(key) ? " changed" : ""), "data-key": key, title: open ? "" : "click to expand" },
        h("th", { text: key }), valueCell));
    }
    table.append(body);
    this.host.replaceChildren(info, keys.length ? table : h("p", { class: "empty", text: "(no userdata)" }));
  }
}

const MAX_EVENTS = 5000;
const MAX_ROWS = 800;
const MAX_ROWS_PER_FRAME = 120; // under a flood only the newest rows of each frame are drawn

function selectionOf(ev) {
  const path = ev.path;
  if (ev.kind === "transition") return path + "/" + (ev.to ?? ev.from);
  if (ev.kind === "start" && ev.active?.length === 1) return path + "/" + ev.active[0];
  if (ev.kind === "error" && ev.state) return path + "/" + ev.state;
  return path;
}

function clock(t) {
  if (typeof t !== "number") return "";
  const d = new Date(t * 1000);
  const pad = (n, w = 2) => String(n).padStart(w, "0");
  return `${pad(d.getHours())}:${pad(d.getMinutes())}:${pad(d.getSeconds())}.${pad(d.getMilliseconds(), 3)}`;
}

/** The words of an event the text filter searches besides its transcript line: the states and outcomes it names. */
function searchedWords(ev) {
  const words = [ev.kind, ev.path, ev.from, ev.to, ev.state, ev.outcome, ev.state_outcome,
    ...[].concat(ev.active ?? [], ev.last ?? []), ...Object.entries(ev.outcomes ?? {}).flat()];
  return words.filter((w) => typeof w === "string");
}

/** The kinds the log shows: a checkbox per kind in a <details> popover, closed by Escape or a click elsewhere. */
class KindFilter {
  constructor(details, changed) {
    this.summary = details.querySelector("summary");
    this.boxes = KINDS.map((kind) => h("input", { type: "checkbox", value: kind, checked: true }));
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
    this.summary.textContent = !this.hidden.size ? "all kinds" : shown ? `${shown} of ${this.boxes.length} kinds` : "no kinds";
  }
}

/** The event log, filtered by kinds and by text; clicking a row selects the state it is about. */
export class EventLog {
  constructor(host, controls, handlers) {
    this.host = host;
    // {kinds: <details> of checkboxes, text: input, count: element, clear: button, partial: the note on a history cut short}
    this.controls = controls;
    this.handlers = handlers;
    this.events = [];
    this.shown = 0; // how many of this.events pass the filters
    this.pending = []; // events not drawn yet
    this.described = new WeakMap(); // event -> {line, text}: its transcript line and the text the filter searches
    this.needle = ""; // the text filter, lower case
    this.stick = true; // follow the newest row (false once the user scrolls up)
    host.addEventListener("scroll", () => {
      this.stick = host.scrollHeight - host.scrollTop - host.clientHeight < 24;
    }, { passive: true });
    this.nodeOf = () => undefined;
    this.selectedRow = null;
    this.kinds = new KindFilter(controls.kinds, () => this.redraw());
    controls.text.addEventListener("input", () => this.redraw());
    controls.clear.addEventListener("click", () => this.reset());
    host.addEventListener("click", (e) => {
      const row = e.target.closest(".log-row");
      if (!row) return;
      this.selectedRow?.classList.remove("selected");
      row.classList.add("selected");
      this.selectedRow = row;
      this.handlers.select(row.dataset.select);
    });
  }

  reset() {
    this.events = [];
    this.controls.partial.hidden = true;
    this.redraw();
  }

  /** A new connection's history: the current run's events up to its snapshot; `complete` false when
   * the server no longer keeps the run's earliest events. */
  history({ complete, events }) {
    this.add(events);
    this.redraw(); // all its rows at once, not only the newest of one frame
    const note = this.controls.partial;
    note.hidden = complete;
    if (!complete) {
      const from = events.length ? ` (the log starts at event ${events[0].seq})` : "";
      note.textContent = `Earlier events of this run are not kept by the server${from}.`;
    }
  }

  /** An event's transcript line and searched text, worked out once (the filter and the row both need them). */
  _describe(ev) {
    let d = this.described.get(ev);
    if (!d) {
      const line = transcript(ev, this.nodeOf);
      d = { line, text: [...searchedWords(ev), line.text].join("\n").toLowerCase() };
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
      h("span", { class: "time", text: clock(ev.t) }),
      h("span", { class: "kind", text: ev.kind }),
      h("span", { class: "path", title: ev.path }, h("bdi", { text: ev.path })),
      h("span", { class: "msg", text: line.text, title: ev.kind === "error" && ev.traceback ? ev.traceback : line.text }));
  }

  /** Keep events; their rows are drawn by the next flush() (once per animation frame, however fast they come). */
  add(events) {
    for (const ev of events) {
      this.events.push(ev);
      if (this._matches(ev)) this.shown += 1;
    }
    const dropped = this.events.length > MAX_EVENTS ? this.events.splice(0, this.events.length - MAX_EVENTS) : [];
    for (const ev of dropped) if (this._matches(ev)) this.shown -= 1;
    for (const ev of events) this.pending.push(ev);
    if (this.pending.length > 4 * MAX_ROWS_PER_FRAME) this.pending.splice(0, this.pending.length - MAX_ROWS_PER_FRAME);
  }

  flush() {
    if (!this.pending.length) return;
    const events = this.pending;
    this.pending = [];
    const stick = this.stick;
    const fresh = events.filter((ev) => this._matches(ev)).slice(-MAX_ROWS_PER_FRAME).map((ev) => this._row(ev));
    if (fresh.length) {
      this.host.querySelector(".empty")?.remove();
      this.host.append(...fresh);
      const extra = this.host.childElementCount - MAX_ROWS;
      for (let i = 0; i < extra; i++) this.host.firstElementChild.remove();
    }
    this._count();
    if (stick) this.host.scrollTop = this.host.scrollHeight;
  }

  /** Draw again from the kept events (the filters or the events changed). */
  redraw() {
    this.pending = [];
    this.needle = this.controls.text.value.trim().toLowerCase();
    const matching = this.events.filter((ev) => this._matches(ev));
    this.shown = matching.length;
    const rows = matching.slice(-MAX_ROWS).map((ev) => this._row(ev));
    this.host.replaceChildren(...(rows.length ? rows : [h("p", { class: "empty", text: "No events." })]));
    this.selectedRow = null;
    this._count();
    this.stick = true;
    this.host.scrollTop = this.host.scrollHeight;
  }

  _count() {
    this.controls.count.textContent = `${this.shown} / ${this.events.length} events`;
  }
}
