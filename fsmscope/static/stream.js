// One machine's websocket stream (docs/api.md): snapshot / events / missed frames, reconnect
// with backoff resuming from the last seq seen, and the numbers the connection badge shows.

import { streamProtocols } from "./token.js";

/** @typedef {import("./schema.js").SnapshotFrame} SnapshotFrame */
/** @typedef {import("./schema.js").EventsFrame} EventsFrame */
/** @typedef {import("./schema.js").MissedFrame} MissedFrame */
/** @typedef {import("./schema.js").PaceFrame} PaceFrame */

const RATE_WINDOW_MS = 3000;
const BACKOFF_MIN_MS = 250;
const BACKOFF_MAX_MS = 4000;

export class Stream {
  /**
   * @param {string} name machine name
   * @param {object} handlers {snapshot(status, lastSeq, history), events(list), missed(count), state(state, detail)}
   *   status: a MachineStatus, history: a History, list: FsmEvents (static/schema.js's typedefs)
   *   history (on a new connection only, else null): {complete, events}, the current run's events
   *   up to the snapshot, for the log (already in the snapshot's status: not to be applied again)
   * @param {object} options {url(name, since) -> ws url, checkResume(since) -> Promise<boolean>}
   *   checkResume is asked before a reconnect whether `since` still makes sense (false: the
   *   server restarted and its seqs start again, so ask for a snapshot instead).
   */
  constructor(name, handlers, options) {
    this.name = name;
    this.handlers = handlers;
    this.options = options;
    this.ws = null;
    this.lastSeq = 0;
    this.state = "idle";
    this.stopped = false;
    this.failures = 0;
    this.timer = null;
    this.missed = 0;
    this.latencyMs = null;
    this.arrivals = []; // [ms timestamp, count]
    this.connects = 0;
    this.paceMs = 0;
  }

  /** Ask for at most one frame every `ms` (0: each as it comes), now and after any reconnect. */
  pace(ms) {
    if (ms === this.paceMs) return;
    this.paceMs = ms;
    this._sendPace();
  }

  _sendPace() {
    /** @type {PaceFrame} */
    const frame = { type: "pace", ms: this.paceMs };
    if (this.ws?.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(frame));
  }

  start() {
    this.stopped = false;
    this._open(0);
  }

  stop() {
    this.stopped = true;
    clearTimeout(this.timer);
    if (this.ws) {
      this.ws.onclose = this.ws.onmessage = this.ws.onerror = null;
      this.ws.close();
      this.ws = null;
    }
    this._setState("closed");
  }

  /** Events per second over the last few seconds. */
  rate() {
    const now = performance.now();
    while (this.arrivals.length && now - this.arrivals[0][0] > RATE_WINDOW_MS) this.arrivals.shift();
    let n = 0;
    for (const [, count] of this.arrivals) n += count;
    return n / (RATE_WINDOW_MS / 1000);
  }

  _setState(state, detail) {
    this.state = state;
    if (this.handlers.state) this.handlers.state(state, detail);
  }

  _open(since) {
    if (this.stopped) return;
    this._setState(this.connects ? "reconnecting" : "connecting");
    const ws = new WebSocket(this.options.url(this.name, since), streamProtocols());
    this.ws = ws;
    ws.onopen = () => {
      this.failures = 0;
      this.connects += 1;
      if (this.paceMs) this._sendPace();
      this._setState("live");
    };
    ws.onmessage = (msg) => this._onFrame(msg.data);
    ws.onclose = () => {
      if (this.ws !== ws) return;
      this.ws = null;
      this._scheduleReconnect();
    };
    ws.onerror = () => { /* onclose follows */ };
  }

  _scheduleReconnect() {
    if (this.stopped) return;
    this.failures += 1;
    this._setState("reconnecting", this.failures);
    const base = Math.min(BACKOFF_MAX_MS, BACKOFF_MIN_MS * 2 ** (this.failures - 1));
    const delay = base * (0.75 + Math.random() * 0.5);
    this.timer = setTimeout(() => this._reconnect(), delay);
  }

  async _reconnect() {
    if (this.stopped) return;
    let since = this.lastSeq;
    if (since && this.options.checkResume) {
      try {
        if (!(await this.options.checkResume(since))) since = 0;
      } catch (err) {
        // Still unreachable (or refused): wait and try again.
        if (this.handlers.state) this.handlers.state("reconnecting", this.failures, err);
        this._scheduleReconnect();
        return;
      }
    }
    this._open(since);
  }

  /** One frame of the stream (static/schema.js: SnapshotFrame, EventsFrame, MissedFrame). */
  _onFrame(data) {
    /** @type {SnapshotFrame|EventsFrame|MissedFrame} */
    let frame;
    try {
      frame = JSON.parse(data);
    } catch (err) {
      return;
    }
    if (frame.type === "snapshot") {
      this.lastSeq = frame.last_seq ?? frame.status?.last_seq ?? 0;
      this.handlers.snapshot(frame.status, this.lastSeq, frame.history ?? null);
    } else if (frame.type === "events") {
      const fresh = [];
      for (const event of frame.events || []) {
        if (event.seq <= this.lastSeq) continue; // already seen (a resume overlap)
        if (this.lastSeq && event.seq > this.lastSeq + 1) this.missed += event.seq - this.lastSeq - 1;
        this.lastSeq = event.seq;
        fresh.push(event);
      }
      if (!fresh.length) return;
      const last = fresh[fresh.length - 1];
      if (typeof last.t === "number") {
        const latency = Math.max(0, Date.now() - last.t * 1000);
        this.latencyMs = this.latencyMs === null ? latency : this.latencyMs * 0.8 + latency * 0.2;
      }
      this.arrivals.push([performance.now(), fresh.length]);
      this.handlers.events(fresh);
    } else if (frame.type === "missed") {
      this.missed += frame.count || 0;
      if (this.handlers.missed) this.handlers.missed(frame.count || 0);
    }
  }
}
