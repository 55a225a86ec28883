// Who controls the machine shown (docs/debugging.md, "One operator at a time"): the operator lease.
// A worker (heartbeat.js) asks who holds it every second, off the main thread, and sends the
// heartbeat while this page holds it, so a page that is closed or cut off stops beating and the
// server's deadman acts, and a busy one does not. Its answers go to the store (store.js), from which
// the pill says who holds control; "Take control" takes a free lease or, confirmed, another page's.

import { api } from "./api.js";
import { clockText } from "./clocktext.js";
import { setText } from "./dom.js";

const $ = (id) => document.getElementById(id);
const BEAT_MS = 1000; // how often the worker asks (server/lease.py BEAT_EVERY: the heartbeat's period)

export class Lease {
  /**
   * @param {Store} store the page's store (store.js): the machine shown, who holds its lease
   * @param {Controls} controls what controls it (controls.js): whether this page may
   */
  constructor(store, controls) {
    this.store = store;
    this.controls = controls;
    this.watching = null; // the machine the worker watches (null: none)
    this.heart = null; // the worker (heartbeat.js), made when the page first watches a machine
    api.onControl((name) => { // a page's first control takes a free lease: ask at once, to start beating
      if (name === this.watching) this.heart.postMessage({ now: true });
    });
    $("lease-take").addEventListener("click", () => this._take());
    $("lease-release").addEventListener("click", () => this._release());
  }

  /** Have the worker watch the machine shown while this page may control it (call on every change
   * of the machine shown, the machines or the role). */
  watch() {
    const name = this.store.state.name;
    const want = name && !this.controls.refusal() ? name : null;
    if (want === this.watching) return;
    this.watching = want;
    if (want && !this.heart) {
      this.heart = new Worker(new URL("./heartbeat.js", import.meta.url));
      this.heart.onmessage = (message) => this._answered(message.data);
    }
    this.heart?.postMessage(want ? { ...api.leaseWatch(want), every: BEAT_MS } : { lease: null });
    this.store.setLease(null);
  }

  /** The worker's answer: who holds the lease, or that this page lost it (taken over, or lapsed). */
  _answered({ status, body, beat }) {
    if (status === 200) this.store.setLease(body);
    else if (status === 409 && beat) {
      this.store.say(`You no longer control ${this.watching}: ${body?.detail ?? "the lease is gone"}`, "warn", true);
      this.store.setLease(null);
    }
  }

  async _take() {
    const { name, lease } = this.store.state;
    const holder = lease?.holder;
    const takeover = Boolean(holder) && !lease.yours;
    if (takeover && !window.confirm(`${holder.client} controls ${name}. Take control over? That page loses it.`)) return;
    try {
      this.store.setLease(await api.takeLease(name, takeover));
      this.heart.postMessage({ now: true, yours: true }); // beat from now on
      this.store.say(`You control ${name}`, "ok");
    } catch (err) {
      this.store.say("Could not take control: " + (err.detail || err.message), "error", true);
    }
  }

  async _release() {
    const name = this.store.state.name;
    try {
      this.store.setLease(await api.releaseLease(name));
      this.heart.postMessage({ now: true, yours: false });
      this.store.say(`You gave up control of ${name}`, "ok");
    } catch (err) {
      this.store.say("Could not give up control: " + (err.detail || err.message), "error", true);
    }
  }

  /** The pill and the two buttons, from who holds the lease in `state` (the store's). */
  update({ name, lease: s }) {
    const pill = $("lease-state");
    const take = $("lease-take");
    const release = $("lease-release");
    const refusal = this.controls.refusal();
    pill.hidden = !s;
    take.hidden = !s || s.yours || Boolean(refusal);
    release.hidden = !s || !s.yours || Boolean(refusal);
    if (!s) return;
    const deadman = s.deadman.action === "none" ? "" :
      ` If this page goes silent for ${s.deadman.after} s, the machine will ${s.deadman.action}.`;
    let text;
    let title;
    if (s.yours) {
      text = "you control";
      title = `This page controls ${name} since ${clockText(s.holder.since)}.${deadman}`;
    } else if (s.holder) {
      text = "controlled by page " + s.holder.page;
      title = `${s.holder.client} controls ${name} since ${clockText(s.holder.since)}.`;
    } else {
      text = "nobody controls";
      title = `No page controls ${name}: the first to use a control takes it.`;
    }
    setText(pill, text);
    pill.title = title;
    pill.className = "pill lease " + (s.yours ? "yours" : s.holder ? "other" : "free");
    setText(take, s.holder ? "Take control over" : "Take control");
  }
}
