// Drawing one frame of the timeline on its canvas: the time axis, the marks lane (errors, preempts,
// controls, run boundaries), one band row per visible container (coloured by the active child's label,
// the way Foxglove's state-transitions panel draws them), the playhead and the live edge. Only the
// visible rows and, per row, only the bands in the visible range are drawn, at most one per pixel
// column; every name and label goes in with fillText.

import { clockText } from "./clocktext.js";
import { MANY, NO_LABEL, lowerBound } from "./timeline_data.js";

export const LAYOUT = { axisH: 22, marksH: 16, rowH: 18, labelW: 190, padR: 12, indent: 12 };
const FONT = '11px ui-monospace, "DejaVu Sans Mono", Menlo, Consolas, monospace';
const COLOURS = {
  bg: "#ffffff", axis: "#fafbfc", line: "#dcdfe4", grid: "#eceef1", text: "#1d2330", muted: "#6b7280",
  outside: "#f1f2f4", selected: "#e8efff", playhead: "#2563eb", live: "#16a34a", run: "#7c3aed",
  several: "#cbd5e1", range: "rgba(37, 99, 235, .14)",
};
const TICK_COLOURS = ["#c62828", "#ea780c", "#2563eb", "#0d9488", "#7c3aed"]; // error, preempt, control, debug, run
const AXIS_STEPS = [0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 15, 30, 60, 120, 300,
  600, 900, 1800, 3600, 7200, 10800, 21600, 43200, 86400];
const MIN_LABEL_SPACING = 110; // px between two time labels

/** The top of the first band row (below the axis and the marks lane). */
export const rowsTop = () => LAYOUT.axisH + LAYOUT.marksH;

/** The x of time t in a frame `g` ({w, v0, v1}). */
export function xOf(g, t) {
  return LAYOUT.labelW + ((t - g.v0) / (g.v1 - g.v0)) * (g.w - LAYOUT.labelW - LAYOUT.padR);
}

/** The time at x in a frame `g`. */
export function tOf(g, x) {
  return g.v0 + ((x - LAYOUT.labelW) / (g.w - LAYOUT.labelW - LAYOUT.padR)) * (g.v1 - g.v0);
}

// Light enough for dark text; no grey (grey is "+" and "…").
const PALETTE = ["#9ecae1", "#a1d99b", "#fdae6b", "#bcbddc", "#fc9272", "#f6e8a6", "#b3e2cd", "#f4b6c2",
  "#6baed6", "#74c476", "#fdd0a2", "#d8b5a5", "#c7e9c0", "#dadaeb", "#cbd5a3", "#a6d8f0"];

/** One stable colour per label (a hash of its text picks it from the palette). */
function labelColour(cache, label) {
  let colour = cache.get(label);
  if (colour === undefined) {
    let hash = 2166136261;
    for (let i = 0; i < label.length; i++) hash = Math.imul(hash ^ label.charCodeAt(i), 16777619);
    colour = label === "+" ? COLOURS.several : PALETTE[(hash >>> 0) % PALETTE.length];
    cache.set(label, colour);
  }
  return colour;
}

function hatch(ctx) {
  const tile = document.createElement("canvas");
  tile.width = tile.height = 6;
  const t = tile.getContext("2d");
  t.fillStyle = "#e5e7eb";
  t.fillRect(0, 0, 6, 6);
  t.strokeStyle = "#9ca3af";
  t.beginPath();
  t.moveTo(0, 6);
  t.lineTo(6, 0);
  t.stroke();
  return ctx.createPattern(tile, "repeat");
}

/** A painter of frames on one canvas context, with its caches (colours, text widths, the hatch). */
export class Painter {
  constructor(ctx) {
    this.ctx = ctx;
    this.colours = new Map();
    this.widths = new Map();
    this.hatch = hatch(ctx);
  }

  textWidth(text) {
    let w = this.widths.get(text);
    if (w === undefined) {
      w = this.ctx.measureText(text).width;
      if (this.widths.size > 5000) this.widths.clear();
      this.widths.set(text, w);
    }
    return w;
  }

