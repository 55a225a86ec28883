// A machine its host runs in a loop (the demo's episodes; can_hold in /api/machines): "Stop after
// this run", and a loop held until Start. `held` in /api/machines is the truth; the machine's
// control events on the stream tell it sooner than the next poll.

/** What an event says of the loop: true (held until Start), false (released by a start) or null (nothing). */
export function holdChange(ev) {
  if (ev.kind !== "control" || ev.result !== "accepted") return null;
  if (ev.params?.until === "start") return true; // a hold, or a preempt that came between two runs
  return ev.action === "start" ? false : null;
}

/** What a held loop waits for: the end of the running run, then Start. */
export const heldText = (running) => (running ? "stops after this run" : "waiting for Start");
