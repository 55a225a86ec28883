// The recorded run a page written by `fsmscope export` carries (the JSON of <script id="fsmscope-export">,
// server/export_html.py), answered as the server's REST API answers it (docs/api.md, "Time travel"):
// the status at an event from the nearest keyframe and the events after it (status.js's reducer),
// pages of history sliced from the events, the timeline the export computed, sliced to a range,
// the graph drawings and the state statistics the export made.

import { ApiError } from "../api.js";
import { Status } from "../status.js";

const LIMIT_DEFAULT = 1000; // events of a history page, unless asked otherwise
const LIMIT_MAX = 10000;
const BUCKETS_MAX = 10000;

/** How many of the ascending `keys` are at or below `value`. */
function countAtMost(keys, value) {
  let lo = 0;
  let hi = keys.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (keys[mid] <= value) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

const given = (value) => value !== undefined && value !== null && value !== "";

function integer(value, name) {
  const n = Number(value);
  if (!Number.isSafeInteger(n) || n < 0) throw new ApiError(422, `${name} must be a non-negative integer`);
  return n;
}

function finite(value, name) {
  const n = Number(value);
  if (!Number.isFinite(n)) throw new ApiError(422, `${name} must be a finite number`);
  return n;
}

/** The key of a set of open containers (null: the server's default), whatever their order. */
const drawingKey = (expand) => (expand ? JSON.stringify([...expand].sort()) : "null");

/** One recorded machine: its events, keyframes, status at the end, timeline and drawings. */
class RecordedMachine {
  constructor(data) {
    this.name = data.name;
    this.events = data.events;
    this.seqs = this.events.map((ev) => ev.seq);
    let clock = -Infinity; // times never go back in the index, whatever a wall clock did
    this.times = this.events.map((ev) => (clock = Math.max(clock, ev.t)));
    this.keyframes = data.keyframes; // [[events applied, status]]
    this.keySeqs = this.keyframes.map(([, status]) => status.last_seq);
    this.end = data.end;
    this.wholeTimeline = data.timeline;
    this.drawings = new Map(data.graphs.map(([expand, svg]) => [drawingKey(expand), svg]));
    this.stats = data.stats;
  }

  /** The state statistics the export counted over the whole recording, of `path` (GET /summary's shape). */
  summary(path) {
    const { states, unvisited, ...counted } = this.stats;
    return { ...counted, states: { [path]: states[path] ?? unvisited } };
  }

  get firstSeq() {
    return this.seqs[0];
  }

  get lastSeq() {
    return this.seqs[this.seqs.length - 1];
  }

  /** Its /api/machines entry: a replay, nothing to control. */
  info() {
    const end = this.end;
    return {
      name: this.name, running: end.running, outcome: end.outcome, last_seq: this.lastSeq, root_path: end.root_path,
      can_start: false, can_hold: false, held: false, source: "replay", connected: null, rejected: 0,
      replay: { speed: 1 }, // the page's play speed when it opens
    };
  }

  /** GET .../status?seq=N or ?t=T (neither: the end of the run). */
  statusAt(at = {}) {
    if (given(at.seq) && given(at.t)) throw new ApiError(422, "give seq or t, not both");
    let index = this.events.length - 1;
    if (given(at.seq)) {
      const seq = integer(at.seq, "seq");
      if (seq > this.lastSeq) throw new ApiError(416, `seq ${seq} is beyond the last event (${this.lastSeq})`);
      if (seq < this.firstSeq) throw new ApiError(410, `history reaches back to seq ${this.firstSeq}`);
      index = countAtMost(this.seqs, seq) - 1;
    } else if (given(at.t)) {
      const t = finite(at.t, "t");
      index = countAtMost(this.times, t) - 1;
      if (index < 0) throw new ApiError(410, `t ${t} is before what history keeps: it reaches back to seq ${this.firstSeq}`);
    }
    return this._statusAfter(index);
  }

  /** The status right after events[index]: the last keyframe before it, moved on by the reducer. */
  _statusAfter(index) {
    let k = countAtMost(this.keySeqs, this.seqs[index]) - 1;
    while (this.keyframes[k][0] > index + 1) k -= 1;
    const [applied, data] = this.keyframes[k];
    const status = Status.fromDict(data);
    for (let i = applied; i <= index; i += 1) status.apply(this.events[i]);
    const { structure, ...shown } = status.toDict();
    return { ...shown, preempt_waiting_on: status.preemptWaitingOn() };
  }

  /** GET .../history: {since, until, limit, kinds, path, order}. */
  history(params = {}) {
    const limit = given(params.limit) ? integer(params.limit, "limit") : LIMIT_DEFAULT;
    if (limit < 1 || limit > LIMIT_MAX) throw new ApiError(422, `limit must be between 1 and ${LIMIT_MAX}`);
    const since = given(params.since) ? integer(params.since, "since") : this.firstSeq;
    const until = given(params.until) ? integer(params.until, "until") : this.lastSeq;
    if (given(params.since) && given(params.until) && since > until) {
      throw new ApiError(422, `since (${since}) is after until (${until})`);
    }
    if (until < this.firstSeq) throw new ApiError(410, `history reaches back to seq ${this.firstSeq}`);
    const kinds = given(params.kinds) ? new Set([].concat(params.kinds).join(",").split(",")) : null;
    const path = given(params.path) ? params.path : null;
    const wanted = (ev) => (!kinds || kinds.has(ev.kind)) && (path === null || ev.path === path);
    const lo = countAtMost(this.seqs, since - 1);
    const hi = countAtMost(this.seqs, until);
    const desc = params.order === "desc";
    const events = [];
    let next = null; // the first match beyond the limit: the since (or, desc, the until) of the next page
    for (let i = desc ? hi - 1 : lo; desc ? i >= lo : i < hi; i += desc ? -1 : 1) {
      if (!wanted(this.events[i])) continue;
      if (events.length === limit) {
        next = this.events[i].seq;
        break;
      }
      events.push(this.events[i]);
    }
    if (desc) events.reverse();
    return { events, first_seq: this.firstSeq, last_seq: this.lastSeq, more: next !== null, next };
  }

  /** GET .../timeline: the whole run's, as the export computed it, sliced to [since_t, until_t]. */
  timeline(params = {}) {
    if (given(params.buckets) && (integer(params.buckets, "buckets") < 1 || Number(params.buckets) > BUCKETS_MAX)) {
      throw new ApiError(422, `buckets must be between 1 and ${BUCKETS_MAX}`);
    }
    const whole = this.wholeTimeline;
    if (!given(params.since_t) && !given(params.until_t)) return whole;
    const lo = given(params.since_t) ? finite(params.since_t, "since_t") : whole.first.t;
    const hi = given(params.until_t) ? finite(params.until_t, "until_t") : whole.last.t;
    if (lo > hi) throw new ApiError(422, `since_t (${lo}) is after until_t (${hi})`);
    const within = (t) => lo <= t && t <= hi;
    const bands = {};
    for (const [path, list] of Object.entries(whole.bands)) {
      const kept = list.filter(([t0, t1]) => t1 >= lo && t0 <= hi).map(([t0, t1, seq, label]) =>
        [Math.max(t0, lo), Math.min(t1, hi), seq, label]);
      if (kept.length) bands[path] = kept;
    }
    const current = whole.runs.filter((r) => r.t <= lo).pop(); // the run under way at lo
    return {
      ...whole,
      runs: whole.runs.filter((r) => r === current || within(r.t)),
      bands,
      ticks: whole.ticks.filter((tick) => within(tick.t)),
      transitions: whole.transitions.filter(([, t]) => within(t)),
    };
  }

  /** GET .../graph.svg?expand=...: only the drawings the export made (the depth menu's). */
  graphSvg(expand) {
    const svg = this.drawings.get(drawingKey(expand));
    if (svg === undefined) {
      throw new ApiError(404, "this file holds the graph at the depths of the depth menu only: choose one there");
    }
    return svg;
  }

  /** The events of the last run up to the end, the newest `limit` at most, for the log: {complete, events}. */
  runEvents(limit) {
    const from = countAtMost(this.seqs, this.end.run_seq - 1);
    return { complete: this.events.length - from <= limit, events: this.events.slice(Math.max(from, this.events.length - limit)) };
  }
}

function load() {
  const element = document.getElementById("fsmscope-export");
  const data = JSON.parse(element ? element.textContent : '{"machines": []}');
  return new Map(data.machines.map((m) => [m.name, new RecordedMachine(m)]));
}

const machines = load();

/** The recorded machine called `name`, or a 404 ApiError. */
export function recorded(name) {
  const found = machines.get(name);
  if (!found) throw new ApiError(404, `no machine named ${JSON.stringify(name)} in this file`);
  return found;
}

/** The /api/machines list of the file's machines. */
export const machineList = () => [...machines.values()].map((m) => m.info());
