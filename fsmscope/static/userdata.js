// The side panel's userdata of one container.
// Every name, value and message goes in as text (createElement + textContent), never as HTML.

import { h } from "./dom.js";
import { valueText } from "./transcript.js";

/** One container's userdata, with the keys written by its last transition highlighted, old -> new. */
export class UserdataPanel {
  constructor(host, picker, handlers) {
    this.host = host;
    this.picker = picker;
    this.handlers = handlers;
    this.path = null;
    this.expanded = new Set();
    this.rendered = null; // the key of what was last drawn (path, userdata, changes, state)
    this.history = null; // {key, items, cut}: the open history of one key
    picker.addEventListener("change", () => this.handlers.pick(picker.value));
    host.addEventListener("click", (e) => {
      const historyButton = e.target.closest(".ud-history-btn");
      if (historyButton) {
        this.handlers.keyHistory(this.path, historyButton.dataset.key);
        return;
      }
      const change = e.target.closest(".ud-key-change");
      if (change) {
        this.handlers.seek(Number(change.dataset.seq));
        return;
      }
      if (e.target.closest(".ud-key-history")) return;
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
    this.history = null;
    if (path) this.picker.value = path;
  }

  closeHistory() {
    this.history = null;
    this.rendered = null;
    this.handlers.redraw();
  }

  /** Show the history of `key` (items of keyHistory(); `cut`: only the first page of the run was read). */
  showHistory(key, items, cut) {
    this.history = { key, items, cut };
    this.rendered = null;
    this.handlers.redraw();
  }

  update(status, node) {
    const entry = this.path ? status.containers[this.path] : null;
    const ud = entry ? entry.userdata : null;
    const changes = entry?.changes || {};
    const key = JSON.stringify([this.path, ud, changes, entry?.running, entry?.outcome, this.history]);
    if (this.rendered === key) return;
    this.rendered = key;
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
      const change = Object.hasOwn(changes, key) && changedValue(changes[key]) ? changes[key] : null;
      const note = change ? changeNote(change) : null;
      // Collapsed, a key takes one line: its value cut to the pane's width, then what it was.
      const valueCell = open
        ? h("td", { class: "value" }, h("pre", { text: JSON.stringify(value, null, 2) }), ...(note ? [note] : []))
        : h("td", { class: "value" }, h("div", { class: "ud-line" }, h("span", { text: valueText(value, 160) }), ...(note ? [note] : [])));
      if (value && typeof value === "object" && ("$repr" in value || "$truncated" in value)) valueCell.classList.add("repr");
      const historyButton = h("button", { type: "button", class: "ud-history-btn", "data-key": key, text: "history",
        title: "every change of " + key + " in this run, with the state that made it" });
      body.append(h("tr", { class: "ud-row" + (change ? " changed" : ""), "data-key": key, title: open ? "" : "click to expand" },
        h("th", { text: key }), valueCell, h("td", { class: "ud-actions" }, historyButton)));
    }
    table.append(body);
    this.host.replaceChildren(info, keys.length ? table : h("p", { class: "empty", text: "(no userdata)" }));
    if (this.history) this.host.append(this._historyList());
  }

  _historyList() {
    const { key, items, cut } = this.history;
    const list = h("ol", { class: "ud-key-history" });
    for (const item of items) {
      list.append(h("li", { class: "ud-key-change", "data-seq": String(item.seq), title: "show event " + item.seq },
        h("span", { class: "seq", text: String(item.seq) }), h("span", { class: "state", text: item.state }),
        h("span", { class: "value", text: valueText(item.value, 80) })));
    }
    const close = h("button", { type: "button", text: "×", title: "close" });
    close.addEventListener("click", () => this.closeHistory());
    const title = h("div", { class: "ud-key-history-title" },
      h("span", { text: `${key}: ${items.length} change${items.length === 1 ? "" : "s"}` + (cut ? " (the first page of the run)" : "") }), close);
    return h("div", { class: "ud-key-history" }, title, items.length ? list : h("p", { class: "empty", text: "No change in this run." }));
  }
}

/** Whether a key its container's last transition wrote (`change`: {old?, new}) has another value now:
 * a state that writes a key again with the value it had changed nothing. */
function changedValue(change) {
  return !Object.hasOwn(change, "old") || JSON.stringify(change.old) !== JSON.stringify(change.new);
}

/** "was OLD" (or "new key") beside a value its container's last transition changed. */
function changeNote(change) {
  const text = Object.hasOwn(change, "old") ? "was " + valueText(change.old, 80) : "new key";
  return h("span", { class: "ud-change", text, title: text });
}

/** Every change of `key` in `events` (one container's start, transition, terminate and userdata
 * events, in order): [{seq, t, state, value}], the state being the one active when it was written (a
 * transition's or terminate's `changes` were written by the state it leaves). */
export function keyHistory(events, key) {
  const items = [];
  let active = [];
  for (const ev of events) {
    if (ev.kind === "start") {
      active = ev.active;
      if (Object.hasOwn(ev.userdata, key)) items.push({ seq: ev.seq, t: ev.t, state: "(start)", value: ev.userdata[key] });
      continue;
    }
    if (ev.changes && Object.hasOwn(ev.changes, key)) {
      items.push({ seq: ev.seq, t: ev.t, state: active.join(", ") || "?", value: ev.changes[key] });
    }
    if (ev.kind === "transition") active = ev.active;
  }
  return items;
}