  /**
   * Draw a frame: `g` = {w, h, v0, v1, scrollTop, selected, playT, liveT, range: [ta, tb] | null};
   * `data` a TimelineData (or null: nothing to draw but the axis).
   */
  frame(g, data) {
    const { ctx } = this;
    ctx.font = FONT;
    ctx.textBaseline = "middle";
    ctx.fillStyle = COLOURS.bg;
    ctx.fillRect(0, 0, g.w, g.h);
    if (g.v1 > g.v0 && g.w > LAYOUT.labelW + LAYOUT.padR) {
      this.span(g, data);
      this.axis(g);
      if (data) {
        this.rows(g, data);
        this.marks(g, data);
      }
      this.overlays(g);
    }
    ctx.strokeStyle = COLOURS.line;
    ctx.beginPath();
    ctx.moveTo(LAYOUT.labelW + 0.5, 0);
    ctx.lineTo(LAYOUT.labelW + 0.5, g.h);
    ctx.moveTo(0, rowsTop() - 0.5);
    ctx.lineTo(g.w, rowsTop() - 0.5);
    ctx.stroke();
  }

  /** Grey outside the run's span, so its start and end show. */
  span(g, data) {
    const { ctx } = this;
    const left = LAYOUT.labelW, right = g.w;
    ctx.fillStyle = COLOURS.outside;
    if (!data || !data.first || !data.last) {
      ctx.fillRect(left, 0, right - left, g.h);
      return;
    }
    const a = Math.max(left, xOf(g, data.first.t)), b = Math.min(right, xOf(g, data.last.t));
    if (a > left) ctx.fillRect(left, 0, a - left, g.h);
    if (b < right) ctx.fillRect(b, 0, right - b, g.h);
  }

  axis(g) {
    const { ctx } = this;
    ctx.fillStyle = COLOURS.axis;
    ctx.fillRect(0, 0, g.w, LAYOUT.axisH);
    const secPerPx = (g.v1 - g.v0) / (g.w - LAYOUT.labelW - LAYOUT.padR);
    const step = AXIS_STEPS.find((s) => s / secPerPx >= MIN_LABEL_SPACING) || AXIS_STEPS.at(-1);
    const offset = -new Date(g.v0 * 1000).getTimezoneOffset() * 60; // local midnight is a multiple
    const grid = new Path2D();
    ctx.fillStyle = COLOURS.muted;
    for (let k = Math.ceil((g.v0 + offset) / step); k * step - offset <= g.v1; k++) {
      const t = k * step - offset;
      const x = Math.round(xOf(g, t)) + 0.5;
      grid.moveTo(x, LAYOUT.axisH - 5);
      grid.lineTo(x, g.h);
      const text = clockText(t);
      if (x + 3 + this.textWidth(text) <= g.w) ctx.fillText(text, x + 3, LAYOUT.axisH / 2);
    }
    ctx.strokeStyle = COLOURS.grid;
    ctx.stroke(grid);
  }

  /** Errors, preempts, controls (ticks in the marks lane) and run boundaries (lines across). */
  marks(g, data) {
    const { ctx } = this;
    const top = LAYOUT.axisH, h = LAYOUT.marksH;
    const { ticks } = data;
    let lastX = -1;
    for (let i = lowerBound(ticks.t, g.v0, ticks.n); i < ticks.n && ticks.t[i] <= g.v1; i++) {
      const x = Math.round(xOf(g, ticks.t[i]));
      if (x === lastX && ticks.kind[i] !== 0) continue; // an error always shows
      lastX = x;
      ctx.fillStyle = TICK_COLOURS[ticks.kind[i]];
      ctx.fillRect(x - 1, top + 2, 3, h - 4);
    }
    ctx.fillStyle = COLOURS.run;
    for (const run of data.runs) {
      const x = Math.round(xOf(g, run.t));
      if (x < LAYOUT.labelW || x > g.w) continue;
      ctx.fillRect(x, top, 1, g.h - top);
      ctx.fillText(`run ${run.run}`, x + 3, top + h / 2);
    }
    ctx.fillStyle = COLOURS.muted;
    ctx.fillText("events", 6, top + h / 2);
  }

