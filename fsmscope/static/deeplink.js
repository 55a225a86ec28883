// The page's address names what it shows: `#m=NAME` the machine, `&seq=N` the event looked back at,
// so a copied address opens the same machine at the same instant (for whoever has access: token.js,
// access.js), and a hash changed in the tab is followed.

import { isMachineName } from "./schema.js";

/** {machine, seq} the address names (null when it does not: a name no machine can have names none). */
export function readLink() {
  const params = new URLSearchParams(location.hash.slice(1));
  const seq = Number(params.get("seq"));
  const machine = params.get("m");
  return { machine: isMachineName(machine) ? machine : null, seq: params.has("seq") && Number.isSafeInteger(seq) && seq >= 0 ? seq : null };
}

/** The hash that names machine `name` at event `seq` (null: live). */
function hashOf(name, seq) {
  const params = new URLSearchParams({ m: name });
  if (seq !== null && seq !== undefined) params.set("seq", String(seq));
  return "#" + params.toString();
}

/** Say in the address that the page shows machine `name`, at event `seq` (null: live). */
export function writeLink(name, seq) {
  const hash = hashOf(name, seq);
  if (location.hash !== hash) history.replaceState(null, "", hash);
}

/** The whole address of machine `name` at event `seq` (null: live), with no token: what a user shares. */
export function linkTo(name, seq) {
  return location.origin + location.pathname + hashOf(name, seq);
}

const FOLLOW_MS = 250; // browsers throttle replaceState: the address follows the page at most this often

/** The address following what the page's store (store.js) shows: the machine, the instant looked at. */
export class LinkFollower {
  /** @param {() => boolean} seeking whether the page is on its way to another instant (the address then
   * keeps naming the one asked for, not the one shown until it arrives) */
  constructor(store, seeking) {
    this.store = store;
    this.seeking = seeking;
    this.timer = null;
    this.pending = false;
  }

  /** Name what the store shows now: at once, or (after a change less than FOLLOW_MS ago) when that has passed. */
  update() {
    if (this.timer) {
      this.pending = true;
      return;
    }
    this._write();
    this.timer = setTimeout(() => {
      this.timer = null;
      if (this.pending) this.update();
    }, FOLLOW_MS);
  }

  _write() {
    this.pending = false;
    const { name, instant } = this.store.state;
    if (name !== null && !this.seeking()) writeLink(name, instant.past ? instant.status.last_seq : null);
  }
}

/** Call `follow(link)` with what the address names each time the user changes its hash in the tab
 * (writeLink's replaceState fires no hashchange, so the page's own writes are not followed back). */
export function onLinkChanged(follow) {
  window.addEventListener("hashchange", () => follow(readLink()));
}
