// The graph's pointer (graph.js): the wheel zooms about the pointer, a drag pans (and tells the page
// the user moved the view), a click selects, a double-click opens or closes a container, a right
// click asks for the state menu. Elements are found by their ids, looked up in the graph's index.

import { ZOOM_STEP } from "./graph_geometry.js";
import { stateId } from "./schema.js";

/** The state or container under `event` in `graph`: {path, cluster, el}, or null. */
function targetOf(graph, event) {
  const g = event.target.closest?.("g.node, g.cluster");
  if (!g || !graph.svg?.contains(g)) return null;
  const path = graph.pathOf.get(g.id);
  if (path === undefined) return null;
  // A cluster or a container's outcome stands for the open container (double-click closes it).
  return { path, cluster: g.id !== stateId(path), el: g };
}

/**
 * @param {import("./graph.js").GraphView} graph
 * @param {object} handlers {select(path), contextmenu(path, x, y), toggle(path), userPanned()}
 */
export function bindPointer(graph, handlers) {
  const host = graph.host;
  let drag = null;
  host.addEventListener("wheel", (e) => {
    if (!graph.svg) return;
    e.preventDefault();
    // A wheel notch (100 px, or 3 lines) is one zoom step.
    graph.zoom(ZOOM_STEP ** (-e.deltaY / (e.deltaMode === 1 ? 3 : 100)), e.clientX, e.clientY);
  }, { passive: false });
  host.addEventListener("pointerdown", (e) => {
    if (!graph.svg || e.button !== 0) return;
    drag = { x: e.clientX, y: e.clientY, vb: { ...graph.vb }, k: graph.scale(), moved: false };
  });
  host.addEventListener("pointermove", (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x;
    const dy = e.clientY - drag.y;
    if (!drag.moved && Math.hypot(dx, dy) < 4) return;
    if (!drag.moved) {
      drag.moved = true;
      host.setPointerCapture(e.pointerId);
      host.classList.add("dragging");
      handlers.userPanned?.();
    }
    graph.setViewBox({ ...drag.vb, x: drag.vb.x - dx / drag.k, y: drag.vb.y - dy / drag.k });
  });
  const end = (e) => {
    if (!drag) return;
    if (drag.moved) {
      host.classList.remove("dragging");
      if (host.hasPointerCapture(e.pointerId)) host.releasePointerCapture(e.pointerId);
      // The click that follows a drag must not select anything.
      const swallow = (ev) => { ev.stopPropagation(); };
      host.addEventListener("click", swallow, { capture: true, once: true });
      setTimeout(() => host.removeEventListener("click", swallow, { capture: true }), 0);
    }
    drag = null;
  };
  host.addEventListener("pointerup", end);
  host.addEventListener("pointercancel", end);
  host.addEventListener("click", (e) => {
    const t = targetOf(graph, e);
    handlers.select?.(t ? t.path : null);
  });
  host.addEventListener("dblclick", (e) => {
    const t = targetOf(graph, e);
    if (t) handlers.toggle?.(t.path, t.cluster);
  });
  host.addEventListener("contextmenu", (e) => {
    const t = targetOf(graph, e);
    if (!t) return;
    e.preventDefault();
    handlers.contextmenu?.(t.path, e.clientX, e.clientY);
  });
}
