// Who controls the machine shown (docs/debugging.md, "One operator at a time"): the operator lease.
// A worker (heartbeat.js) asks who holds it every second, off the main thread, and sends the
// heartbeat while this page holds it, so a page that is closed or cut off stops beating and the
// server's deadman acts, and a busy one does not. The pill says
// who holds control; "Take control" takes a free lease or, confirmed, another page's.

import { api } from "./api.js";
import { clockText } from "./clocktext.js";
import { setText } from "./dom.js";
import { notice } from "./notice.js";

const $ = (id) => document.getElementById(id);
const BEAT_MS = 1000; // how often the worker asks (server/lease.py BEAT_EVERY: the heartbeat's period)

export class Lease {
  /**
   * @param {Store} store the machine shown (store.js)
   * @param {Controls} controls what controls it (controls.js): whether this page may
   */
  constructor(store, controls) {
    this.store = store;
    this.controls = controls;
    this.state = null; // the last answer about the machine shown, null when unknown
    this.name = null; // the machine shown
    this.watching = null; // the machine the worker watches (null: none)
    this.heart = null; // the worker (heartbeat.js), made when the page first watches a machine
    api.onControl((name) => { // a page's first control takes a free lease: ask at once, to start beating
      if (name === this.watching) this.heart.postMessage({ now: true });
    });
    $("lease-take").addEventListener("click", () => this._take());
    $("lease-release").addEventListener("click", () => this._release());
  }

  /** Follow the machine shown and whether this page may control it (call on every controls update). */
  update() {
    this.name = this.store.name;
    const want = this.name && !this.controls.refusal() ? this.name : null;
    if (want !== this.watching) {
      this.watching = want;
      this.state = null;
      if (want && !this.heart) {
        this.heart = new Worker(new URL("./heartbeat.js", import.meta.url));
        this.heart.onmessage = (message) => this._answered(message.data);
      }
      this.heart?.postMessage(want ? { ...api.leaseWatch(want), every: BEAT_MS } : { lease: null });
    }
    this._show();
  }

  /** The worker's answer: who holds the lease, or that this page lost it (taken over, or lapsed). */
  _answered({ status, body, beat }) {
    if (status === 200) this.state = body;
    else if (status === 409 && beat) {
      notice(`You no longer control ${this.watching}: ${body?.detail ?? "the lease is gone"}`, "warn", true);
      this.state = null;
    }
    this._show();
  }

  async _take() {
    const name = this.name;
    const holder = this.state?.holder;
    const takeover = Boolean(holder) && !this.state.yours;
    if (takeover && !window.confirm(`${holder.client} controls ${name}. Take control over? That page loses it.`)) return;
    try {
      this.state = await api.takeLease(name, takeover);
      this.heart.postMessage({ now: true, yours: true }); // beat from now on
      notice(`You control ${name}`, "ok");
    } catch (err) {
      notice("Could not take control: " + (err.detail || err.message), "error", true);
    }
    this._show();
  }

  async _release() {
    const name = this.name;
    try {
      this.state = await api.releaseLease(name);
      this.heart.postMessage({ now: true, yours: false });
      notice(`You gave up control of ${name}`, "ok");
    } catch (err) {
      notice("Could not give up control: " + (err.detail || err.message), "error", true);
    }
    this._show();
  }

  /** The pill and the two buttons, from the last answer. */
  _show() {
    const pill = $("lease-state");
    const take = $("lease-take");
    const release = $("lease-release");
    const refusal = this.controls.refusal();
    const s = this.state;
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
      title = `This page controls ${this.name} since ${clockText(s.holder.since)}.${deadman}`;
    } else if (s.holder) {
      text = "controlled by page " + s.holder.page;
      title = `${s.holder.client} controls ${this.name} since ${clockText(s.holder.since)}.`;
    } else {
      text = "nobody controls";
      title = `No page controls ${this.name}: the first to use a control takes it.`;
    }
    setText(pill, text);
    pill.title = title;
    pill.className = "pill lease " + (s.yours ? "yours" : s.holder ? "other" : "free");
    setText(take, s.holder ? "Take control over" : "Take control");
  }
}
