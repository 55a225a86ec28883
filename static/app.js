// Wiring: the machine shown (store.js), fed by its stream, drawn by the graph and the panels at the
// instant the playhead (timetravel.js) says, live or past; the picker (machines.js), controls
// (controls.js), depth (depth.js), notices and badge around it. About 300 lines, one piece on
// purpose: it is the one place where the page's parts meet, and it holds no logic of its own.

import { api } from "./api.js";
import { Audit } from "./audit.js";
import { showBadge } from "./badge.js";
import { Breadcrumb } from "./breadcrumb.js";
import { Breakpoints, debugMarks } from "./breakpoints.js";
import { readLink, writeLink } from "./deeplink.js";
import { Controls } from "./controls.js";
import { DebugBar } from "./debugger.js";
import { Depth } from "./depth.js";
import { DetailsPanel } from "./details.js";
import { showMenu } from "./dialogs.js";
import { GraphView } from "./graph.js";
import { Lease } from "./lease.js";
import { Machines, isReplay, showRunState } from "./machines.js";
import { Minimap } from "./minimap.js";
import { Panes } from "./panes.js";
import { RunNotices, notice } from "./notice.js";
import { EventLog } from "./eventlog.js";
import { FramePace } from "./frame_pace.js";
import { Playhead } from "./timetravel.js";
import { Timeline } from "./timeline.js";
import { TreeView } from "./tree.js";
import { UserdataPanel, keyHistory } from "./userdata.js";
import { SceneView } from "./scene.js";
import { SearchPalette } from "./search.js";
import { SCHEMA_VERSION } from "./schema.js";
import { containers, parentPath } from "./status.js";
import { Store, view } from "./store.js";
import { Stream } from "./stream.js";

const $ = (id) => document.getElementById(id);

const store = new Store();
let stream = null; // the stream of the machine shown
let renderQueued = false;
const KEY_HISTORY_LIMIT = 10000; // events of a run read for one key's history
const TIMELINE_REFRESH_MS = 1000; // a live machine's timeline is asked again this often
const TREE_WAIT_MS = 250; // the hierarchy's rows wait this long at most for the drawing
let timelineRange = { since_t: null, until_t: null }; // the range the timeline shows (null: the whole run)

const playhead = new Playhead(api, {
  changed: () => queueRender(playhead.playing),
  failed: (err) => notice("Could not show that instant: " + (err.detail || err.message), "warn"),
});

const graph = new GraphView($("graph"), {
  select: (path) => select(path),
  contextmenu: (path, x, y) => stateMenu(path, x, y),
  toggle: (path, isCluster) => depth.toggle(path, isCluster),
  userPanned: () => stopFollowing(),
});
function stopFollowing() {
  $("follow").checked = false;
  graph.follow = false;
}
new Breadcrumb($("crumb-bar"), $("fit"), graph, {
  label: (path) => store.nodes.get(path)?.label ?? path,
  fit: (path) => {
    stopFollowing();
    graph.fitPath(path);
  },
});
new Minimap($("minimap"), graph, (x, y) => {
  stopFollowing();
  graph.centreOn(x, y);
});
new Panes(document.querySelector("main.layout"));
const tree = new TreeView($("tree"), {
  select: (path) => select(path),
  contextmenu: (path, x, y) => stateMenu(path, x, y),
});
const userdata = new UserdataPanel($("userdata"), $("ud-container"), {
  pick: (path) => select(path),
  redraw: () => queueRender(),
  keyHistory: (path, key) => showKeyHistory(path, key),
  seek: (seq) => playhead.seek({ seq }),
});
const log = new EventLog($("log"), {
  kinds: $("log-kinds"), text: $("log-filter"), count: $("log-count"), clear: $("log-clear"), partial: $("log-partial"),
}, {
  select: (path, seq) => {
    select(path);
    if (Number.isSafeInteger(seq)) playhead.seek({ seq });
  },
});
log.nodeOf = (path) => store.nodes.get(path);
const timeline = new Timeline($("timeline"), {
  seek: (target) => playhead.seek(target),
  range: (range) => {
    timelineRange = range;
    loadTimeline();
  },
  play: () => playhead.play(),
  pause: () => playhead.pause(),
  speed: (x) => playhead.setSpeed(x),
  step: (direction, path) => playhead.step(direction, path),
  live: () => playhead.live(),
});
const scene = new SceneView($("scene-pane"), document.querySelector("main.layout"), api.scenePose);
const notices = new RunNotices();
const machines = new Machines($("machine-picker"), store, {
  open: (name) => openMachine(name),
  polled: () => {
    if (machines.online && !scene.url) api.scene().then((s) => scene.show(s && s.url)).catch(() => {});
    updateTopBar();
  },
});
const controls = new Controls(store, machines, notices, () => stream?.state === "live");
api.session().then((s) => controls.setRole(s.role)).catch(() => {}); // no valid token: token.js says so
const lease = new Lease(store, controls);
const audit = new Audit(store);
$("audit-btn").addEventListener("click", () => audit.open());
const showsLive = () => stream?.state === "live" && !playhead.past; // the debugger controls only what it shows
const breakpoints = new Breakpoints(store, controls, showsLive);
const debugBar = new DebugBar(store, controls, showsLive);
const depth = new Depth($("depth"), store, () => graph.openPaths(), (semantic) => loadGraph(semantic), api.anyOpenSet);

