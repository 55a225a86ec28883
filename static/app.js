// Wiring: machine picker, stream -> Status -> graph/tree/userdata/log, controls, connection badge.

import { api, ApiError } from "./api.js";
import { Stream } from "./stream.js";
import { Status, containers, allNodes, parentPath } from "./status.js";
import { GraphView } from "./graph.js";
import { TreeView, UserdataPanel, EventLog } from "./panels.js";
import { confirmPreempt, editInitialState, showMenu } from "./dialogs.js";
import { SceneView } from "./scene.js";
import { overduePreemptText } from "./preempt.js";
import { heldText, holdChange } from "./loop.js";
import { CONTROLLABLE_SOURCES, SCHEMA_VERSION, SOURCES, edgeId, outcomeId } from "./schema.js";

const $ = (id) => document.getElementById(id);
const MACHINE_POLL_MS = 2000;

const app = {
  machines: [],
  name: null,
  status: null,
  stream: null,
  nodes: new Map(), // path -> structure node
  structureKey: null,
  selected: null,
  changed: new Map(), // container path -> Set of keys written by its last transition
  pendingChanges: new Map(), // container path -> Set of keys written since its last transition
  lastEdge: new Map(), // container path -> the edge id of its last transition
  expand: null, // null: the server's default; else a Set of container paths drawn open
  endings: new Map(), // name -> {seq, error} of the other machines that ended without an outcome
  preemptAsked: false,
  preemptAck: null,
  heldBy: null, // the seq of a preempt that came between two runs and held the loop (no outcome follows)
  finishedText: null, // "NAME finished: outcome 'X'" once the root terminated, until it starts again
  overdueText: null, // the notice naming the states that have not serviced a preempt, while shown
  renderQueued: false,
  online: true,
};

// ---------------------------------------------------------------- views

const graph = new GraphView($("graph"), {
  select: (path) => select(path),
  contextmenu: (path, x, y) => stateMenu(path, x, y),
  toggle: (path, isCluster) => toggleExpand(path, isCluster),
  userPanned: () => {
    $("follow").checked = false;
    graph.follow = false;
  },
});
const tree = new TreeView($("tree"), {
  select: (path) => select(path),
  contextmenu: (path, x, y) => stateMenu(path, x, y),
});
const userdata = new UserdataPanel($("userdata"), $("ud-container"), {
  pick: (path) => select(path),
  redraw: () => queueRender(),
});
const log = new EventLog($("log"), {
  kinds: $("log-kinds"), text: $("log-filter"), count: $("log-count"), clear: $("log-clear"), partial: $("log-partial"),
}, { select: (path) => select(path) });
log.nodeOf = (path) => app.nodes.get(path);
const scene = new SceneView($("scene-pane"), document.querySelector("main.layout"));

// ---------------------------------------------------------------- notices

let noticeTimer = null;
function notice(text, level = "info", sticky = false) {
  const el = $("notice");
  el.textContent = text;
  el.title = text; // the whole of it, when the top bar leaves it too little room
  el.className = "notice " + level;
  clearTimeout(noticeTimer);
  if (!sticky) noticeTimer = setTimeout(clearNotice, 8000);
}

function clearNotice() {
  clearTimeout(noticeTimer);
  $("notice").textContent = $("notice").title = "";
  $("notice").className = "notice";
}

/** A notice about machine `name`, dropped when the page has moved to another machine meanwhile. */
function noticeAbout(name, text, level, sticky) {
  if (name === app.name) notice(text, level, sticky);
}

function banner(text) {
  const el = $("banner");
  el.textContent = text || "";
  el.hidden = !text;
}

// ---------------------------------------------------------------- machines

function currentEntry() {
  return app.machines.find((m) => m.name === app.name) || null;
}

const NOT_CONTROLLABLE = {
  [SOURCES.ingest]: "this machine runs in another process: control it there",
  [SOURCES.replay]: "this machine is a recording being replayed: nothing to control",
};

