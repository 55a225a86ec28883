// The playhead: which instant of the machine shown the page draws, kept in the store (store.js,
// `state.instant`) and moved only from here. Live (the stream's present) or an event of the past,
// rebuilt by the server (GET .../status?seq=N) and moved on locally with the same reducer
// (status.js) from pages of history (GET .../history) while it plays. Seeks are coalesced: one
// request in flight, the newest target wins, so a drag never queues up requests.

import { Status } from "./status.js";
import { presentOf } from "./store.js";

const STEP_KINDS = "start,transition,terminate"; // what "the previous / next transition" steps over
const WINDOW_BEFORE = 400; // events of the log shown before the instant
const WINDOW_AFTER = 100; // and after it (greyed: not happened yet at the instant)
const AHEAD = 1000; // events fetched ahead while playing
const MAX_GAP = 2; // seconds of recorded time: a longer quiet stretch plays in this long
const WINDOW_EVERY_MS = 250; // while playing, the log around the instant is redrawn this often

export class Playhead {
  /**
   * @param {object} api {statusAt(name, {seq}|{t}), history(name, params)}: the server's answers
   * @param {Store} store the page's store: its `instant` is what this moves
   * @param {(err: Error) => void} failed told when an instant could not be shown
   */
  constructor(api, store, failed) {
    this.api = api;
    this.store = store;
    this.failed = failed;
    this.speed = 1;
    this.open(null, false);
  }

  /** Show machine `name`: at event `at` when given, else live, or (a replay) paused at its first event. */
  open(name, replay, at = null) {
    this.name = name;
    this.store.setInstant(presentOf(replay));
    this.ahead = []; // events after the instant, fetched while playing
    this.exhausted = false; // no events after `ahead` (the end of what the server has)
    this._target = null; // the newest seek asked for
    this._busy = null; // the seek answering, while one is
    this._generation = (this._generation || 0) + 1; // answers for an earlier machine or seek are dropped
    this._windowTimer = null;
    if (name === null) return;
    if (at !== null) this.seek({ seq: at });
    else if (replay) this._first();
  }

  get past() {
    return this.store.state.instant.past;
  }

  get status() {
    return this.store.state.instant.status;
  }

  get playing() {
    return this.store.state.instant.playing;
  }

  get replay() {
    return this.store.state.instant.replay;
  }

  /** Whether an instant asked for has not been shown yet. */
  get seeking() {
    return this._target !== null || this._busy !== null;
  }

  get seq() {
    return this.status ? this.status.last_seq : null;
  }

  get t() {
    return this.status ? this.status.last_t : null;
  }

  /** Go to event {seq} or the last event at time {t} (coalesced with seeks still in flight). */
  seek(target) {
    if (this.name === null) return;
    this.pause();
    this._target = target;
    if (!this._busy) this._run();
  }

  /** Back to the present of a live machine (a replay has none: its end). */
  live() {
    this.pause();
    this._generation += 1;
    this._target = null;
    this._busy = null; // a seek still answering belongs to the generation just left: the next one runs anew
    if (this.replay) {
      this._last();
      return;
    }
    this.store.setInstant({ past: false, status: null, window: null });
  }

  /** Step to the previous (-1) or next (+1) transition of any container, or of container `path`. */
  async step(direction, path = null) {
    if (this.name === null) return;
    const from = this.past ? this.seq : null;
    if (from === null && direction > 0) return; // live: nothing is next yet
    const params = { kinds: STEP_KINDS, limit: 1 };
    if (path) params.path = path;
    if (direction > 0) params.since = from + 1;
    else if (from !== null) Object.assign(params, { until: from - 1, order: "desc" });
    else params.order = "desc";
    try {
      const page = await this.api.history(this.name, params);
      const next = page.events[page.events.length - 1];
      if (next) this.seek({ seq: next.seq });
    } catch (err) {
      this.failed(err);
    }
  }

  play() {
    if (this.name === null || this.playing) return;
    if (!this.past) return; // live already moves on its own
    this._clock = this.t;
    this._tick = null;
    this._played = []; // events played since the log was last redrawn
    this._windowAt = 0;
    this.store.setInstant({ playing: true });
    this._fill();
    requestAnimationFrame((now) => this._frame(now));
  }