  rows(g, data) {
    const { ctx } = this;
    const top = rowsTop(), { rowH } = LAYOUT;
    const first = Math.max(0, Math.floor(g.scrollTop / rowH));
    const last = Math.min(data.rows.length, Math.ceil((g.scrollTop + g.h - top) / rowH));
    ctx.save();
    ctx.beginPath();
    ctx.rect(0, top, g.w, g.h - top);
    ctx.clip();
    const fills = new Map(); // fill style -> the path of every band of that colour
    const texts = [];
    for (let r = first; r < last; r++) {
      const row = data.rows[r];
      const y = top + r * rowH - g.scrollTop;
      if (row.path === g.selected) {
        ctx.fillStyle = COLOURS.selected;
        ctx.fillRect(0, y, g.w, rowH);
      }
      this.bands(g, data, row, y + 2, rowH - 4, fills, texts);
    }
    for (const [style, path] of fills) {
      ctx.fillStyle = style;
      ctx.fill(path);
    }
    ctx.fillStyle = COLOURS.text;
    for (const [text, x, y] of texts) ctx.fillText(text, x, y);
    ctx.beginPath();
    ctx.rect(0, top, LAYOUT.labelW - 4, g.h - top);
    ctx.clip();
    for (let r = first; r < last; r++) {
      const row = data.rows[r];
      ctx.fillStyle = row.path === g.selected ? COLOURS.playhead : COLOURS.text;
      ctx.fillText(row.name, 6 + row.depth * LAYOUT.indent, top + r * rowH - g.scrollTop + rowH / 2);
    }
    ctx.restore();
  }

  /** One row's bands in the visible range, at most one per pixel column, added to `fills` (by colour)
   * and their labels that fit to `texts`: one fill per colour for the frame, not one per band. */
  bands(g, data, row, y, h, fills, texts) {
    const left = LAYOUT.labelW + 1;
    let lastX = -Infinity;
    for (let i = lowerBound(row.t1, g.v0, row.n); i < row.n && row.t0[i] <= g.v1; i++) {
      const label = row.label[i];
      if (label === NO_LABEL) continue;
      const x0 = Math.max(left, xOf(g, row.t0[i])), x1 = Math.min(g.w, xOf(g, row.t1[i]));
      if (Math.floor(x1) <= lastX) continue; // this pixel is painted already
      const x = Math.max(x0, lastX), w = Math.max(1, x1 - x);
      lastX = Math.floor(x + w);
      const text = label === MANY ? null : data.labels[label];
      const style = text === null ? this.hatch : labelColour(this.colours, text);
      let path = fills.get(style);
      if (!path) fills.set(style, (path = new Path2D()));
      path.rect(x, y, w > 3 ? w - 1 : w, h); // a gap ends a band wide enough, should its neighbour share its colour
      if (text !== null && w > 24 && this.textWidth(text) + 8 <= w) texts.push([text, x + 4, y + h / 2]);
    }
  }

  /** The shift-drag range, the live edge and the playhead. */
  overlays(g) {
    const { ctx } = this;
    if (g.range) {
      const a = xOf(g, Math.min(...g.range)), b = xOf(g, Math.max(...g.range));
      ctx.fillStyle = COLOURS.range;
      ctx.fillRect(a, 0, b - a, g.h);
    }
    const line = (t, colour, text) => {
      const x = Math.round(xOf(g, t));
      if (x < LAYOUT.labelW || x > g.w) return;
      ctx.fillStyle = colour;
      ctx.fillRect(x - 1, 0, 2, g.h);
      const w = this.textWidth(text) + 8;
      const bx = Math.min(x + 2, g.w - w);
      ctx.fillRect(bx, 2, w, LAYOUT.axisH - 4);
      ctx.fillStyle = "#ffffff";
      ctx.fillText(text, bx + 4, LAYOUT.axisH / 2);
    };
    if (g.liveT !== null) line(g.liveT, COLOURS.live, "live");
    if (g.playT !== null) line(g.playT, COLOURS.playhead, clockText(g.playT));
  }
}
