// The search palette: Ctrl-K (or "/") opens it, Escape closes it, arrow keys and Enter (or a click)
// choose. It finds states and containers by name or path, userdata keys, outcomes (search_index.js,
// indexed once per structure); what a choice does is the page's (app.js). Names go in as text.

import { h } from "./dom.js";
import { MAX_RESULTS, SearchIndex } from "./search_index.js";
import { shownStatus } from "./shown.js";

const KINDS = { state: "state", container: "container", key: "userdata key", outcome: "outcome" };

export class SearchPalette {
  /**
   * @param {Store} store the page's store (store.js): the structure, the status shown (its userdata keys)
   * @param {(entry: object) => void} choose called with the chosen entry ({kind, name, path})
   */
  constructor(store, choose) {
    this.store = store;
    this.choose = choose;
    this.index = null;
    this.indexed = null; // the structure key the index was built for
    this.results = [];
    this.current = 0;
    this.input = h("input", { type: "search", class: "search-input", placeholder: "state, container, userdata key, outcome",
      autocomplete: "off", "aria-label": "Search states, containers, userdata keys and outcomes" });
    this.input.spellcheck = false;
    this.count = h("p", { class: "search-count muted" });
    this.list = h("ul", { class: "search-results", role: "listbox" });
    this.dialog = h("dialog", { class: "search", id: "search-dialog" }, this.input, this.count, this.list);
    document.body.append(this.dialog);
    this.input.addEventListener("input", () => this._update());
    this.input.addEventListener("keydown", (e) => this._key(e));
    this.list.addEventListener("click", (e) => {
      const row = e.target.closest("li[data-i]");
      if (row) this._choose(Number(row.dataset.i));
    });
    this.dialog.addEventListener("click", (e) => {
      if (e.target === this.dialog) this.dialog.close(); // the backdrop
    });
    document.addEventListener("keydown", (e) => {
      const typing = e.target.closest?.("input, textarea, select, dialog");
      if (((e.ctrlKey || e.metaKey) && e.key.toLowerCase() === "k") || (e.key === "/" && !typing)) {
        e.preventDefault();
        this.open();
      }
    });
  }

  /** Open the palette (the index built when the structure changed, the keys read from the status shown). */
  open() {
    const root = this.store.state.live?.structure;
    if (!root) return;
    if (this.indexed !== this.store.state.structureKey) {
      this.index = new SearchIndex(root);
      this.indexed = this.store.state.structureKey;
    }
    this.index.setKeys(shownStatus(this.store.state)?.containers);
    if (!this.dialog.open) this.dialog.showModal();
    this.input.select();
    this._update();
  }

  _update() {
    const { results, total } = this.index.search(this.input.value, MAX_RESULTS);
    this.results = results;
    this.current = 0;
    this.count.textContent = !this.input.value.trim() ? "Type a name, a path, a userdata key or an outcome."
      : total > results.length ? `${total} matches, the best ${results.length} shown` : `${total} match${total === 1 ? "" : "es"}`;
    this.list.replaceChildren(...results.map((entry, i) => h("li", { role: "option", "data-i": String(i),
      class: "search-hit " + entry.kind },
    h("span", { class: "search-kind", text: KINDS[entry.kind] }),
    h("span", { class: "search-name", text: entry.name }),
    h("span", { class: "search-path", text: entry.kind === "key" ? "userdata of " + entry.path
      : entry.kind === "outcome" ? "of " + entry.path : entry.path + " (" + entry.type + ")" }))));
    this._mark();
  }

  _mark() {
    [...this.list.children].forEach((li, i) => li.setAttribute("aria-selected", String(i === this.current)));
    this.list.children[this.current]?.scrollIntoView({ block: "nearest" });
  }

  _key(e) {
    const n = this.results.length;
    if (e.key === "ArrowDown" || e.key === "ArrowUp") {
      e.preventDefault();
      if (n) this.current = (this.current + (e.key === "ArrowDown" ? 1 : n - 1)) % n;
      this._mark();
    } else if (e.key === "Enter") {
      e.preventDefault();
      if (n) this._choose(this.current);
    } else if (e.key === "Escape") { // a search field would only clear its text
      e.preventDefault();
      this.dialog.close();
    }
  }

  _choose(i) {
    const entry = this.results[i];
    this.dialog.close();
    if (entry) this.choose(entry);
  }
}