  pause() {
    if (!this.playing) return;
    this.ahead = [];
    this.exhausted = false;
    this.store.setInstant({ playing: false });
    this._scheduleWindow();
  }

  setSpeed(speed) {
    this.speed = speed;
  }

  /** How many events the instant is behind `liveStatus` (the stream's present). */
  behind(liveStatus) {
    return this.past && liveStatus ? Math.max(0, liveStatus.last_seq - this.seq) : 0;
  }

  // ---------------------------------------------------------------- seeking

  async _run() {
    const run = {};
    this._busy = run;
    const generation = this._generation;
    try {
      while (this._target !== null && generation === this._generation) {
        const target = this._target;
        this._target = null;
        const data = await this.api.statusAt(this.name, target);
        if (generation !== this._generation) return;
        this.store.setInstant({ past: true, status: Status.fromDict({ machine: this.name, ...data }) });
      }
      if (generation === this._generation) this._scheduleWindow();
    } catch (err) {
      if (generation === this._generation) this.failed(err);
    } finally {
      if (this._busy === run) this._busy = null;
    }
  }

  _first() {
    return this._edge({ limit: 1 });
  }

  _last() {
    return this._edge({ limit: 1, order: "desc" });
  }

  /** Seek to the first or last event the server has (`params` of a one-event history page). */
  async _edge(params) {
    const generation = this._generation;
    try {
      const page = await this.api.history(this.name, params);
      if (generation !== this._generation) return;
      const ev = page.events[0];
      if (ev) this.seek({ seq: ev.seq });
    } catch (err) {
      if (generation === this._generation) this.failed(err);
    }
  }

  /** The log around the instant, once the seeks have settled (not on every frame of a drag). */
  _scheduleWindow() {
    clearTimeout(this._windowTimer);
    if (!this.past || this.playing) return;
    this._windowTimer = setTimeout(() => this._loadWindow(), 60);
  }

  async _loadWindow() {
    const generation = this._generation;
    const seq = this.seq;
    if (seq === null || this._busy) return;
    try {
      const page = await this.api.history(this.name, {
        since: Math.max(0, seq - WINDOW_BEFORE), until: seq + WINDOW_AFTER, limit: WINDOW_BEFORE + WINDOW_AFTER + 1,
      });
      if (generation !== this._generation || seq !== this.seq) return;
      this.store.setInstant({ window: { events: page.events, seq } });
    } catch (err) {
      if (generation === this._generation) this.failed(err);
    }
  }

  // ---------------------------------------------------------------- playing

  async _fill() {
    if (this._filling || this.exhausted) return;
    this._filling = true;
    const generation = this._generation;
    try {
      const since = (this.ahead.length ? this.ahead[this.ahead.length - 1].seq : this.seq) + 1;
      const page = await this.api.history(this.name, { since, limit: AHEAD });
      if (generation !== this._generation || !this.playing) return;
      this.ahead.push(...page.events);
      if (!page.more) this.exhausted = true;
    } catch (err) {
      this.failed(err);
      this.pause();
    } finally {
      this._filling = false;
    }
  }

  _frame(now) {
    if (!this.playing) return;
    const elapsed = this._tick === null ? 0 : (now - this._tick) / 1000;
    this._tick = now;
    const ahead = this.ahead;
    if (ahead.length && ahead[0].t - this._clock > MAX_GAP) this._clock = ahead[0].t - MAX_GAP;
    this._clock += elapsed * this.speed;
    let applied = 0;
    while (applied < ahead.length && ahead[applied].t <= this._clock) this.status.apply(ahead[applied++]);
    if (applied) {
      this._played.push(...ahead.splice(0, applied));
      const moved = {};
      if (now - this._windowAt >= WINDOW_EVERY_MS) { // the log follows a few times a second, not every frame
        this._windowAt = now;
        const { window } = this.store.state.instant;
        moved.window = { events: (window ? window.events.concat(this._played) : this._played).slice(-WINDOW_BEFORE), seq: this.seq };
        this._played = [];
      }
      this.store.setInstant(moved); // the status moved on in place
    }
    if (ahead.length < AHEAD / 4) this._fill();
    if (!ahead.length && this.exhausted) {
      this.pause();
      if (!this.replay) this.live(); // caught up with a live machine
      return;
    }
    requestAnimationFrame((t) => this._frame(t));
  }
}