/** Why this page cannot control the machine of `entry` ("" when it can): the server would answer 409. */
function controlRefusal(entry) {
  if (!entry) return "no such machine on the server";
  if (CONTROLLABLE_SOURCES.includes(entry.source)) return "";
  return NOT_CONTROLLABLE[entry.source] || `a machine of source ${entry.source} cannot be controlled`;
}

async function pollMachines() {
  try {
    const list = await api.machines();
    app.online = true;
    banner("");
    app.machines = Array.isArray(list) ? list : [];
    checkEndings();
    fillPicker();
    if (!scene.url) api.scene().then((s) => scene.show(s && s.url)).catch(() => {});
    if (!app.name || !app.machines.some((m) => m.name === app.name)) {
      const wanted = decodeURIComponent((location.hash.match(/m=([^&]*)/) || [])[1] || "");
      const pick = app.machines.find((m) => m.name === wanted) || app.machines.find((m) => m.running) || app.machines[0];
      if (pick && pick.name !== app.name) openMachine(pick.name);
    }
    updateControls();
  } catch (err) {
    app.online = false;
    if (err instanceof ApiError && err.status === 401) {
      banner("Not authorized: open the address the server printed (the one with ?token=...).");
    } else {
      banner("");
    }
    updateControls();
  } finally {
    setTimeout(pollMachines, MACHINE_POLL_MS);
  }
}

/** running, done (reached an outcome), failed (ended without one after an error) or idle; or
 * disconnected: another process's machine whose publisher left before it ended (`entry`: its
 * /api/machines entry), so nobody can tell what it does now. */
function runState(s, entry) {
  const state = s.running ? "running" : s.outcome !== null && s.outcome !== undefined ? "done" : s.error ? "failed" : "idle";
  return entry?.connected === false && (state === "running" || state === "idle") ? "disconnected" : state;
}

/** Whether the other machines that ended without an outcome failed: /api/machines does not say,
 * their status does (asked once per change of their last_seq). */
function checkEndings() {
  for (const m of app.machines) {
    if (m.name === app.name || m.running || m.outcome || app.endings.get(m.name)?.seq === m.last_seq) continue;
    const ending = { seq: m.last_seq, error: null };
    app.endings.set(m.name, ending);
    api.status(m.name).then((s) => {
      ending.error = s.error;
      fillPicker();
    }).catch(() => app.endings.delete(m.name)); // asked again at the next poll
  }
}

function fillPicker() {
  const picker = $("machine-picker");
  const have = [...picker.options].map((o) => o.value + "\u0000" + o.textContent).join("\u0001");
  const labels = app.machines.map((m) => {
    const live = m.name === app.name && app.status?.structure
      ? app.status // the stream is fresher
      : { running: m.running, outcome: m.outcome, error: app.endings.get(m.name)?.error };
    const state = runState(live, m);
    const text = state === "done" ? "→ " + live.outcome : state;
    return [m.name, `${m.name}  (${text}${m.source === SOURCES.ingest ? ", remote" : ""})`];
  });
  if (labels.map(([v, t]) => v + "\u0000" + t).join("\u0001") === have) return;
  picker.replaceChildren(...labels.map(([value, text]) => {
    const o = document.createElement("option");
    o.value = value;
    o.textContent = text;
    return o;
  }));
  if (app.name) picker.value = app.name;
}

$("machine-picker").addEventListener("change", (e) => openMachine(e.target.value));

