// Which view box the graph shows when it is fitted, and when a new layout replaces the drawing: a
// fit that keeps labels readable on a big machine, and an anchor that keeps one element where it was
// on screen across a re-layout (Graphviz lays the whole drawing out again: without it, what stays
// open jumps). Functions of a GraphView `g` (graph.js): its base, clusters, elements and scale.

import { COMFORT_SCALE, LABEL_PT, MAX_FIT_SCALE, READABLE_SCALE, fitScale, fitView, userBox, viewAt } from "./graph_geometry.js";
import { containerId, stateId } from "./schema.js";
import { parentPath } from "./status.js";

/** The last segment of a path: the state's name, for what the page says. */
const nameOf = (path) => path.slice(path.lastIndexOf("/") + 1);

/** The frame of the deepest open container holding `path` (itself included), the root's excluded. */
function clusterOf(g, path) {
  for (let p = path; p; p = parentPath(p)) {
    const index = g.clusters.findIndex((c) => c.path === p);
    if (index >= 0) return index === 0 ? null : g.clusters[index];
  }
  return null;
}

/**
 * The whole drawing, centred (at most MAX_FIT_SCALE, a small one at the top); when its labels would
 * be under READABLE_PX: the container of the selection (or of the active state), or, too big as well,
 * that state (or the drawing's top left) with labels of 13 px, kept clear of the host's bottom
 * `g.inset` px (the minimap, shown while a part is). `note` says which ("" for the whole).
 * @param {DOMRect} rect the host's size
 * @returns {{vb: import("./graph_geometry.js").Box, note: string}}
 */
export function readableFit(g, rect) {
  const base = g.base;
  const whole = fitScale(base, rect.width, rect.height);
  if (whole >= READABLE_SCALE) {
    const vb = fitView(base, rect.width, rect.height);
    if (whole > MAX_FIT_SCALE) vb.y = base.y - 8 / MAX_FIT_SCALE; // a small graph sits at the top
    return { vb, note: "" };
  }
  const tiny = `the whole graph would have ${(whole * LABEL_PT).toFixed(1)} px labels`;
  const focus = g.selectedPath || g.activePath;
  const cluster = focus ? clusterOf(g, focus) : null;
  const clusterScale = cluster ? Math.min(fitScale(cluster.box, rect.width, rect.height - g.inset), MAX_FIT_SCALE) : 0;
  if (cluster && clusterScale >= READABLE_SCALE) {
    return { vb: partView(cluster.box, clusterScale, rect, g.inset), note: `Fit shows ${nameOf(cluster.path)}: ${tiny}` };
  }
  const el = focus ? g.stateElement(focus) : null;
  if (!el) {
    const vb = { x: base.x - 8, y: base.y - 8, w: rect.width / COMFORT_SCALE, h: rect.height / COMFORT_SCALE };
    return { vb, note: `Fit shows the top left: ${tiny}` };
  }
  return { vb: partView(userBox(el, g.svg), COMFORT_SCALE, rect, g.inset),
    note: `Fit shows ${nameOf(g.pathOf.get(el.id) ?? focus)}: ${tiny}` };
}

/** The view box at `scale` that centres `box` in the part of the host above its bottom `inset` px. */
export function partView(box, scale, rect, inset) {
  return viewAt(box.x + box.w / 2, box.y + box.h / 2 + inset / 2 / scale, scale, rect.width, rect.height);
}

/** Where the elements standing for `path` and its ancestors are in the view before a re-layout: a
 * node by its centre, an open container by its top left corner (it grows right and down when a child
 * opens), in user space with the view box shown; null when none is drawn. Read from the drawing's
 * attributes: no layout. */
export function anchorBefore(g, path) {
  if (!g.vb) return null;
  const spots = [];
  for (let p = path; p; p = parentPath(p)) {
    for (const id of [stateId(p), containerId(p)]) {
      const el = g.el(id);
      const cluster = id !== stateId(p);
      if (el) spots.push({ id, cluster, at: anchorPoint(el, g.svg, cluster) });
    }
  }
  return spots.length ? { spots, vb: { ...g.vb } } : null;
}

/** The view box of the new drawing, at the old scale, that puts the first of the anchor's elements it
 * still has where it was in the view; null when it has none of them. */
export function anchorAfter(g, { spots, vb }) {
  for (const { id, cluster, at } of spots) {
    const el = g.el(id);
    if (!el) continue;
    const now = anchorPoint(el, g.svg, cluster);
    return { ...vb, x: vb.x + now.x - at.x, y: vb.y + now.y - at.y };
  }
  return null;
}

/** A node's centre, or an open container's top left corner, in user space. */
function anchorPoint(el, svg, cluster) {
  const box = userBox(el, svg);
  return cluster ? { x: box.x, y: box.y } : { x: box.x + box.w / 2, y: box.y + box.h / 2 };
}
