// Wiring, and no state of its own: the page's one store (store.js) is fed by the stream of the machine
// shown (feed.js), the playhead (timetravel.js), the machines' poll (machines.js) and the lease's
// worker (lease.js); each part the store says changed is drawn by the views that show it, the machine
// and its panels by the renderer (renderer.js) at a pace. What the user does goes to the store or to
// the server.

import { AccessForm } from "./access.js";
import { api } from "./api.js";
import { Audit } from "./audit.js";
import { showBadge } from "./badge.js";
import { Breadcrumb } from "./breadcrumb.js";
import { Breakpoints, debugMarks } from "./breakpoints.js";
import { LinkFollower, linkTo, onLinkChanged, readLink } from "./deeplink.js";
import { Controls } from "./controls.js";
import { DebugBar } from "./debugger.js";
import { Depth } from "./depth.js";
import { DetailsPanel } from "./details.js";
import { showMenu } from "./dialogs.js";
import { Feed } from "./feed.js";
import { GraphView } from "./graph.js";
import { GraphToolbar } from "./graph_toolbar.js";
import { MachineDrawing } from "./machine_drawing.js";
import { Lease } from "./lease.js";
import { Machines, isReplay, showRunState } from "./machines.js";
import { Minimap } from "./minimap.js";
import { Panes } from "./panes.js";
import { RunNotices, showNotice } from "./notice.js";
import { EventLog } from "./eventlog.js";
import { exposeToConsole } from "./page_probe.js";
import { BEHIND_FRAME_MS, Renderer } from "./renderer.js";
import { Playhead } from "./timetravel.js";
import { Timeline } from "./timeline.js";
import { TimelineLoader } from "./timeline_loader.js";
import { TreeView } from "./tree.js";
import { UserdataPanel, keyHistory } from "./userdata.js";
import { SceneView } from "./scene.js";
import { SearchPalette } from "./search.js";
import { shownStatus, view } from "./shown.js";
import { parentPath } from "./status.js";
import { Store } from "./store.js";

const $ = (id) => document.getElementById(id);
const failure = (err) => err.detail || err.message;

const KEY_HISTORY_LIMIT = 10000; // events of a run read for one key's history

const store = new Store();
const playhead = new Playhead(api, store, (err) => store.say("Could not show that instant: " + failure(err), "warn"));