function openMachine(name) {
  if (app.stream) app.stream.stop();
  app.name = name;
  history.replaceState(null, "", "#m=" + encodeURIComponent(name));
  $("machine-picker").value = name;
  app.status = new Status(name);
  app.nodes = new Map();
  app.structureKey = null;
  app.selected = null;
  forgetRunMarks();
  app.expand = null;
  // Notices and preempt bookkeeping are about the machine shown so far, not this one.
  clearNotice();
  app.preemptAsked = false;
  app.preemptAck = null;
  app.heldBy = null;
  app.finishedText = null;
  app.overdueText = null;
  graph.clear("Waiting for the machine's structure…");
  tree.build(null);
  userdata.show(null);
  log.reset();
  app.stream = new Stream(name, {
    snapshot: onSnapshot,
    events: onEvents,
    missed: (count) => notice(`${count} events missed: resynchronised from a snapshot`, "warn"),
    state: () => updateBadge(),
  }, {
    url: (n, since) => api.streamUrl(n, since),
    checkResume: async (since) => {
      // A restarted server numbers its events from 1 again: then ask for a snapshot.
      const list = await api.machines();
      const entry = list.find((m) => m.name === name);
      return Boolean(entry) && entry.last_seq >= since;
    },
  });
  app.stream.start();
  checkEndings(); // the machine shown so far is one of the others now
  queueRender();
}

// ---------------------------------------------------------------- stream handling

function onSnapshot(status, lastSeq, history) {
  app.status = Status.fromDict({ machine: app.name, ...status });
  forgetRunMarks();
  structureChanged();
  if (history) log.history(history); // a new connection: the run so far, for the log only (the status has it)
  queueRender();
}

function onEvents(events) {
  const status = app.status;
  for (const ev of events) {
    if (ev.v !== undefined && ev.v !== SCHEMA_VERSION) continue; // a schema this page does not know
    status.apply(ev);
    track(ev);
    if (ev.kind === "structure") structureChanged();
  }
  log.add(events);
  queueRender();
}

/** Forget the last edges and changed keys seen so far (the reducer keeps neither). */
function forgetRunMarks() {
  app.changed = new Map();
  app.pendingChanges = new Map();
  app.lastEdge = new Map();
}

/** What the reducer does not keep but the page shows: last edges, changed keys, outcomes. */
function track(ev) {
  const path = ev.path;
  switch (ev.kind) {
    case "start":
      if (path === app.status.root_path) {
        forgetRunMarks(); // a new run: the page shows this run only, as the reducer does
        if (app.finishedText) {
          app.finishedText = null;
          clearNotice(); // the previous run's outcome no longer describes the machine
        }
      }
      app.pendingChanges.set(path, new Set());
      app.changed.set(path, new Set());
      app.lastEdge.delete(path);
      break;
    case "userdata": {
      const pending = app.pendingChanges.get(path) || new Set();
      for (const key of Object.keys(ev.changes || {})) pending.add(key);
      app.pendingChanges.set(path, pending);
      app.changed.set(path, new Set(pending));
      break;
    }
    case "transition":
      app.changed.set(path, app.pendingChanges.get(path) || new Set());
      app.pendingChanges.set(path, new Set());
      app.lastEdge.set(path, edgeId(path, ev.from, ev.outcome));
      break;
    case "terminate": {
      app.changed.set(path, app.pendingChanges.get(path) || new Set());
      app.pendingChanges.set(path, new Set());
      const last = ev.last && ev.last.length === 1 ? ev.last[0] : null;
      if (last && ev.state_outcome) app.lastEdge.set(path, edgeId(path, last, ev.state_outcome));
      if (path === app.status.root_path) {
        const outcome = ev.outcome === null ? "no outcome" + (ev.error ? ` (${ev.error})` : "") : `outcome '${ev.outcome}'`;
        app.finishedText = `${app.name} finished: ${outcome}`;
        const text = app.preemptAsked && app.preemptAck ? `${app.preemptAck}: ${app.finishedText}` : app.finishedText;
        notice(text, ev.outcome === null ? "error" : app.preemptAsked ? "warn" : "ok", true);
        app.preemptAsked = false;
        app.preemptAck = null;
      }
      break;
    }
    case "error":
      notice(`${ev.exc_type}: ${ev.message}`, "error", true);
      break;
    case "control":
      loopHeld(ev);
      break;
    default:
  }
}

