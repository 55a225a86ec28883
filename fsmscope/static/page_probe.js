// What the page shows, for the console and the browser tests (`window.fsmscope`): read-only views of
// the store's state (store.js), and clearNotice().

import { shownStatus } from "./shown.js";

/** Put `window.fsmscope` on the page, reading `store`. */
export function exposeToConsole(store) {
  window.fsmscope = Object.freeze({
    get name() { return store.state.name; },
    get status() { return shownStatus(store.state); }, // the status of the instant shown
    get liveStatus() { return store.state.live; },
    get instant() {
      const { past, status, playing } = store.state.instant;
      return { past, seq: status ? status.last_seq : null, t: status ? status.last_t : null, playing };
    },
    get selected() { return store.state.selected; },
    clearNotice: () => store.clearNotice(),
  });
}
