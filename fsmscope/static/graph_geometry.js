// Where things are in the drawing's user space (SVG units: Graphviz's points), read from attributes
// where possible so that asking forces no layout, and the view box arithmetic of fitting and zooming.

/** @typedef {{x: number, y: number, w: number, h: number}} Box */

// The nodes' labels are 12 pt (server/graph.py); under 9 px on screen they cannot be read.
export const LABEL_PT = 12;
export const READABLE_PX = 9;
export const READABLE_SCALE = READABLE_PX / LABEL_PT; // px per SVG unit at which labels can be read
export const COMFORT_SCALE = 13 / LABEL_PT; // the "readable" zoom: labels of 13 px
export const MAX_FIT_SCALE = 1.7; // px per SVG unit: about 1.3 times Graphviz's natural size
export const ZOOM_STEP = 1.6; // one "+" / "-" or wheel notch: a fitted whole is readable in a few

/** The transform from an element's own coordinates to its <svg>'s user space (read from the
 * attributes: no layout). */
export function placement(el, root) {
  let matrix = new DOMMatrix();
  for (let e = el; e && e !== root; e = e.parentElement) {
    const list = e.transform?.baseVal;
    if (!list) continue;
    let own = new DOMMatrix();
    for (let i = 0; i < list.numberOfItems; i++) own = own.multiply(DOMMatrix.fromMatrix(list.getItem(i).matrix));
    matrix = own.multiply(matrix);
  }
  return matrix;
}

/** The box around `points` (in `matrix`'s source coordinates), in user space. */
function boxOf(points, matrix) {
  let [x0, y0, x1, y1] = [Infinity, Infinity, -Infinity, -Infinity];
  for (const p of points) {
    const q = matrix.transformPoint(p);
    [x0, y0, x1, y1] = [Math.min(x0, q.x), Math.min(y0, q.y), Math.max(x1, q.x), Math.max(y1, q.y)];
  }
  return { x: x0, y: y0, w: x1 - x0, h: y1 - y0 };
}

/** The points that outline an element's own shapes (its polygons, ellipses and paths: what Graphviz
 * draws a node or a frame with), in its coordinates, read from their attributes. */
function outline(el) {
  const points = [];
  for (const shape of el.querySelectorAll(":scope > polygon, :scope > ellipse, :scope > path")) {
    if (shape.localName === "polygon") {
      for (const p of shape.points) points.push(new DOMPoint(p.x, p.y));
    } else if (shape.localName === "ellipse") {
      const [cx, cy, rx, ry] = ["cx", "cy", "rx", "ry"].map((a) => shape[a].baseVal.value);
      points.push(new DOMPoint(cx - rx, cy - ry), new DOMPoint(cx + rx, cy + ry));
    } else {
      // dot's paths are absolute "M x,y C x,y x,y x,y ...": their control points bound the curve
      const n = (shape.getAttribute("d") || "").match(/-?(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?/gi) || [];
      for (let i = 0; i + 1 < n.length; i += 2) points.push(new DOMPoint(Number(n[i]), Number(n[i + 1])));
    }
  }
  return points;
}

/** An element's box in its own coordinates: from its shapes' attributes, so that asking forces no
 * layout (getBBox, which does, only for an element drawn without any). */
export function ownBox(el) {
  const points = outline(el);
  if (!points.length) {
    const b = el.getBBox();
    return { x: b.x, y: b.y, w: b.width, h: b.height };
  }
  return boxOf(points, new DOMMatrix());
}

/** An element's box in the user space of `root` (no layout: `ownBox`). */
export function userBox(el, root) {
  const b = ownBox(el);
  const corners = [[b.x, b.y], [b.x + b.w, b.y], [b.x, b.y + b.h], [b.x + b.w, b.y + b.h]];
  return boxOf(corners.map(([x, y]) => new DOMPoint(x, y)), placement(el, root));
}

/** Every open container's frame in user space, parents before their children (document order),
 * from the frames' points: no layout. */
export function clusterBoxes(svg, pathOf) {
  const out = [];
  for (const g of svg.querySelectorAll("g.cluster")) {
    const path = pathOf.get(g.id);
    const frame = g.querySelector(":scope > polygon");
    if (path === undefined || !frame || !frame.points.numberOfItems) continue;
    out.push({ path, box: boxOf([...frame.points].map((p) => new DOMPoint(p.x, p.y)), placement(frame, svg)) });
  }
  return out;
}

/** The deepest of `clusters` (parents first) whose box holds the point. */
export function clusterAt(clusters, x, y) {
  let found = null;
  for (const c of clusters) {
    if (x >= c.box.x && x <= c.box.x + c.box.w && y >= c.box.y && y <= c.box.y + c.box.h) found = c;
  }
  return found;
}

/** The view box of `width` x `height` px at `scale` px per unit centred on (cx, cy). */
export function viewAt(cx, cy, scale, width, height) {
  const w = width / scale;
  const h = height / scale;
  return { x: cx - w / 2, y: cy - h / 2, w, h };
}

/** The scale (px per unit) at which `box`, padded by 2 %, fills a host of `width` x `height` px. */
export function fitScale(box, width, height) {
  const pad = Math.max(box.w, box.h) * 0.04 + 8;
  return Math.min(width / (box.w + pad), height / (box.h + pad));
}

/** The view box that shows `box` whole and centred in a host of `width` x `height` px, at most
 * MAX_FIT_SCALE. */
export function fitView(box, width, height) {
  const scale = Math.min(fitScale(box, width, height), MAX_FIT_SCALE);
  return viewAt(box.x + box.w / 2, box.y + box.h / 2, scale, width, height);
}