/** A hold seen on the stream, shown at once. A preempt that came between two runs held the loop:
 * no outcome will come, the loop waits for Start. */
function loopHeld(ev) {
  const held = holdChange(ev);
  const entry = currentEntry();
  if (held === null || !entry?.can_hold) return;
  entry.held = held; // what the next poll of /api/machines will say
  if (held && ev.action === "preempt") {
    app.preemptAsked = false;
    app.heldBy = ev.seq;
    notice(`Preempt accepted (event ${ev.seq}) between two runs: the loop waits for Start`, "warn", true);
  }
}

function structureChanged() {
  const root = app.status.structure;
  const key = root ? JSON.stringify(root) : null;
  if (key === app.structureKey) return;
  app.structureKey = key;
  app.nodes = new Map();
  for (const node of allNodes(root)) app.nodes.set(node.path, node);
  graph.index(app.nodes.values());
  tree.build(root);
  const all = root ? [...containers(root)] : [];
  userdata.setContainers(all);
  if (!userdata.path || !app.nodes.has(userdata.path)) userdata.show(root ? root.path : null);
  if (app.expand) app.expand = new Set([...app.expand].filter((p) => app.nodes.has(p)));
  fillDepth(all);
  loadGraph();
}

// ---------------------------------------------------------------- graph layout (structure + expand set)

function depthOf(path) {
  const root = app.status.root_path || "";
  return path === root ? 0 : path.slice(root.length).split("/").length - 1;
}

function fillDepth(all) {
  const select = $("depth");
  const max = all.reduce((m, n) => Math.max(m, depthOf(n.path) + 1), 1);
  const current = select.value;
  const options = [["auto", "auto"]];
  for (let d = 1; d <= max; d++) options.push([String(d), String(d)]);
  options.push(["custom", "custom"]);
  select.replaceChildren(...options.map(([value, text]) => {
    const o = document.createElement("option");
    o.value = value;
    o.textContent = text;
    if (value === "custom") o.hidden = true;
    return o;
  }));
  select.value = options.some(([v]) => v === current) ? current : "auto";
}

$("depth").addEventListener("change", (e) => {
  const value = e.target.value;
  if (value === "auto") app.expand = null;
  else if (value !== "custom") {
    const d = Number(value);
    app.expand = new Set([...containers(app.status.structure)].map((n) => n.path).filter((p) => depthOf(p) < d));
  }
  loadGraph();
});

function toggleExpand(path, isCluster) {
  const node = app.nodes.get(path);
  if (!node || !node.container || path === app.status.root_path) return;
  if (!app.expand) {
    // From the server's default: open what it opened (clusters in the current SVG).
    app.expand = new Set(graph.openPaths());
    app.expand.add(app.status.root_path);
  }
  if (isCluster || app.expand.has(path)) {
    for (const p of [...app.expand]) if (p === path || p.startsWith(path + "/")) app.expand.delete(p);
  } else {
    for (let p = path; p; p = parentPath(p)) app.expand.add(p);
  }
  $("depth").value = "custom";
  loadGraph();
}

async function loadGraph() {
  const name = app.name;
  if (!app.status.structure) return;
  const expand = app.expand ? [...app.expand].sort() : null;
  const key = JSON.stringify([name, app.structureKey, expand]);
  try {
    const changed = await graph.load(key, () => api.graphSvg(name, expand));
    if (changed) queueRender();
  } catch (err) {
    if (name === app.name) graph.clear("Could not draw the graph: " + (err.detail || err.message));
  }
}

$("fit").addEventListener("click", () => graph.fit());
$("zoom-in").addEventListener("click", () => graph.zoom(1.25));
$("zoom-out").addEventListener("click", () => graph.zoom(0.8));
$("follow").addEventListener("change", (e) => {
  graph.follow = e.target.checked;
  queueRender();
});

