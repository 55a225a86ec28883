// A preempt that some state does not service: once it is PREEMPT_GRACE_S old, the page names the
// active states that have not serviced it and says for how long it has waited.

const PREEMPT_GRACE_S = 3;

/** What to say at `now` (wall-clock seconds) about a preempt not serviced in time; null: nothing. */
export function overduePreemptText(status, now) {
  const age = status.preempt ? Math.floor(now - status.preempt.t) : 0;
  if (age < PREEMPT_GRACE_S) return null;
  const waiting = status.preemptWaitingOn();
  if (!waiting.length) return null;
  return `Preempt requested ${age} s ago: ${waiting.join(", ")} ${waiting.length === 1 ? "has" : "have"} not serviced it`;
}
