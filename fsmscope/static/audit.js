// The audit: every control of the machine shown (preempt, start, the debugger's, the lease's and
// the deadman's), with its time, who asked (address, role, page), who held control then, what was
// asked and the result, newest first, filtered by action, result and text. It reads the machine's
// recorded `control` events (GET .../history), so a replay shows the same audit as the live run.

import { api } from "./api.js";
import { clockText } from "./clocktext.js";
import { h } from "./dom.js";
import { valueText } from "./transcript.js";

const LIMIT = 10000; // control events read at most (the newest)
const PARAMS_LIMIT = 120; // characters of what was asked, as the transcript shows it

/** Who held the lease at each control event, walking `events` (oldest first): "" when nobody. A page
 * holds it from the event that gave it the lease to the one that ended it (released, lapsed), both included. */
export function holdersAt(events) {
  let holder = "";
  return events.map((ev) => {
    const ends = ev.action === "deadman" || (ev.action === "lease" && ev.params?.how === "released");
    if (ev.action === "lease" && !ends) holder = `page ${ev.params?.page ?? "?"}`;
    const then = holder;
    if (ends) holder = "";
    return then;
  });
}

export class Audit {
  /** @param {Store} store the page's store (store.js): the machine shown */
  constructor(store) {
    this.store = store;
    this.dialog = document.getElementById("audit-dialog");
    this.rows = []; // [{ev, holder}] newest first
    this.filters = {
      action: this.dialog.querySelector("select[name=action]"),
      result: this.dialog.querySelector("select[name=result]"),
      text: this.dialog.querySelector("input[name=text]"),
    };
    for (const input of Object.values(this.filters)) input.addEventListener("input", () => this._draw());
    this.dialog.querySelector("button[name=refresh]").addEventListener("click", () => this.load());
  }

  /** Open the audit of the machine shown. */
  open() {
    this.dialog.querySelector(".dlg-machine").textContent = this.store.state.name || "";
    this.dialog.showModal();
    return this.load();
  }

  async load() {
    const name = this.store.state.name;
    const table = this.dialog.querySelector("tbody");
    try {
      const page = await api.history(name, { kinds: "control", limit: LIMIT, order: "desc" });
      const events = page.events; // the newest LIMIT, oldest first
      const holders = holdersAt(events);
      this.rows = events.map((ev, i) => ({ ev, holder: holders[i] })).reverse();
      this.dialog.querySelector(".dlg-partial").hidden = !page.more;
    } catch (err) {
      this.rows = [];
      table.replaceChildren(h("tr", {}, h("td", { colSpan: 6, text: "Could not read the controls: " + (err.detail || err.message) })));
      return;
    }
    this._fillActions();
    this._draw();
  }

  _fillActions() {
    const select = this.filters.action;
    const chosen = select.value;
    const actions = [...new Set(this.rows.map((r) => r.ev.action))].sort();
    select.replaceChildren(h("option", { value: "", text: "every action" }),
      ...actions.map((a) => h("option", { value: a, text: a })));
    select.value = actions.includes(chosen) ? chosen : "";
  }

  _draw() {
    const action = this.filters.action.value;
    const result = this.filters.result.value;
    const text = this.filters.text.value.trim().toLowerCase();
    const shown = this.rows.filter(({ ev, holder }) => {
      if (action && ev.action !== action) return false;
      const accepted = ev.result === "accepted";
      if ((result === "accepted" && !accepted) || (result === "refused" && accepted)) return false;
      return !text || [ev.client, ev.reason, holder, ev.result, JSON.stringify(ev.params ?? {})]
        .some((field) => String(field ?? "").toLowerCase().includes(text));
    });
    this.dialog.querySelector(".dlg-count").textContent = `${shown.length} of ${this.rows.length} controls`;
    this.dialog.querySelector("tbody").replaceChildren(...shown.map(({ ev, holder }) => h("tr",
      { class: ev.result === "accepted" ? "" : "refused", "data-seq": ev.seq },
      h("td", { text: clockText(ev.t) }),
      h("td", { text: ev.client }),
      h("td", { text: holder || "nobody" }),
      h("td", { text: ev.action }),
      h("td", { text: [ev.params && Object.keys(ev.params).length ? valueText(ev.params, PARAMS_LIMIT) : "",
        ev.reason ? `(${ev.reason})` : ""].filter(Boolean).join(" ") }),
      h("td", { text: ev.result }))));
  }
}