// ---------------------------------------------------------------- selection and menus

function select(path) {
  app.selected = path || null;
  tree.select(app.selected);
  if (path) {
    const node = app.nodes.get(path);
    userdata.show(node && node.container ? path : parentPath(path) || path);
  }
  queueRender();
}

function stateMenu(path, x, y) {
  const node = app.nodes.get(path);
  const container = parentPath(path);
  const parent = container ? app.nodes.get(container) : null;
  select(path);
  const refusal = controlRefusal(currentEntry());
  const takesInitial = parent && parent.type !== "Concurrence" && parent.type !== "Iterator";
  showMenu(x, y, path, [
    {
      label: "Set as initial state…",
      disabled: !node || !parent || !takesInitial || Boolean(refusal),
      title: !parent ? "the root has no parent container" : !takesInitial ? `a ${parent.type} has no initial state to choose` : refusal,
      action: () => setInitial(container, node.label),
    },
    { label: node && node.container ? "Show userdata" : "Show container userdata", action: () => {
      userdata.show(node?.container ? path : container);
      queueRender();
    } },
    { label: "Center in graph", action: () => graph.reveal(graph.stateElement(path)) },
  ]);
}

async function setInitial(container, state) {
  const name = app.name;
  const ud = app.status.containers[container]?.userdata || {};
  const ok = await editInitialState({
    container, state, userdata: ud,
    submit: (value) => api.setInitialState(name, container, [state], value),
  });
  if (ok) noticeAbout(name, `Initial state of ${container} set to ${state} (next run)`, "ok");
}

// ---------------------------------------------------------------- controls

$("preempt-btn").addEventListener("click", async () => {
  const name = app.name;
  const answer = await confirmPreempt(name);
  if (!answer) return;
  app.preemptAsked = true;
  app.preemptAck = null;
  app.finishedText = null;
  try {
    const ack = await api.preempt(name, answer.reason);
    if (name !== app.name || ack.seq === app.heldBy) return; // the stream has told what it did
    // The outcome may have arrived on the stream before this answer did.
    app.preemptAck = `Preempt accepted (event ${ack.seq})`;
    notice(app.preemptAck + ": " + (app.finishedText || "waiting for the outcome…"), "warn", true);
  } catch (err) {
    if (name !== app.name) return;
    app.preemptAsked = false;
    notice("Preempt failed: " + (err.detail || err.message), "error", true);
  }
});

/** Name the states that have not serviced a preempt requested a while ago, counting the seconds; take
 * it back when that no longer holds (unless another notice, such as the outcome, has replaced it). */
function sayOverduePreempt() {
  const text = app.status ? overduePreemptText(app.status, Date.now() / 1000) : null;
  if (text === app.overdueText) return;
  if (text) notice(text, "warn", true);
  else if ($("notice").textContent === app.overdueText) clearNotice();
  app.overdueText = text;
}
setInterval(sayOverduePreempt, 500);

/** Ask the server for `what` by `call(name)`; a notice says how it answered. */
async function ask(what, call, then = "") {
  const name = app.name;
  try {
    const ack = await call(name);
    noticeAbout(name, `${what} accepted (event ${ack.seq})${then}`, "ok");
  } catch (err) {
    noticeAbout(name, `${what} failed: ` + (err.detail || err.message), "error", true);
  }
}

$("start-btn").addEventListener("click", () => ask("Start", api.start));
$("hold-btn").addEventListener("click", () => ask("Stop after this run", api.hold, ": then the loop waits for Start"));

