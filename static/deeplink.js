// The page's address names what it shows: `#m=NAME` the machine, `&seq=N` the event looked back at,
// so a copied address opens the same machine at the same instant.

import { isMachineName } from "./schema.js";

/** {machine, seq} the address names (null when it does not: a name no machine can have names none). */
export function readLink() {
  const params = new URLSearchParams(location.hash.slice(1));
  const seq = Number(params.get("seq"));
  const machine = params.get("m");
  return { machine: isMachineName(machine) ? machine : null, seq: params.has("seq") && Number.isSafeInteger(seq) && seq >= 0 ? seq : null };
}

/** Say in the address that the page shows machine `name`, at event `seq` (null: live). */
export function writeLink(name, seq) {
  const params = new URLSearchParams({ m: name });
  if (seq !== null && seq !== undefined) params.set("seq", String(seq));
  const hash = "#" + params.toString();
  if (location.hash !== hash) history.replaceState(null, "", hash);
}

const FOLLOW_MS = 250; // browsers throttle replaceState: the address follows the page at most this often

/** The address following what the page's store (store.js) shows: the machine, the instant looked at. */
export class LinkFollower {
  constructor(store) {
    this.store = store;
    this.timer = null;
  }

  /** Name what the store shows now, in at most FOLLOW_MS. */
  update() {
    if (this.timer) return;
    this.timer = setTimeout(() => {
      this.timer = null;
      const { name, instant } = this.store.state;
      if (name !== null) writeLink(name, instant.past ? instant.status.last_seq : null);
    }, FOLLOW_MS);
  }
}
