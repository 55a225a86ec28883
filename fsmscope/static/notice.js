// The top bar's notice line and banner, drawn from the store's state (store.js), and what the notice
// says of the machine shown's runs: the outcome, the answer to a preempt, a loop held between two
// runs, a preempt not serviced in time. What the notice says is the store's `notice`, never the
// element's text.

import { holdChange } from "./loop.js";
import { overduePreemptText } from "./preempt.js";

/** Draw the notice line and the banner of `state`. */
export function showNotice(noticeEl, bannerEl, { notice, banner }) {
  noticeEl.textContent = notice.text;
  noticeEl.title = notice.text; // the whole of it, when the top bar leaves it too little room
  noticeEl.className = notice.level ? "notice " + notice.level : "notice";
  bannerEl.textContent = banner;
  bannerEl.hidden = !banner;
}

/** What the notice says of the runs of the machine shown, from its events and this page's preempts. */
export class RunNotices {
  /** @param {Store} store the page's store (store.js): the notice it says, the machine shown */
  constructor(store) {
    this.store = store;
    this.forget();
  }

  /** Another machine is shown: nothing said so far is about it. */
  forget() {
    this.store.clearNotice();
    this.preemptAsked = false;
    this.preemptAck = null; // "Preempt accepted (event N)" once the server answered this page's preempt
    this.heldBy = null; // the seq of a preempt that came between two runs and held the loop (no outcome follows)
    this.finishedText = null; // "NAME finished: outcome 'X'" once the root terminated, until it starts again
    this.overdueText = null; // the notice naming the states that have not serviced a preempt, while shown
  }

  _say(text, level, sticky = true) {
    this.store.say(text, level, sticky);
  }

  /** What the stream's `events` of the machine shown (applied to the store) have the notice say. */
  events(events) {
    const { name, live } = this.store.state;
    for (const ev of events) {
      this._event(ev, name, live.root_path);
      const held = holdChange(ev);
      if (held === null || !this.store.current()?.can_hold) continue;
      this.store.setHeld(held); // what the next poll will say of its loop
      if (ev.action === "preempt") this.heldByPreempt(ev.seq);
    }
  }

  /** What event `ev` of machine `name`, whose root is at `rootPath`, has the notice say. */
  _event(ev, name, rootPath) {
    if (ev.kind === "start" && ev.path === rootPath && this.finishedText) {
      // The previous run's outcome no longer describes the machine; what else the notice says (the
      // answer to the Start that began this run may come before or after its first event) stays.
      if (this.store.state.notice.text.includes(this.finishedText)) this.store.clearNotice();
      this.finishedText = null;
    } else if (ev.kind === "terminate" && ev.path === rootPath) {
      const outcome = ev.outcome === null ? "no outcome" + (ev.error ? ` (${ev.error})` : "") : `outcome '${ev.outcome}'`;
      this.finishedText = `${name} finished: ${outcome}`;
      const text = this.preemptAsked && this.preemptAck ? `${this.preemptAck}: ${this.finishedText}` : this.finishedText;
      this._say(text, ev.outcome === null ? "error" : this.preemptAsked ? "warn" : "ok");
      this.preemptAsked = false;
      this.preemptAck = null;
    } else if (ev.kind === "error") {
      this._say(`${ev.exc_type}: ${ev.message}`, "error");
    }
  }

  /** A preempt with sequence number `seq` came between two runs and held the loop: no outcome will come. */
  heldByPreempt(seq) {
    this.preemptAsked = false;
    this.heldBy = seq;
    this._say(`Preempt accepted (event ${seq}) between two runs: the loop waits for Start`, "warn");
  }

  /** This page asked for a preempt. */
  preemptSent() {
    this.preemptAsked = true;
    this.preemptAck = null;
    this.finishedText = null;
  }

  /** The server accepted this page's preempt as event `seq`; the outcome may have come before this answer. */
  preemptAccepted(seq) {
    if (seq === this.heldBy) return; // the stream has told what it did
    this.preemptAck = `Preempt accepted (event ${seq})`;
    this._say(this.preemptAck + ": " + (this.finishedText || "waiting for the outcome…"), "warn");
  }

  preemptFailed(err) {
    this.preemptAsked = false;
    this._say("Preempt failed: " + (err.detail || err.message), "error");
  }

  /** Name the states of the live status that have not serviced a preempt requested a while ago,
   * counting the seconds; take it back when that no longer holds (unless another notice, such as the
   * outcome, has replaced it). */
  checkOverdue() {
    const status = this.store.state.live;
    const text = status ? overduePreemptText(status, Date.now() / 1000) : null;
    if (text === this.overdueText) return;
    if (text) this._say(text, "warn");
    else if (this.store.state.notice.text === this.overdueText) this.store.clearNotice();
    this.overdueText = text;
  }
}
