// The top bar's notice line and banner, and what the notice says of the machine shown's runs: the
// outcome, the answer to a preempt, a loop held between two runs, a preempt not serviced in time.

import { overduePreemptText } from "./preempt.js";

const $ = (id) => document.getElementById(id);
let timer = null;

/** Say `text` (level info, ok, warn or error); a notice that is not `sticky` goes after 8 s. */
export function notice(text, level = "info", sticky = false) {
  const el = $("notice");
  el.textContent = text;
  el.title = text; // the whole of it, when the top bar leaves it too little room
  el.className = "notice " + level;
  clearTimeout(timer);
  if (!sticky) timer = setTimeout(clearNotice, 8000);
}

export function clearNotice() {
  clearTimeout(timer);
  $("notice").textContent = $("notice").title = "";
  $("notice").className = "notice";
}

/** The line above the page (empty `text`: none). */
export function banner(text) {
  const el = $("banner");
  el.textContent = text || "";
  el.hidden = !text;
}

/** What the notice says of the runs of the machine shown, from its events and this page's preempts. */
export class RunNotices {
  constructor() {
    this.forget();
  }

  /** Another machine is shown: nothing said so far is about it. */
  forget() {
    clearNotice();
    this.preemptAsked = false;
    this.preemptAck = null; // "Preempt accepted (event N)" once the server answered this page's preempt
    this.heldBy = null; // the seq of a preempt that came between two runs and held the loop (no outcome follows)
    this.finishedText = null; // "NAME finished: outcome 'X'" once the root terminated, until it starts again
    this.overdueText = null; // the notice naming the states that have not serviced a preempt, while shown
  }

  /** What event `ev` of machine `name`, whose root is at `rootPath`, has the notice say. */
  event(ev, name, rootPath) {
    if (ev.kind === "start" && ev.path === rootPath && this.finishedText) {
      // The previous run's outcome no longer describes the machine; what else the notice says (the
      // answer to the Start that began this run may come before or after its first event) stays.
      if ($("notice").textContent.includes(this.finishedText)) clearNotice();
      this.finishedText = null;
    } else if (ev.kind === "terminate" && ev.path === rootPath) {
      const outcome = ev.outcome === null ? "no outcome" + (ev.error ? ` (${ev.error})` : "") : `outcome '${ev.outcome}'`;
      this.finishedText = `${name} finished: ${outcome}`;
      const text = this.preemptAsked && this.preemptAck ? `${this.preemptAck}: ${this.finishedText}` : this.finishedText;
      notice(text, ev.outcome === null ? "error" : this.preemptAsked ? "warn" : "ok", true);
      this.preemptAsked = false;
      this.preemptAck = null;
    } else if (ev.kind === "error") {
      notice(`${ev.exc_type}: ${ev.message}`, "error", true);
    }
  }

  /** A preempt with sequence number `seq` came between two runs and held the loop: no outcome will come. */
  heldByPreempt(seq) {
    this.preemptAsked = false;
    this.heldBy = seq;
    notice(`Preempt accepted (event ${seq}) between two runs: the loop waits for Start`, "warn", true);
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
    notice(this.preemptAck + ": " + (this.finishedText || "waiting for the outcome…"), "warn", true);
  }

  preemptFailed(err) {
    this.preemptAsked = false;
    notice("Preempt failed: " + (err.detail || err.message), "error", true);
  }

  /** Name the states of `status` that have not serviced a preempt requested a while ago, counting the
   * seconds; take it back when that no longer holds (unless another notice, such as the outcome, has
   * replaced it). */
  checkOverdue(status) {
    const text = status ? overduePreemptText(status, Date.now() / 1000) : null;
    if (text === this.overdueText) return;
    if (text) notice(text, "warn", true);
    else if ($("notice").textContent === this.overdueText) clearNotice();
    this.overdueText = text;
  }
}
