// The fleet overview's tiles in the page: one link per machine to its full dashboard, kept by name
// and only its changed texts touched at each update (a fleet's tiles update twice a second).

import { h } from "./dom.js";
import { agoText, shortPath } from "./fleet_view.js";

/** @typedef {import("./schema.js").Tile} Tile */

const SOURCE_LABEL = { local: "this server", ingest: "publisher", replay: "replay" };

export class FleetTiles {
  /** @param {HTMLElement} host where the tiles go */
  constructor(host) {
    this.host = host;
    this.tiles = new Map(); // name -> {el, parts}
  }

  /**
   * Show exactly `tiles`, in their order; `now`: the server's clock now (for "last seen").
   * @param {Tile[]} tiles
   * @param {number} now
   */
  show(tiles, now) {
    const names = new Set(tiles.map((t) => t.name));
    for (const [name, tile] of this.tiles) {
      if (!names.has(name)) {
        tile.el.remove();
        this.tiles.delete(name);
      }
    }
    let previous = null;
    for (const t of tiles) {
      const tile = this.tiles.get(t.name) || this._make(t.name);
      this._fill(tile, t, now);
      const expected = previous ? previous.nextSibling : this.host.firstChild;
      if (tile.el !== expected) this.host.insertBefore(tile.el, expected);
      previous = tile.el;
    }
  }

  _make(name) {
    const parts = {
      robot: h("span", { class: "tile-robot" }),
      pill: h("span", { class: "pill" }),
      machine: h("span", { class: "tile-machine" }),
      active: h("span", { class: "tile-active" }),
      rate: h("span", { class: "tile-rate" }),
      seen: h("span", { class: "tile-seen" }),
    };
    const el = h("a", { class: "tile", href: "./#" + new URLSearchParams({ m: name }).toString(), "data-name": name },
      h("span", { class: "tile-head" }, parts.robot, parts.pill), parts.machine, parts.active,
      h("span", { class: "tile-foot" }, parts.rate, parts.seen));
    const tile = { el, parts, text: {} };
    this.tiles.set(name, tile);
    return tile;
  }

  _fill(tile, t, now) {
    const state = t.state === "done" ? "finished: " + t.outcome : t.state === "failed" && t.error ? "failed: " + t.error : t.state;
    const active = t.active.map(shortPath).join(" · ");
    this._text(tile, "robot", t.robot ?? SOURCE_LABEL[t.source] ?? t.source);
    this._text(tile, "pill", state);
    this._text(tile, "machine", t.machine);
    this._text(tile, "active", active || (t.state === "running" ? "…" : "—"));
    this._text(tile, "rate", `${t.rate.toFixed(1)} ev/s`);
    const seen = "last event " + agoText(t.last_seen === null ? null : Math.max(0, now - t.last_seen));
    this._text(tile, "seen", t.connected || t.state === "gone" ? seen : seen + " · gone");
    tile.parts.active.title = t.active.join("\n");
    const cls = "tile " + t.state;
    if (tile.el.className !== cls) tile.el.className = cls;
    const pill = "pill " + t.state;
    if (tile.parts.pill.className !== pill) tile.parts.pill.className = pill;
    tile.el.dataset.state = t.state;
  }

  _text(tile, part, text) {
    if (tile.text[part] !== text) {
      tile.text[part] = text;
      tile.parts[part].textContent = text;
    }
  }
}
