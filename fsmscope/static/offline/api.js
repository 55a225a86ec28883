// static/api.js for a page written by `fsmscope export` (server/export_html.py puts this module in
// its place): the same `api` and `ApiError`, answered from the recording in the file (recording.js)
// with the REST API's shapes; nothing to control, no 3D view, no server.

import { ApiError } from "../api.js";
import { machineList, recorded } from "./recording.js";

export { ApiError };

/** A promise of `compute()`, as a request would give it (an ApiError rejects it). */
const answer = (compute) => new Promise((resolve) => resolve(compute()));

const refuse = () => Promise.reject(new ApiError(409, "this is a recording in a file: nothing to control"));

export const api = {
  machines: () => answer(machineList),
  scene: () => answer(() => ({ url: null })),
  session: () => answer(() => ({ role: "operator" })), // every control answers that there is nothing to control
  status: (name) => answer(() => recorded(name).statusAt()),
  statusAt: (name, at) => answer(() => recorded(name).statusAt(at)),
  history: (name, params) => answer(() => recorded(name).history(params)),
  timeline: (name, params) => answer(() => recorded(name).timeline(params)),
  scenePose: () => Promise.reject(new ApiError(404, "this file has no 3D view")),
  summary: (name, path) => answer(() => recorded(name).summary(path)),
  graphSvg: (name, expand) => answer(() => recorded(name).graphSvg(expand)),
  anyOpenSet: false, // the file holds the drawings of the depth menu's levels only: no semantic zoom
  preempt: refuse,
  setInitialState: refuse,
  start: refuse,
  hold: refuse,
  pause: refuse,
  resume: refuse,
  step: refuse,
  force: refuse,
  setBreakpoints: refuse,
  onControl: () => {},
  takeLease: refuse,
  leaseWatch: () => null,
  releaseLease: refuse,
  streamUrl: () => "",
};