const details = new DetailsPanel($("details"), store, api);
const search = new SearchPalette(store, () => shownStatus(), (entry) => goTo(entry));
$("search-btn").addEventListener("click", () => search.open());

// ---------------------------------------------------------------- the machine shown and its stream

function openMachine(name) {
  if (stream) stream.stop();
  store.open(name);
  const link = readLink();
  const entry = machines.list.find((m) => m.name === name);
  playhead.open(name, isReplay(entry), link.machine === name ? link.seq : null);
  if (entry?.replay?.speed) {
    playhead.setSpeed(entry.replay.speed);
    timeline.showSpeed(entry.replay.speed);
  }
  timelineRange = { since_t: null, until_t: null };
  loadTimeline();
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
  queueRender(true);
}

function structureChanged() {
  if (!store.restructured()) return;
  const root = store.status.structure;
  graph.index(store.nodes.values());
  depth.restructured();
  // The drawing first: a big machine's hierarchy takes longer to build and lay out than the server's
  // drawing takes to come, so its rows wait for the drawing (at most TREE_WAIT_MS).
  const drawn = loadGraph();
  Promise.race([drawn, new Promise((done) => setTimeout(done, TREE_WAIT_MS))]).then(() => {
    if (store.status?.structure !== root) return; // another machine or structure since
    tree.build(root);
    queueRender();
  });
  userdata.setContainers([...containers(root)]);
  if (!userdata.path || !store.nodes.has(userdata.path)) userdata.show(root ? root.path : null);
}

/** Draw the layout of the structure with the containers `depth` opens (the server lays it out);
 * `semantic`: opened or closed as the machine moved: what the user looks at stays where it is. */
async function loadGraph(semantic = false) {
  const name = store.name;
  if (!store.status.structure) return;
  const expand = depth.paths();
  const key = JSON.stringify([name, store.structureKey, expand]);
  try {
    const anchor = semantic ? () => store.selected || graph.activePath : null;
    if (await graph.load(key, () => api.graphSvg(name, expand), anchor)) {
      depth.laidOut();
      queueRender();
    }
  } catch (err) {
    if (name !== store.name) return;
    const text = "Could not draw the graph: " + (err.detail || err.message);
    if (err.status === 404 && graph.key) notice(text, "warn"); // that drawing is missing: keep the one shown
    else graph.clear(text);
  }
}

/** Ask the server for the timeline of the machine shown, in the range the timeline shows. */
async function loadTimeline() {
  const name = store.name;
  if (name === null) return;
  try {
    const data = await api.timeline(name, timelineRange);
    if (name === store.name) timeline.setData(data);
  } catch (err) {
    if (name === store.name) notice("Could not read the timeline: " + (err.detail || err.message), "warn");
  }
}

