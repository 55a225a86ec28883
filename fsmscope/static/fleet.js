// The fleet overview page (fleet.html): a tile per machine the server knows, streamed from
// /api/overview/stream (server/overview.py), filtered and sorted as the address says
// (#q=TEXT&state=failed&sort=state), each tile a link to that machine's full dashboard.

import { api } from "./api.js";
import { setText } from "./dom.js";
import { FleetTiles } from "./fleet_tiles.js";
import { countStates, STATES, visibleTiles } from "./fleet_view.js";
import { streamProtocols } from "./token.js";

const $ = (id) => document.getElementById(id);
const RETRY_MS = [500, 1000, 2000, 5000];

const tiles = new FleetTiles($("tiles"));
let latest = { tiles: [], now: 0, at: performance.now() }; // the last frame, and when it came
let failures = 0;

/** The page's choices, from the address (a copied address shows the same view). */
function choices() {
  const params = new URLSearchParams(location.hash.slice(1));
  return { text: params.get("q") || "", state: params.get("state") || "", sort: params.get("sort") || "robot" };
}

function writeChoices() {
  const params = new URLSearchParams();
  if ($("filter").value) params.set("q", $("filter").value);
  if ($("state-filter").value) params.set("state", $("state-filter").value);
  if ($("sort").value !== "robot") params.set("sort", $("sort").value);
  const hash = params.toString() ? "#" + params.toString() : "";
  if (location.hash !== hash) history.replaceState(null, "", location.pathname + location.search + hash);
  render();
}

function render() {
  const now = latest.now + (performance.now() - latest.at) / 1000; // the server's clock, moved on since
  const shown = visibleTiles(latest.tiles, choices());
  tiles.show(shown, now);
  const counts = countStates(latest.tiles);
  const summary = [`${latest.tiles.length} machine${latest.tiles.length === 1 ? "" : "s"}`,
    ...STATES.filter((s) => counts[s]).map((s) => `${counts[s]} ${s === "done" ? "finished" : s}`)].join(" · ");
  setText($("fleet-summary"), summary);
  $("empty").hidden = shown.length > 0;
  $("empty").textContent = latest.tiles.length ? "No machine matches." : "No machine yet.";
}

function connect() {
  const ws = new WebSocket(api.overviewUrl(), streamProtocols());
  ws.onmessage = (message) => {
    /** @type {import("./schema.js").Frame} */
    const frame = JSON.parse(message.data);
    if (frame.type !== "overview") return;
    failures = 0;
    latest = { tiles: frame.tiles, now: frame.now, at: performance.now() };
    setStatus("");
    render();
  };
  ws.onclose = () => {
    // A refused handshake and a server away look alike to a websocket: the token's own route tells.
    api.session().then(() => setStatus("The overview's stream was lost: reconnecting…"), (err) => setStatus(
      err.status === 401 ? "Not authorized: open the address the server printed (the one with ?token=...)."
        : "The server is not reachable: retrying…"));
    setTimeout(connect, RETRY_MS[Math.min(failures++, RETRY_MS.length - 1)]);
  };
}

function setStatus(text) {
  $("banner").textContent = text;
  $("banner").hidden = !text;
}

const initial = choices();
$("filter").value = initial.text;
$("state-filter").value = STATES.includes(initial.state) ? initial.state : "";
$("sort").value = initial.sort;
for (const id of ["filter", "state-filter", "sort"]) $(id).addEventListener("input", writeChoices);
setInterval(render, 1000); // "last event 3 s ago" goes on counting between frames
connect();

// Read-only, for the console and the browser tests.
window.fsmscopeFleet = Object.freeze({ get tiles() { return latest.tiles; } });
