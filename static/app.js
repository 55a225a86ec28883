// Wiring: the machine shown (store.js), fed by its stream, drawn by the graph and the panels; the
// picker (machines.js), controls (controls.js), depth (depth.js), notices and badge around it.

import { api } from "./api.js";
import { showBadge } from "./badge.js";
import { Controls } from "./controls.js";
import { Depth } from "./depth.js";
import { showMenu } from "./dialogs.js";
import { GraphView } from "./graph.js";
import { Machines, isReplay, showRunState } from "./machines.js";
import { RunNotices, notice } from "./notice.js";
import { EventLog } from "./eventlog.js";
import { TreeView } from "./tree.js";
import { UserdataPanel } from "./userdata.js";
import { SceneView } from "./scene.js";
import { SCHEMA_VERSION } from "./schema.js";
import { containers, parentPath } from "./status.js";
import { Store, view } from "./store.js";
import { Stream } from "./stream.js";

const $ = (id) => document.getElementById(id);

const store = new Store();
let stream = null; // the stream of the machine shown
let renderQueued = false;

const graph = new GraphView($("graph"), {
  select: (path) => select(path),
  contextmenu: (path, x, y) => stateMenu(path, x, y),
  toggle: (path, isCluster) => depth.toggle(path, isCluster),
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
log.nodeOf = (path) => store.nodes.get(path);
const scene = new SceneView($("scene-pane"), document.querySelector("main.layout"));
const notices = new RunNotices();
const machines = new Machines($("machine-picker"), store, {
  open: (name) => openMachine(name),
  polled: () => {
    if (machines.online && !scene.url) api.scene().then((s) => scene.show(s && s.url)).catch(() => {});
    updateTopBar();
  },
});
const controls = new Controls(store, machines, notices, () => stream?.state === "live");
const depth = new Depth($("depth"), store, () => graph.openPaths(), () => loadGraph());

// ---------------------------------------------------------------- the machine shown and its stream

function openMachine(name) {
  if (stream) stream.stop();
  store.open(name);
  machines.opened(name);
  depth.reset();
  notices.forget(); // they were about the machine shown so far
  graph.clear("Waiting for the machine's structure…");
  tree.build(null);
  userdata.show(null);
  log.reset();
  stream = new Stream(name, {
    snapshot: onSnapshot,
    events: onEvents,
    missed: (count) => notice(`${count} events missed: resynchronised from a snapshot`, "warn"),
    state: () => updateBadge(),
  }, {
    url: (n, since) => api.streamUrl(n, since),
    checkResume: async (since) => {
      // A restarted server numbers its events from 1 again: then ask for a snapshot.
      const entry = (await api.machines()).find((m) => m.name === name);
      return Boolean(entry) && entry.last_seq >= since;
    },
  });
  stream.start();
  queueRender();
}

function onSnapshot(status, lastSeq, history) {
  store.load(status);
  structureChanged();
  if (history) log.history(history); // a new connection: the run so far, for the log only (the status has it)
  queueRender();
}

function onEvents(events) {
  for (const ev of events) {
    if (ev.v !== undefined && ev.v !== SCHEMA_VERSION) continue; // a schema this page does not know
    store.apply(ev);
    notices.event(ev, store.name, store.status.root_path);
    if (machines.sawHold(ev) && ev.action === "preempt") notices.heldByPreempt(ev.seq);
    if (ev.kind === "structure") structureChanged();
  }
  log.add(events);
  queueRender();
}

function structureChanged() {
  if (!store.restructured()) return;
  const root = store.status.structure;
  graph.index(store.nodes.values());
  tree.build(root);
  userdata.setContainers([...containers(root)]);
  if (!userdata.path || !store.nodes.has(userdata.path)) userdata.show(root ? root.path : null);
  depth.restructured();
  loadGraph();
}

/** Draw the layout of the structure with the containers `depth` opens (the server lays it out). */
async function loadGraph() {
  const name = store.name;
  if (!store.status.structure) return;
  const expand = depth.paths();
  const key = JSON.stringify([name, store.structureKey, expand]);
  try {
    if (await graph.load(key, () => api.graphSvg(name, expand))) queueRender();
  } catch (err) {
    if (name === store.name) graph.clear("Could not draw the graph: " + (err.detail || err.message));
  }
}

// ---------------------------------------------------------------- selection and the state menu

function select(path) {
  store.selected = path || null;
  tree.select(store.selected);
  if (path) {
    const node = store.nodes.get(path);
    userdata.show(node && node.container ? path : parentPath(path) || path);
  }
  queueRender();
}

function stateMenu(path, x, y) {
  const node = store.nodes.get(path);
  select(path);
  showMenu(x, y, path, [
    controls.initialStateItem(path),
    { label: node && node.container ? "Show userdata" : "Show container userdata", action: () => {
      userdata.show(node?.container ? path : parentPath(path));
      queueRender();
    } },
    { label: "Center in graph", action: () => graph.reveal(graph.stateElement(path)) },
  ]);
}

// ---------------------------------------------------------------- top bar and render

function updateTopBar() {
  controls.update();
  showRunState($("run-state"), store.status, machines.current());
}

function updateBadge() {
  showBadge($("badge"), stream, { online: machines.online, replay: isReplay(machines.current()) });
  updateTopBar();
}

function queueRender() {
  if (renderQueued) return;
  renderQueued = true;
  requestAnimationFrame(render);
}

function render() {
  renderQueued = false;
  const s = store.status;
  if (!s) return;
  const shown = view(s);
  graph.apply({ ...shown, selected: store.selected });
  tree.update(s, shown.failed);
  log.flush();
  machines.fillPicker();
  const udPath = userdata.path;
  userdata.update(s, udPath ? store.nodes.get(udPath) : null);
  updateTopBar();
}

// ---------------------------------------------------------------- go

$("fit").addEventListener("click", () => graph.fit());
$("zoom-in").addEventListener("click", () => graph.zoom(1.25));
$("zoom-out").addEventListener("click", () => graph.zoom(0.8));
$("follow").addEventListener("change", (e) => {
  graph.follow = e.target.checked;
  queueRender();
});
document.addEventListener("keydown", (e) => {
  if (e.target.closest("input, textarea, select, dialog")) return;
  if (e.key === "f") graph.fit();
  else if (e.key === "+" || e.key === "=") graph.zoom(1.25);
  else if (e.key === "-") graph.zoom(0.8);
});
setInterval(updateBadge, 500);
setInterval(() => notices.checkOverdue(store.status), 500);

// Read-only, for the console and the browser tests (the selected path, the status shown).
window.fsmscope = Object.freeze({
  get name() { return store.name; },
  get status() { return store.status; },
  get selected() { return store.selected; },
});
machines.poll();