/** The history of `key` of container `path` in the current run, beside the userdata. */
async function showKeyHistory(path, key) {
  const name = store.name;
  const s = shownStatus();
  try {
    const page = await api.history(name, { since: s.run_seq, until: s.last_seq, path, kinds: "start,transition,userdata",
      limit: KEY_HISTORY_LIMIT });
    if (name === store.name) userdata.showHistory(key, keyHistory(page.events, key), page.more);
  } catch (err) {
    notice("Could not read the history of " + key + ": " + (err.detail || err.message), "warn");
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

/** A search's choice: a userdata key shows its container's userdata; a state, container or outcome (its
 * state) is drawn (the containers on its path opened), brought into view and selected. */
async function goTo(entry) {
  if (entry.kind === "key") {
    userdata.show(entry.path);
    queueRender();
    return;
  }
  $("follow").checked = false; // the user looks elsewhere than the active state
  graph.follow = false;
  await depth.reveal(entry.path);
  select(entry.path);
  graph.centrePath(entry.path);
}

function stateMenu(path, x, y) {
  const node = store.nodes.get(path);
  select(path);
  showMenu(x, y, path, [
    controls.initialStateItem(path),
    ...breakpoints.items(path),
    { label: node && node.container ? "Show userdata" : "Show container userdata", action: () => {
      userdata.show(node?.container ? path : parentPath(path));
      queueRender();
    } },
    { label: "Center in graph", action: () => graph.centrePath(path) },
  ]);
}

// ---------------------------------------------------------------- top bar and render

function updateTopBar() {
  controls.update();
  lease.update();
  debugBar.update(shownStatus());
  showRunState($("run-state"), shownStatus(), machines.current());
}

function updateBadge() {
  showBadge($("badge"), stream, { online: machines.online, replay: isReplay(machines.current()) });
  updateTopBar();
}

// Events, and a replay playing, are drawn at most 30 times a second, and no more often than leaves
// drawing a quarter of the main thread (frame_pace.js: a big machine drawn open draws less often);
// at most 4 times a second while the page looks back and only its count of events behind changes.
// The server is then asked for the live events at that pace too (a frame every 250 ms rather than 50
// a second): a flood costs the page's computer (often the robot's) a fraction of a core
// (bench/live_rewind.py). What the user does is drawn at the next frame.
const PACED_FRAME_MS = 33;
const BEHIND_FRAME_MS = 250;
const framePace = new FramePace();
let lastRender = -Infinity;
let renderTimer = null;

/** Draw at the next animation frame, or, `paced`, not sooner than the pace allows. */
function queueRender(paced = false) {
  if (renderQueued && (renderTimer === null || paced)) return;
  clearTimeout(renderTimer);
  renderTimer = null;
  renderQueued = true;
  const pace = playhead.past && !playhead.playing ? BEHIND_FRAME_MS : framePace.gap(PACED_FRAME_MS);
  const wait = paced ? lastRender + pace - performance.now() : 0;
  if (wait <= 0) {
    requestAnimationFrame(render);
    return;
  }
  renderTimer = setTimeout(() => {
    renderTimer = null;
    requestAnimationFrame(render);
  }, wait);
}

/** The status of the instant shown: the playhead's when it looks back, else the stream's present. */
function shownStatus() {
  return playhead.past ? playhead.status : store.status;
}

/** The timeline's playhead, and the page framed as looking back when it does. */
function showInstant() {
  const live = store.status;
  const past = playhead.past;
  timeline.setInstant({
    seq: past ? playhead.seq : live.last_seq, t: past ? playhead.t : live.last_t, live: !past,
    behind: past && !playhead.replay ? playhead.behind(live) : null, playing: playhead.playing,
    liveMachine: !playhead.replay,
  });
  document.body.classList.toggle("looking-back", past && !playhead.replay);
  stream?.pace(past ? BEHIND_FRAME_MS : 0);
}

let linkTimer = null;
/** The address names the instant shown (at most four times a second: browsers throttle replaceState). */
function updateLink() {
  if (linkTimer) return;
  linkTimer = setTimeout(() => {
    linkTimer = null;
    if (store.name !== null) writeLink(store.name, playhead.past ? playhead.seq : null);
  }, 250);
}

// A drawing is two frames: the machine (graph, hierarchy, details, top bar), then the log and the
// userdata. Each half of a big machine's drawing under a flood stays under 50 ms, where the whole
// was a long task that kept the page from answering the user (bench/big_machine_browser.py).
function render() {
  renderQueued = false;
  lastRender = performance.now();
  framePace.started();
  if (!store.status) return;
  const s = shownStatus();
  const shown = view(s);
  const marks = debugMarks(s);
  graph.apply({ ...shown, ...marks, selected: store.selected });
  depth.show(shown.running, store.selected);
  tree.update(s, shown.failed, marks);
  details.update();
  if (graph.follow && graph.activePath) tree.reveal(graph.activePath);
  showInstant();
  scene.showPose(playhead.past ? s.pose : null);
  updateLink();
  machines.fillPicker();
  updateTopBar();
  requestAnimationFrame(renderPanels);
}

/** The second frame of a drawing: the log and the userdata of the instant shown. */
function renderPanels() {
  framePace.frame();
  if (!store.status) return;
  if (playhead.past && !playhead.window) log.freeze();
  else log.showPast(playhead.past ? playhead.window : null);
  log.flush();
  const udPath = userdata.path;
  userdata.update(shownStatus(), udPath ? store.nodes.get(udPath) : null);
  log.followNewest();
}

// ---------------------------------------------------------------- go

$("fit").addEventListener("click", () => graph.fit());
$("zoom-in").addEventListener("click", () => graph.zoomStep(1));
$("zoom-out").addEventListener("click", () => graph.zoomStep(-1));
$("zoom-readable").addEventListener("click", () => graph.zoomReadable());
$("follow").addEventListener("change", (e) => {
  graph.follow = e.target.checked;
  queueRender();
});
document.addEventListener("keydown", (e) => {
  if (e.target.closest("input, textarea, select, dialog")) return;
  if (e.key === "f") graph.fit();
  else if (e.key === "+" || e.key === "=") graph.zoomStep(1);
  else if (e.key === "-") graph.zoomStep(-1);
  else if (e.key === "r") graph.zoomReadable();
});
setInterval(updateBadge, 500);
setInterval(() => {
  if (!playhead.replay && !document.hidden) loadTimeline(); // a live run grows
}, TIMELINE_REFRESH_MS);
setInterval(() => notices.checkOverdue(store.status), 500);

// Read-only, for the console and the browser tests (the selected path, the status shown, the live one).
window.fsmscope = Object.freeze({
  get name() { return store.name; },
  get status() { return shownStatus(); },
  get liveStatus() { return store.status; },
  get instant() { return { past: playhead.past, seq: playhead.seq, t: playhead.t, playing: playhead.playing }; },
  get selected() { return store.selected; },
});
machines.poll();
