// The details of the selected state or container, a collapsible section under the hierarchy: its class,
// path and docstring, its outcomes and where each leads (its container's transitions; a Concurrence's
// outcome map), its keys and remapping, and its statistics (visits, time in state, last outcome) from
// GET .../summary, asked every second while the section is open. Every name, key and docstring goes
// in as text (dom.js).

import { h } from "./dom.js";
import { parentPath } from "./status.js";

const POLL_MS = 1000;

/** Seconds as text: "-" for none, ms below a second. */
function seconds(value) {
  if (value === null || value === undefined) return "-";
  return value < 1 ? (value * 1000).toFixed(1) + " ms" : value.toFixed(3) + " s";
}

/** Where `outcome` of `node` leads, from its container `parent`: a sibling, the container's outcome, or
 * (no container) the machine's outcome. */
function leadsTo(node, parent, outcome) {
  if (!parent) return "the machine ends with it";
  if (!parent.transitions) return "-";
  const tr = parent.transitions.find((t) => t.from === node.label && t.outcome === outcome);
  if (!tr) return parent.outcome_map ? "in no outcome of the outcome map" : "not connected";
  const to = tr.to ?? outcome;
  if (parent.outcome_map) return "→ " + parent.label + " ends " + to + " (with the others of the outcome map)";
  return parent.children.some((c) => c.label === to) ? "→ " + to : "→ " + parent.label + " ends: " + to;
}

/** A definition list's term and description rows. */
function rows(pairs) {
  return h("dl", { class: "details-list" }, ...pairs.flatMap(([term, value]) => [h("dt", { text: term }), h("dd", {}, value)]));
}

export class DetailsPanel {
  /**
   * @param {HTMLDetailsElement} section the collapsible section (its `.details-body` is filled)
   * @param {Store} store the page's store (store.js): the machine shown
   * @param {object} api the REST API (api.js): `summary(name, path)`
   */
  constructor(section, store, api) {
    this.section = section;
    this.body = section.querySelector(".details-body");
    this.store = store;
    this.api = api;
    this.path = undefined; // the path shown (null: nothing selected)
    this.structureKey = null;
    this.stats = null; // the element the statistics go in
    this.asking = false;
    section.addEventListener("toggle", () => this.poll());
    setInterval(() => this.poll(), POLL_MS);
  }

  /** Show the selection of `state` (the store's; rebuilt only when it or the structure changed). */
  update({ selected: path, structureKey, nodes }) {
    if (path === this.path && structureKey === this.structureKey) return;
    this.path = path;
    this.structureKey = structureKey;
    const node = path ? nodes.get(path) : null;
    if (!node) {
      this.stats = null;
      this.body.replaceChildren(h("p", { class: "empty", text: "Select a state or container (or search: Ctrl-K)." }));
      return;
    }
    const parentNode = nodes.get(parentPath(path)) || null;
    this.stats = h("div", { class: "details-stats" }, h("p", { class: "muted", text: "counting…" }));
    this.body.replaceChildren(
      h("p", { class: "details-head" }, h("strong", { text: node.label }), " ", h("span", { class: "muted", text: node.type })),
      h("p", { class: "details-path", text: node.path }),
      node.doc ? h("p", { class: "details-doc", text: node.doc }) : h("p", { class: "details-no-doc muted", text: "no docstring" }),
      rows([
        ["outcomes", this._outcomes(node, parentNode)],
        ["input keys", this._keys(node.input_keys, node.remapping)],
        ["output keys", this._keys(node.output_keys, node.remapping)],
        ...(node.container ? [["initial", h("span", { text: (node.initial || []).join(", ") || "-" })]] : []),
        ...(node.outcome_map ? [["outcome map", this._outcomeMap(node)]] : []),
      ]),
      this.stats);
    this.poll();
  }

  _outcomes(node, parentNode) {
    return h("ul", { class: "details-outcomes" }, ...node.outcomes.map((o) =>
      h("li", {}, h("code", { text: o }), " ", h("span", { text: leadsTo(node, parentNode, o) }))));
  }

  /** Keys with the container's key each is remapped to ("key ← parent's key"), or "-". */
  _keys(keys, remapping) {
    if (!keys.length) return h("span", { text: "-" });
    return h("ul", { class: "details-keys" }, ...keys.map((k) => {
      const outer = remapping?.[k];
      return h("li", {}, h("code", { text: k }), outer && outer !== k ? h("span", { text: " ⇄ container's " + outer }) : null);
    }));
  }

  /** A Concurrence's outcome map: each outcome and the children's outcomes it needs; its default outcome. */
  _outcomeMap(node) {
    const items = Object.entries(node.outcome_map).map(([outcome, needs]) => h("li", {}, h("code", { text: outcome }),
      h("span", { text: " when " + Object.entries(needs).map(([child, o]) => child + ":" + o).join(", ") })));
    if (node.default_outcome) items.push(h("li", {}, h("span", { text: "otherwise " }), h("code", { text: node.default_outcome })));
    return h("ul", { class: "details-map" }, ...items);
  }

  /** Ask the server for the statistics of the state shown, while the section is open (one request at a time). */
  async poll() {
    const path = this.path;
    const name = this.store.state.name;
    if (!this.section.open || !path || !this.stats || this.asking || document.hidden) return;
    this.asking = true;
    try {
      const answer = await this.api.summary(name, path);
      if (path === this.path && name === this.store.state.name) this._showStats(answer, path);
    } catch (err) {
      if (path === this.path) this.stats.replaceChildren(h("p", { class: "muted", text: "No statistics: " + (err.detail || err.message) }));
    } finally {
      this.asking = false;
    }
  }

  _showStats(answer, path) {
    const s = answer.states[path];
    const counted = answer.counted;
    const over = counted.first_seq === null ? "no events yet"
      : `events ${counted.first_seq}–${counted.last_seq}` + (answer.complete ? "" : ` of ${answer.last_seq}, counting…`);
    this.stats.replaceChildren(rows([
      ["visits", h("span", { class: "details-visits", text: String(s.visits) })],
      ["time in state", h("span", { class: "details-time",
        text: `last ${seconds(s.time.last)} · median ${seconds(s.time.median)} · max ${seconds(s.time.max)}` })],
      ["last outcome", h("span", { class: "details-last-outcome", text: s.last_outcome ?? "-" })],
      ["counted over", h("span", { class: "muted", text: over })],
    ]));
  }
}
