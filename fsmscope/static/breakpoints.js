// Breakpoints from the page: the state menu's "Break before", "Break after", "Break when…" and
// "Remove breakpoint", and which states the graph and the tree mark. The set is the machine's own
// (`status.debug.breakpoints`, from its events): the page keeps no copy of it, it reads the set, adds
// or removes, and replaces it whole (PUT), so two pages never disagree on what is set.

import { api } from "./api.js";
import { editBreakpoint } from "./dialogs.js";
import { showsLive } from "./shown.js";
import { breakpointText } from "./transcript.js";

/** @typedef {import("./schema.js").Breakpoint} Breakpoint */

/** The states of `status` (a Status) with a breakpoint, and those where the machine holds. */
export function debugMarks(status) {
  const debug = status.debug;
  return {
    breakpoints: [...new Set((debug?.breakpoints ?? []).map((bp) => bp.state))],
    held: (debug?.holds ?? []).map((hold) => hold.path + "/" + hold.state),
  };
}

export class Breakpoints {
  /**
   * @param {Store} store the page's store (store.js)
   * @param {Controls} controls its controls (controls.js): why this page may not control it, and `ask`
   */
  constructor(store, controls) {
    this.store = store;
    this.controls = controls;
  }

  /** The state menu's breakpoint items for the state at `path`, disabled (the item saying why) when
   * the server would refuse them or the page is not showing the live machine. */
  items(path) {
    const own = this._set().filter((bp) => bp.state === path);
    const why = path === this.store.state.live.root_path ? "the root is in no container that could hold it"
      : this.controls.refusal() || (showsLive(this.store.state) ? "" : "not live: go back to live to set breakpoints");
    const item = (label, action, title = why) => ({ label, action, disabled: Boolean(why), title });
    /** @type {(at: string) => Breakpoint} */
    const breakpoint = (at) => ({ state: path, at, outcome: null, when: null });
    const add = (what, at) => () => this._replace(what, (set) => [...set, breakpoint(at)]);
    const items = [
      item("Break before", add("Break before", "before")),
      item("Break after", add("Break after", "after")),
      item("Break when…", () => this._edit(path)),
    ];
    if (own.length) {
      const label = own.length === 1 ? "Remove breakpoint" : `Remove ${own.length} breakpoints`;
      items.push(item(label, () => this._replace(label, (set) => set.filter((bp) => bp.state !== path)),
        why || own.map(breakpointText).join("; ")));
    }
    return items;
  }

  /** The machine's breakpoints as its live status says now. */
  _set() {
    return this.store.state.live.debug?.breakpoints ?? [];
  }

  /** Replace the set by `change(set)`; a notice says how the server answered. */
  _replace(what, change) {
    this.controls.ask(what, (name) => api.setBreakpoints(name, change(this._set())));
  }

  /** "Break when…": the dialog stays open on the server's refusal, which it shows. */
  _edit(path) {
    editBreakpoint({
      state: path, outcomes: this.store.state.nodes.get(path)?.outcomes ?? [],
      submit: (bp) => api.setBreakpoints(this.store.state.name, [...this._set(), bp]),
    });
  }
}
