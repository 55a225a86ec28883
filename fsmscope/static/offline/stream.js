// static/stream.js for a page written by `fsmscope export`: the recording in the file is over, so
// its "stream" says once what the live one says on connecting (the status at the end, and the
// last run's events for the log) and then nothing more.

import { recorded } from "./recording.js";

const HISTORY = 5000; // events of the run sent for the log, as server/fanout.py's HISTORY

export class Stream {
  /** The handlers and options of static/stream.js's Stream (only snapshot and state are called; pace is
   * taken and has nothing to do). */
  constructor(name, handlers) {
    this.name = name;
    this.handlers = handlers;
    this.lastSeq = 0;
    this.state = "idle";
    this.missed = 0;
    this.latencyMs = null;
    this.stopped = false;
  }

  start() {
    this.stopped = false;
    setTimeout(() => this._snapshot(), 0); // after the caller's set-up, as a socket's first frame comes
  }

  stop() {
    this.stopped = true;
    this._setState("closed");
  }

  rate() {
    return 0;
  }

  /** Nothing comes after the snapshot, so there is nothing to pace. */
  pace() {}

  _setState(state) {
    this.state = state;
    if (this.handlers.state) this.handlers.state(state);
  }

  _snapshot() {
    if (this.stopped) return;
    const machine = recorded(this.name);
    this._setState("live");
    this.lastSeq = machine.end.last_seq;
    this.handlers.snapshot(machine.end, this.lastSeq, machine.runEvents(HISTORY));
  }
}
