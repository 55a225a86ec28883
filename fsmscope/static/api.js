// Fetch wrappers for the REST API (docs/api.md). Same origin, the page's token authenticates
// (token.js); JSON bodies; every failure becomes an ApiError carrying the server's `detail`.

import { authHeaders } from "./token.js";

export class ApiError extends Error {
  constructor(status, detail) {
    super(status ? `${status}: ${detail}` : detail);
    this.status = status; // 0 when the server could not be reached
    this.detail = detail;
  }
}

/** This page's id, sent with every request: the operator lease (docs/debugging.md) is held by a page,
 * not by a token, so that two tabs of one operator are two pages. Random per load. */
export const PAGE_ID = Array.from(crypto.getRandomValues(new Uint8Array(12)), (b) => b.toString(16).padStart(2, "0")).join("");

/** Headers of every request: the token's and this page's id. */
const pageHeaders = () => ({ ...authHeaders(), "X-Fsmscope-Page": PAGE_ID });

/** A read refused for its client's budget of the server's time (429, docs/api.md "Read budget") is asked
 * again after the Retry-After it was told (at most RETRY_MAX_S), up to RETRIES times: the page is slowed,
 * never shown an error for it. */
const RETRIES = 3;
const RETRY_MAX_S = 30;

async function request(method, url, body, accept = "json") {
  const init = { method, credentials: "omit", cache: "no-store", headers: pageHeaders() };
  if (body !== undefined) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  let response;
  for (let attempt = 0; ; attempt++) {
    try {
      response = await fetch(url, init);
    } catch (err) {
      throw new ApiError(0, "server unreachable");
    }
    if (response.status !== 429 || method !== "GET" || attempt >= RETRIES) break;
    const wait = Math.min(Number(response.headers.get("Retry-After")) || 1, RETRY_MAX_S);
    await new Promise((resolve) => setTimeout(resolve, wait * 1000));
  }
  if (!response.ok) {
    let detail = response.statusText || "request failed";
    try {
      const data = await response.json();
      if (data && data.detail !== undefined) {
        detail = typeof data.detail === "string" ? data.detail : JSON.stringify(data.detail);
      }
    } catch (err) { /* not JSON: keep the status text */ }
    throw new ApiError(response.status, detail);
  }
  return accept === "text" ? response.text() : response.json();
}

const machine = (name) => "/api/machines/" + encodeURIComponent(name);

/** The websocket address of `path` on this page's server. */
const wsUrl = (path) => `${location.protocol === "https:" ? "wss:" : "ws:"}//${location.host}${path}`;

const controlListeners = new Set();

/** A control of machine `name` (one the lease covers): the listeners hear of each one accepted. */
async function control(method, name, path, body) {
  const answer = await request(method, machine(name) + path, body);
  for (const listener of controlListeners) listener(name);
  return answer;
}

/** `?a=1&b=2&b=3` of the defined entries of `params`, an array giving a key once per item ("" when none). */
function query(params) {
  const qs = new URLSearchParams();
  for (const [key, value] of Object.entries(params || {})) {
    for (const item of [].concat(value ?? [])) qs.append(key, item);
  }
  const text = qs.toString();
  return text ? "?" + text : "";
}

export const api = {
  machines: () => request("GET", "/api/machines"),
  scene: () => request("GET", "/api/scene"),
  /** What this page's token lets it do: {role: "operator" | "viewer"}. */
  session: () => request("GET", "/api/session"),
  status: (name) => request("GET", machine(name) + "/status"),
  /** The status right after event {seq}, or after the last event at time {t} (docs/api.md, "Time travel"). */
  statusAt: (name, at) => request("GET", machine(name) + "/status" + query(at)),
  /** A page of the machine's events: {since, until, limit, kinds, path, order}. */
  history: (name, params) => request("GET", machine(name) + "/history" + query(params)),
  /** Bands, ticks and runs of the machine's timeline: {since_t, until_t, buckets}. */
  timeline: (name, params) => request("GET", machine(name) + "/timeline" + query(params)),
  /** Each state's visits, time in state and last outcome, as `fsmscope replay` counts them ({path}: only that one). */
  summary: (name, path) => request("GET", machine(name) + "/summary" + query({ path })),
  /** Show a recorded pose in this page's own 3D view, `view` (static/scene.js; null: back to the live arm). */
  scenePose: (view, pose) => request("POST", "/api/scene/pose", { view, pose }),
  graphSvg: (name, expand) => request("GET", machine(name) + "/graph.svg" + query({ expand }), undefined, "text"),
  anyOpenSet: true, // the server lays out any set of open containers (semantic zoom asks for them)
  preempt: (name, reason) => request("POST", machine(name) + "/preempt", { reason: reason || "" }),
  setInitialState: (name, path, states, userdata) => control("POST", name, "/initial-state", { path, states, userdata }),
  start: (name) => control("POST", name, "/start", {}),
  hold: (name, reason) => request("POST", machine(name) + "/hold", { reason: reason || "" }),
  pause: (name) => control("POST", name, "/pause"),
  resume: (name) => control("POST", name, "/resume"),
  /** One transition, then hold again; `level` a container's path: at its next transition (a step over). */
  step: (name, level = null) => control("POST", name, "/step", { level }),
  force: (name, state, outcome) => control("POST", name, "/force", { state, outcome }),
  /** Replace the machine's whole set of breakpoints (docs/debugging.md). */
  setBreakpoints: (name, breakpoints) => control("PUT", name, "/breakpoints", { breakpoints }),
  /** Call `listener(name)` after each accepted control that the lease covers (a page's first one takes it). */
  onControl: (listener) => controlListeners.add(listener),
  takeLease: (name, takeover) => request("POST", machine(name) + "/lease", { takeover }),
  /** What heartbeat.js asks, off the main thread: `lease` (GET, as lease()) and `beat` (POST: the
   * holder's heartbeat, answered as lease() is, or 409 when this page lost the lease), with `headers`. */
  leaseWatch: (name) => ({ lease: machine(name) + "/lease", beat: machine(name) + "/lease/beat", headers: pageHeaders() }),
  releaseLease: (name) => request("DELETE", machine(name) + "/lease"),
  streamUrl(name, since) {
    const qs = since ? "?since=" + encodeURIComponent(since) : "";
    return wsUrl(`${machine(name)}/stream${qs}`);
  },
  /** The fleet overview's stream (fleet.js). */
  overviewUrl: () => wsUrl("/api/overview/stream"),
};
