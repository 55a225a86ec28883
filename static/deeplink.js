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