const graph = new GraphView($("graph"), {
  select: (path) => select(path),
  contextmenu: (path, x, y) => stateMenu(path, x, y),
  toggle: (path, isCluster) => depth.toggle(path, isCluster),
  userPanned: () => toolbar.stopFollowing(),
});
const toolbar = new GraphToolbar(graph, () => renderer.queue());
new Breadcrumb($("crumb-bar"), $("fit"), graph, {
  label: (path) => store.state.nodes.get(path)?.label ?? path,
  fit: (path) => {
    toolbar.stopFollowing();
    graph.fitPath(path);
  },
  whole: () => graph.fitWhole(),
});
new Minimap($("minimap"), $("minimap-on"), graph, (x, y) => {
  toolbar.stopFollowing();
  graph.centreOn(x, y);
});
new Panes(document.querySelector("main.layout"));
const tree = new TreeView($("tree"), {
  select: (path) => select(path),
  contextmenu: (path, x, y) => stateMenu(path, x, y),
});
const userdata = new UserdataPanel($("userdata"), $("ud-container"), {
  pick: (path) => select(path),
  redraw: () => renderer.queue(),
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
log.nodeOf = (path) => store.state.nodes.get(path);
const timeline = new Timeline($("timeline"), {
  seek: (target) => playhead.seek(target),
  range: (range) => timelineLoader.setRange(range),
  play: () => playhead.play(),
  pause: () => playhead.pause(),
  speed: (x) => playhead.setSpeed(x),
  step: (direction, path) => playhead.step(direction, path),
  live: () => playhead.live(),
  copyLink: () => copyLink(),
});
const scene = new SceneView($("scene-pane"), document.querySelector("main.layout"), api.scenePose);
const notices = new RunNotices(store);
const access = new AccessForm($("access"));
const machines = new Machines($("machine-picker"), store, {
  open: (name) => openMachine(name),
  refused: (yes) => access.show(yes),
  polled: () => {
    if (store.state.machines.online && !scene.url) api.scene().then((s) => scene.show(s && s.url)).catch(() => {});
  },
});
const controls = new Controls(store, notices);
api.session().then((s) => store.setRole(s.role)).catch(() => {}); // no valid token: token.js says so
const lease = new Lease(store, controls);
const audit = new Audit(store);
$("audit-btn").addEventListener("click", () => audit.open());
const breakpoints = new Breakpoints(store, controls);
const debugBar = new DebugBar(store, controls);
const depth = new Depth($("depth"), store, () => graph.openPaths(), (semantic) => drawing.load(semantic), api.anyOpenSet);
const details = new DetailsPanel($("details"), store, api);
const search = new SearchPalette(store, (entry) => goTo(entry));
$("search-btn").addEventListener("click", () => search.open());
const feed = new Feed(store, api, {
  history: (history) => log.history(history),
  events: (applied, all) => {
    notices.events(applied);
    log.add(all);
  },
  missed: (count) => store.say(`${count} events missed: resynchronised from a snapshot`, "warn"),
});
const renderer = new Renderer(store, [render, renderPanels]);
const drawing = new MachineDrawing(store, api, { graph, depth, tree, userdata }, () => renderer.queue());
const timelineLoader = new TimelineLoader(store, api, timeline);
const address = new LinkFollower(store, () => playhead.seeking);

// ---------------------------------------------------------------- what each change of the store draws

store.subscribe((state, part) => {
  switch (part) {
    case "notice": return showNotice($("notice"), $("banner"), state);
    case "structure": return drawing.restructured(state);
    case "machines":
      machines.update(state);
      lease.watch(); // whether this page may control the machine shown may have changed
      return updateTopBar(state);
    case "role":
      lease.watch();
      return updateTopBar(state);
    case "lease": return updateTopBar(state);
    case "connection":
      updateBadge(state);
      return updateTopBar(state);
    // The machine at the instant shown: events are drawn at a pace, and the instant while it plays;
    // what the user does at the next frame.
    case "machine":
      lease.watch();
      return renderer.queue();
    case "live": return renderer.queue(true);
    case "instant": return renderer.queue(state.instant.playing);
    case "selection": return renderer.queue();
  }
});

// ---------------------------------------------------------------- the machine shown

function openMachine(name) {
  store.open(name);
  const link = readLink();
  const entry = store.current();
  playhead.open(name, isReplay(entry), link.machine === name ? link.seq : null);
  if (entry?.replay?.speed) {
    playhead.setSpeed(entry.replay.speed);
    timeline.showSpeed(entry.replay.speed);
  }
  timelineLoader.open();
  machines.opened(name);
  depth.reset();
  notices.forget(); // they were about the machine shown so far
  graph.clear("Waiting for the machine's structure…");
  tree.build(null);
  userdata.show(null);
  log.reset();
  feed.open(name);
}

/** Show what a hash the user changed in the tab names: another machine, another instant, or live. */
function followLink({ machine, seq }) {
  const { name, machines: { list } } = store.state;
  if (machine === null) return;
  if (machine !== name) {
    if (list.some((m) => m.name === machine)) {
      machines.picked = machine; // the user named it: kept shown, as one chosen in the list
      openMachine(machine); // at the link's seq
    }
    else store.say(`No machine named ${machine} here`, "warn");
  } else if (seq !== null) {
    if (!playhead.past || playhead.seq !== seq) playhead.seek({ seq });
  } else if (playhead.past && !playhead.replay) {
    playhead.live();
  }
}

/** Copy the address of the machine at the instant shown, and say who it opens for: it holds no token. */
async function copyLink() {
  const { name, instant } = store.state;
  if (name === null) return;
  const seq = instant.past ? instant.status.last_seq : null;
  const link = linkTo(name, seq);
  const what = `${name} ${seq === null ? "live" : "at event " + seq}`;
  const who = "in this browser; anyone else also needs this dashboard's address with its token (the viewer's, to only watch)";
  try {
    await navigator.clipboard.writeText(link);
    store.say(`Link copied: it opens ${what} ${who}`, "ok");
  } catch (err) { // no clipboard (a page not served from this computer over plain http): the link to copy by hand
    store.say(`Copy this link, which opens ${what} ${who}: ${link}`, "ok");
  }
}

/** The history of `key` of container `path` in the current run, beside the userdata. */
async function showKeyHistory(path, key) {
  const name = store.state.name;
  const s = shownStatus(store.state);
  try {
    const page = await api.history(name, { since: s.run_seq, until: s.last_seq, path, kinds: "start,transition,terminate,userdata",
      limit: KEY_HISTORY_LIMIT });
    if (name === store.state.name) userdata.showHistory(key, keyHistory(page.events, key), page.more);
  } catch (err) {
    store.say("Could not read the history of " + key + ": " + failure(err), "warn");
  }
}

// ---------------------------------------------------------------- selection and the state menu

function select(path) {
  tree.select(path || null);
  if (path) {
    const node = store.state.nodes.get(path);
    userdata.show(node && node.container ? path : parentPath(path) || path);
  }
  store.select(path);
}

/** A search's choice: a userdata key shows its container's userdata; a state, container or outcome (its
 * state) is drawn (the containers on its path opened), brought into view and selected. */
async function goTo(entry) {
  if (entry.kind === "key") {
    userdata.show(entry.path);
    renderer.queue();
    return;
  }
  toolbar.stopFollowing(); // the user looks elsewhere than the active state
  await depth.reveal(entry.path);
  select(entry.path);
  graph.centrePath(entry.path);
}

function stateMenu(path, x, y) {
  const node = store.state.nodes.get(path);
  select(path);
  showMenu(x, y, path, [
    controls.initialStateItem(path),
    ...breakpoints.items(path),
    { label: node && node.container ? "Show userdata" : "Show container userdata", action: () => {
      userdata.show(node?.container ? path : parentPath(path));
      renderer.queue();
    } },
    { label: "Center in graph", action: () => graph.centrePath(path) },
  ]);
}

// ---------------------------------------------------------------- the top bar and the two frames of a drawing

function updateTopBar(state) {
  controls.update(state);
  lease.update(state);
  debugBar.update(state);
  showRunState($("run-state"), shownStatus(state), store.current());
}

function updateBadge(state) {
  showBadge($("badge"), feed.stream, { online: state.machines.online, replay: isReplay(store.current()) });
}

/** The timeline's playhead, and the page framed as looking back when it does. */
function showInstant({ live, instant }) {
  const past = instant.past;
  timeline.setInstant({
    seq: past ? instant.status.last_seq : live.last_seq, t: past ? instant.status.last_t : live.last_t, live: !past,
    behind: past && !instant.replay ? playhead.behind(live) : null, playing: instant.playing,
    liveMachine: !instant.replay,
  });
  document.body.classList.toggle("looking-back", past && !instant.replay);
  feed.pace(past ? BEHIND_FRAME_MS : 0);
}

/** The first frame: the machine at the instant shown (graph, hierarchy, details, timeline, top bar). */
function render(state) {
  if (!state.live) return;
  const s = shownStatus(state);
  const shown = view(s);
  const marks = debugMarks(s);
  graph.apply({ ...shown, ...marks, selected: state.selected });
  depth.show(shown.running, state.selected);
  tree.update(s, shown.failed, marks);
  details.update(state);
  if (graph.follow && graph.activePath) tree.reveal(graph.activePath);
  showInstant(state);
  scene.showPose(state.instant.past ? s.pose : null);
  address.update();
  machines.update(state);
  updateTopBar(state);
}

/** The second frame: the log and the userdata of the instant shown. */
function renderPanels(state) {
  if (!state.live) return;
  const { past, window } = state.instant;
  if (past && !window) log.freeze();
  else log.showPast(past ? window : null);
  log.flush();
  const udPath = userdata.path;
  userdata.update(shownStatus(state), udPath ? state.nodes.get(udPath) : null);
  log.followNewest();
}

// ---------------------------------------------------------------- go

setInterval(() => { // the badge's rate and latency move on with time
  updateBadge(store.state);
  updateTopBar(store.state);
}, 500);
setInterval(() => notices.checkOverdue(), 500);

onLinkChanged(followLink);
exposeToConsole(store);
showNotice($("notice"), $("banner"), store.state);
machines.poll();
