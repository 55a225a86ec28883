// Who controls the machine shown (docs/debugging.md, "One operator at a time"): the operator lease.
// While the page holds the lease a worker (heartbeat.js) sends its heartbeat, so a page that is
// closed or cut off stops beating and the server's deadman acts; otherwise the page asks who holds it. The pill says
// who holds control; "Take control" takes a free lease or, confirmed, another page's.

import { api } from "./api.js";
import { clockText } from "./clocktext.js";
import { notice } from "./notice.js";

const $ = (id) => document.getElementById(id);
const POLL_MS = 2000; // how often a page that does not hold the lease asks who does

export class Lease {
  /**
   * @param {Store} store the machine shown (store.js)
   * @param {Controls} controls what controls it (controls.js): whether this page may
   */
  constructor(store, controls) {
    this.store = store;
    this.controls = controls;
    this.state = null; // the last answer about the machine shown, null when unknown
    this.name = null; // the machine that answer is of
    this.timer = null;
    this.heart = null; // the heartbeat worker (heartbeat.js), made when this page first holds a lease
    this.beating = null; // the machine it beats for
    api.onControl((name) => { // a page's first control takes a free lease: ask at once, to start beating
      if (name === this.name && !this.state?.yours) this._schedule(0);
    });
    $("lease-take").addEventListener("click", () => this._take());
    $("lease-release").addEventListener("click", () => this._release());
  }

  /** Follow the machine shown (call when it changes and on every controls update). */
  update() {
    if (this.store.name !== this.name) {
      this.name = this.store.name;
      this._answered(null);
      this._schedule(0);
    }
    this._show();
  }

  _schedule(ms) {
    clearTimeout(this.timer);
    this.timer = setTimeout(() => this._poll(), ms);
  }

  /** Ask who holds the lease (the heartbeat's answers say it while this page holds it). */
  async _poll() {
    const name = this.name;
    if (name && !this.controls.refusal() && !this.state?.yours) {
      try {
        const state = await api.lease(name);
        if (name === this.name) this._answered(state);
      } catch (err) {
        if (name === this.name) this._answered(null);
      }
    }
    this._schedule(POLL_MS);
  }

  /** A new answer about the machine shown: show it, and beat while it says this page holds the lease. */
  _answered(state) {
    this.state = state;
    const beatFor = state?.yours ? this.name : null;
    if (beatFor !== this.beating) {
      this.beating = beatFor;
      if (beatFor && !this.heart) {
        this.heart = new Worker(new URL("./heartbeat.js", import.meta.url));
        this.heart.onmessage = (message) => this._beaten(message.data);
      }
      const request = beatFor ? api.beatRequest(beatFor) : null;
      this.heart?.postMessage(request ? { ...request, every: state.beat_every * 1000 } : { url: null });
    }
    this._show();
  }

  /** The heartbeat's answer: the lease as before, or lost (another page took it over, or it lapsed). */
  _beaten({ status, body }) {
    const name = this.beating;
    if (name !== this.name) return;
    if (status === 200) this._answered(body);
    else if (status === 409) {
      notice(`You no longer control ${name}: ${body?.detail ?? "the lease is gone"}`, "warn", true);
      this._answered(null);
    }
  }

  async _take() {
    const name = this.name;
    const holder = this.state?.holder;
    const takeover = Boolean(holder) && !this.state.yours;
    if (takeover && !window.confirm(`${holder.client} controls ${name}. Take control over? That page loses it.`)) return;
    try {
      this._answered(await api.takeLease(name, takeover));
      notice(`You control ${name}`, "ok");
    } catch (err) {
      notice("Could not take control: " + (err.detail || err.message), "error", true);
    }
  }

  async _release() {
    const name = this.name;
    try {
      this._answered(await api.releaseLease(name));
      notice(`You gave up control of ${name}`, "ok");
    } catch (err) {
      notice("Could not give up control: " + (err.detail || err.message), "error", true);
    }
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
    if (pill.textContent !== text) pill.textContent = text;
    pill.title = title;
    pill.className = "pill lease " + (s.yours ? "yours" : s.holder ? "other" : "free");
    take.textContent = s.holder ? "Take control over" : "Take control";
  }
}
