// The stream of the machine shown (stream.js) into the store (store.js): its snapshot and events
// become the live status, its connection the badge's state; the event log and the notices hear of the
// events too (they keep what they say of them). One stream at a time: a stream stopped for another
// machine's says nothing more.

import { SCHEMA_VERSION } from "./schema.js";
import { Stream } from "./stream.js";

export class Feed {
  /**
   * @param {Store} store the page's store
   * @param {object} api the REST API (api.js): streamUrl, machines
   * @param {object} handlers {history({complete, events}): a new connection's run so far, for the log;
   *   events(applied, all): the events just applied (of a schema this page knows) and all of them, for
   *   the log; missed(count): events the server could not send}
   */
  constructor(store, api, handlers) {
    this.store = store;
    this.api = api;
    this.handlers = handlers;
    this.stream = null;
  }

  /** Follow machine `name` (the store shows it already), from a snapshot. */
  open(name) {
    this.stream?.stop();
    const stream = new Stream(name, {
      snapshot: (status, lastSeq, history) => {
        this.store.load(status);
        if (history) this.handlers.history(history); // for the log only: the status has it
      },
      events: (events) => {
        const known = events.filter((ev) => ev.v === undefined || ev.v === SCHEMA_VERSION); // a schema this page knows
        this.store.apply(known);
        this.handlers.events(known, events);
      },
      missed: (count) => this.handlers.missed(count),
      state: (state) => {
        if (stream === this.stream) this.store.setConnection(state);
      },
    }, {
      url: (n, since) => this.api.streamUrl(n, since),
      checkResume: async (since) => {
        // A restarted server numbers its events from 1 again: then ask for a snapshot.
        const entry = (await this.api.machines()).find((m) => m.name === name);
        return Boolean(entry) && entry.last_seq >= since;
      },
    });
    this.stream = stream;
    stream.start();
  }

  /** Ask for at most one frame every `ms` (0: each as it comes). */
  pace(ms) {
    this.stream?.pace(ms);
  }
}
