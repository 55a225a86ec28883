// The /timeline answer (docs/api.md, issue 9's contract) in the flat, typed form the timeline draws
// and hit-tests from: one row per container (its bands as parallel typed arrays, labels as indices
// into one table), the ticks sorted by time. Built once per answer, never per frame.

import { TICK_KINDS } from "./schema.js";

export const NO_LABEL = -1; // null: the container is not running
export const MANY = -2; // "…": many states within one bucket

const segments = (path) => path.split("/").filter(Boolean);

/** Tree order: a parent before its children, siblings by name. */
function treeOrder(a, b) {
  const sa = segments(a), sb = segments(b);
  for (let i = 0; i < Math.min(sa.length, sb.length); i++) {
    if (sa[i] !== sb[i]) return sa[i] < sb[i] ? -1 : 1;
  }
  return sa.length - sb.length;
}

/** The index of the first element of a sorted typed array that is >= x (its length when none). */
export function lowerBound(arr, x, n = arr.length) {
  let lo = 0, hi = n;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (arr[mid] < x) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

function buildRows(bands, labelIndex) {
  const paths = Object.keys(bands || {}).sort(treeOrder);
  const top = Math.min(...paths.map((p) => segments(p).length));
  return paths.map((path) => {
    const list = Array.isArray(bands[path]) ? bands[path] : [];
    const n = list.length;
    const row = {
      path, name: segments(path).at(-1) || path, depth: segments(path).length - top, n,
      t0: new Float64Array(n), t1: new Float64Array(n), seq: new Float64Array(n), label: new Int32Array(n),
    };
    for (let i = 0; i < n; i++) {
      const [t0, t1, seq0, label] = list[i];
      row.t0[i] = t0;
      row.t1[i] = t1;
      row.seq[i] = seq0;
      row.label[i] = labelIndex(label);
    }
    return row;
  });
}

function buildTicks(ticks) {
  const list = (Array.isArray(ticks) ? ticks : []).filter((k) => Number.isFinite(k.t)).sort((a, b) => a.t - b.t);
  const n = list.length;
  const out = { n, t: new Float64Array(n), seq: new Float64Array(n), kind: new Uint8Array(n), text: new Array(n) };
  list.forEach((k, i) => {
    out.t[i] = k.t;
    out.seq[i] = k.seq;
    out.kind[i] = Math.max(0, TICK_KINDS.indexOf(k.kind));
    out.text[i] = `${k.kind} · seq ${k.seq}${k.text ? ": " + k.text : ""}`;
  });
  return out;
}

export class TimelineData {
  /** @param {object} resp the /timeline JSON: {first, last, kept_from, runs, bands, ticks, transitions, coarse, history_from} */
  constructor(resp = {}) {
    this.first = resp.first || null;
    this.last = resp.last || null;
    this.keptFrom = Number.isFinite(resp.kept_from) ? resp.kept_from : null;
    this.historyFrom = Number.isFinite(resp.history_from) ? resp.history_from : null; // the oldest seq that can be shown
    this.runs = (Array.isArray(resp.runs) ? resp.runs : []).filter((r) => Number.isFinite(r.t));
    this.coarse = Boolean(resp.coarse);
    this.labels = []; // index -> label text
    const index = new Map();
    const labelIndex = (label) => {
      if (label === null || label === undefined) return NO_LABEL;
      if (label === "…") return MANY;
      const text = String(label);
      if (!index.has(text)) {
        index.set(text, this.labels.length);
        this.labels.push(text);
      }
      return index.get(text);
    };
    this.rows = buildRows(resp.bands, labelIndex);
    this.ticks = buildTicks(resp.ticks);
  }

  /** The band of `row` at time t, as its index, or -1. */
  bandAt(row, t) {
    const i = lowerBound(row.t1, t, row.n);
    return i < row.n && row.t0[i] <= t ? i : -1;
  }

  /** The tick nearest to t within `tolerance` seconds, as its index, or -1. */
  tickNear(t, tolerance) {
    const { ticks } = this;
    const i = lowerBound(ticks.t, t - tolerance, ticks.n);
    let best = -1;
    for (let j = i; j < ticks.n && ticks.t[j] <= t + tolerance; j++) {
      if (best < 0 || Math.abs(ticks.t[j] - t) < Math.abs(ticks.t[best] - t)) best = j;
    }
    return best;
  }
}