function updateControls() {
  const entry = currentEntry();
  const running = app.status ? app.status.running : false;
  const live = app.online && app.stream?.state === "live";
  const controllable = !controlRefusal(entry);
  $("preempt-btn").disabled = !live || !running || !controllable;
  $("start-btn").disabled = !live || running || !controllable || !entry.can_start;
  const hold = $("hold-btn");
  hold.hidden = !entry?.can_hold;
  hold.disabled = !live || !running || !controllable || entry.held;
  const loop = $("loop-state");
  loop.hidden = !entry?.held;
  if (loop.textContent !== heldText(running)) loop.textContent = heldText(running);
  const pill = $("run-state");
  const s = app.status;
  const state = s?.structure ? runState(s, entry) : "idle";
  let text = s?.structure ? state : "—";
  if (state === "failed") text = "failed: " + (s.error.exc_type || "error");
  if (state === "done") text = "finished: " + s.outcome;
  if (pill.textContent !== text) pill.textContent = text;
  pill.className = "pill " + state;
  pill.title = s?.error ? `${s.error.exc_type || ""} ${s.error.message || ""}`.trim() : "";
}

// ---------------------------------------------------------------- badge

function updateBadge() {
  const badge = $("badge");
  const stream = app.stream;
  const state = !stream ? "idle" : stream.state;
  let cls = "down";
  let text = state;
  if (state === "live") {
    cls = "live";
    const rate = stream.rate();
    const lat = stream.latencyMs;
    const shownRate = rate < 10 ? rate.toFixed(1) : Math.round(rate);
    if (currentEntry()?.source === SOURCES.replay) {
      text = `replay · ${shownRate} ev/s`; // a recording's timestamps say nothing of latency
    } else {
      text = `live · ${shownRate} ev/s · ${lat === null ? "–" : lat < 10 ? lat.toFixed(1) : Math.round(lat)} ms`;
    }
  } else if (state === "reconnecting" || state === "connecting") {
    cls = "wait";
    text = app.online ? state + "…" : "server unreachable · retrying";
  }
  if (stream && stream.missed) text += ` · missed ${stream.missed}`;
  badge.className = "badge " + cls;
  badge.dataset.state = state;
  const label = badge.querySelector(".badge-text");
  if (label.textContent !== text) label.textContent = text;
  updateControls();
}
setInterval(updateBadge, 500);

// ---------------------------------------------------------------- render

function queueRender() {
  if (app.renderQueued) return;
  app.renderQueued = true;
  requestAnimationFrame(render);
}

/** The failing state and the containers it brought down (they ended without an outcome). */
function failedPaths(s) {
  if (!s.error || !s.error.path) return [];
  const failing = s.error.state ? s.error.path + "/" + s.error.state : s.error.path;
  const failed = [failing];
  for (let p = parentPath(failing); p; p = parentPath(p)) {
    const entry = s.containers[p];
    if (entry && !entry.running && entry.outcome === null) failed.push(p);
  }
  return failed;
}

function render() {
  app.renderQueued = false;
  const s = app.status;
  if (!s) return;
  const active = s.activePaths();
  const running = Object.entries(s.containers).filter(([, c]) => c.running).map(([p]) => p);
  const reached = Object.entries(s.containers)
    .filter(([, c]) => !c.running && c.outcome !== null && c.outcome !== undefined)
    .map(([p, c]) => outcomeId(p, c.outcome));
  const failed = failedPaths(s);
  graph.apply({ active, running, reached, lastEdges: [...app.lastEdge.values()], failed, selected: app.selected });
  tree.update(s, failed);
  log.flush();
  fillPicker();
  const udPath = userdata.path;
  userdata.update(s, udPath ? app.nodes.get(udPath) : null, udPath ? app.changed.get(udPath) : null);
  updateControls();
}

// ---------------------------------------------------------------- go

document.addEventListener("keydown", (e) => {
  if (e.target.closest("input, textarea, select, dialog")) return;
  if (e.key === "f") graph.fit();
  else if (e.key === "+" || e.key === "=") graph.zoom(1.25);
  else if (e.key === "-") graph.zoom(0.8);
});

window.fsmscope = app; // for debugging in the console and for the browser tests
pollMachines();
