"""A machine of several hundred states in the graph pane (issue 11): semantic zoom ("auto" opens the
active path and closes idle branches, fsmscope/static/semantic_zoom.js), the view kept in place across its
re-layouts (graph_fit.js), the breadcrumb of the container in view (breadcrumb.js), a fit that keeps
labels readable, the minimap (minimap.js)."""

from __future__ import annotations

import pytest
from browser_support import serving_while_running, watching
from fsm.observation.schema import container_id
from fsmscope.server.testing.big_machine import big_machine, count_states

SHAPE = (3, 4, 6)  # branching, depth, leaves: 40 containers, 280 states
TICK = 0.1  # seconds a leaf runs: a container is active about 0.6 s, longer than semantic zoom takes to open it (<= 400 ms apart)

# The deepest active state of the status shown, and whether the graph draws it itself (not a closed
# ancestor) inside the graph pane.
ACTIVE_IN_VIEW = """() => {
  const s = window.fsmscope.status;
  const path = s.activePaths().sort((a, b) => b.length - a.length)[0];
  const el = path && document.getElementById('s:' + path);
  if (!el) return null;
  const box = el.getBoundingClientRect();
  const view = document.getElementById('graph').getBoundingClientRect();
  const inside = box.left >= view.left && box.right <= view.right && box.top >= view.top && box.bottom <= view.bottom;
  return { path, inside };
}"""

# The on-screen size (px) of the labels of the states in view: the font size times the drawing's scale.
# The part of the drawing on screen, in its user space: the graph's box through the drawing's screen matrix.
SHOWN = """() => {
  const svg = document.querySelector('#graph svg.fsm-graph');
  const box = document.querySelector('#graph').getBoundingClientRect();
  const toUser = svg.getScreenCTM().inverse();
  const a = new DOMPoint(box.left, box.top).matrixTransform(toUser);
  const b = new DOMPoint(box.right, box.bottom).matrixTransform(toUser);
  return [a.x, a.y, b.x - a.x, b.y - a.y];
}"""
LABEL_PX = """() => {
  const view = document.getElementById('graph').getBoundingClientRect();
  return [...document.querySelectorAll('#graph svg.fsm-graph g.node text')].filter((t) => {
    const b = t.getBoundingClientRect();
    return b.left >= view.left && b.right <= view.right && b.top >= view.top && b.bottom <= view.bottom;
  }).map((t) => parseFloat(t.getAttribute('font-size')) * t.getScreenCTM().a);
}"""


@pytest.fixture(scope="module")
def served():
    """A server with `big` (280 states), running until the module ends."""
    assert count_states(*SHAPE) == 280
    with serving_while_running(*big_machine(*SHAPE, tick=TICK), "big") as srv:
        yield srv


@pytest.fixture
def page(browser, served):
    with watching(browser, served, "big", ready="#run-state.running") as page:
        yield page


def open_all(page) -> None:
    """Choose the deepest depth: every container drawn open."""
    page.select_option("#depth", page.eval_on_selector("#depth", "s => [...s.options].filter(o => /^\\d+$/.test(o.value)).pop().value"))
    page.wait_for_function("() => document.querySelectorAll('#graph g.cluster').length === 40", timeout=30000)


def test_semantic_zoom_draws_the_active_leaf_in_view_as_the_machine_moves_across_containers(page):
    containers = set()
    for _ in range(3):
        seen = page.wait_for_function("""(known) => {
          const r = (%s)();
          const container = r && r.path.slice(0, r.path.lastIndexOf('/'));
          return r && r.inside && !known.includes(container) ? container : null;
        }""" % ACTIVE_IN_VIEW, arg=sorted(containers), timeout=20000)
        containers.add(seen.json_value())
    assert len(containers) == 3


def test_semantic_zoom_leaves_idle_branches_closed(page):
    page.wait_for_function("() => document.querySelectorAll('#graph g.cluster').length >= 3", timeout=20000)
    assert page.evaluate("document.querySelectorAll('#graph g.cluster').length") < 40


# A state's place on screen, read in one task with the drawing it is in (a re-layout between two
# protocol calls would leave a detached element, whose box is empty).
PLACE = """(id) => {
  const el = document.getElementById(id);
  const b = el.getBoundingClientRect();
  return { drawing: el.ownerSVGElement === window.__drawing, at: [b.x, b.y] };
}"""

# The page's next request for a drawing waits until the test calls window.__held().
HOLD_NEXT_DRAWING = """() => {
  const fetched = window.fetch;
  window.fetch = (url, init) => {
    if (!String(url).includes('/graph.svg')) return fetched(url, init);
    window.fetch = fetched;
    return new Promise((release) => { window.__held = release; }).then(() => fetched(url, init));
  };
}"""


def test_a_relayout_keeps_the_state_selected_while_it_was_laid_out_where_it_was_on_screen(page):
    """Semantic zoom asks for a new drawing; the user selects a state before it comes: the new drawing
    keeps that state in place, not the one that was selected (or active) when it was asked for."""
    root = page.evaluate("window.fsmscope.status.root_path")
    first = root + "/W_0"
    page.uncheck("#follow")
    page.wait_for_selector("#graph svg.fsm-graph")  # the first drawing (a fit) is in
    page.evaluate(HOLD_NEXT_DRAWING)
    page.wait_for_function("() => window.__held", timeout=20000)
    page.click('.tree-row[data-path="%s"] .label' % first)
    page.evaluate("() => { window.__drawing = document.querySelector('#graph svg.fsm-graph'); }")
    before = page.evaluate(PLACE, "s:" + first)
    page.evaluate("() => window.__held()")
    page.wait_for_function("() => document.querySelector('#graph svg.fsm-graph') !== window.__drawing", timeout=20000)
    after = page.evaluate(PLACE, "s:" + first)
    assert before["drawing"] and not after["drawing"]
    assert after["at"] == pytest.approx(before["at"], abs=1.0)


def test_the_breadcrumb_names_the_container_at_the_view_centre(page):
    page.uncheck("#follow")  # nothing but the drag moves the view
    page.select_option("#depth", "2")
    root = page.evaluate("window.fsmscope.status.root_path")
    target = container_id(root + "/TASK_1")
    # The drawing of depth 2 (the root and its 3 tasks open), not semantic zoom's, which may have TASK_1 open too.
    page.wait_for_function("(id) => document.querySelectorAll('#graph g.cluster').length === 4"
                           " && document.getElementById(id) !== null", arg=target)
    centre = "el => { const b = el.getBoundingClientRect(); return [b.x + b.width / 2, b.y + b.height / 2]; }"
    view = page.eval_on_selector("#graph", centre)
    for _ in range(10):  # drags of at most 200 px, the pointer always inside the page, until TASK_1 is at the centre
        box = page.eval_on_selector('[id="%s"]' % target, centre)
        step = [max(-200.0, min(200.0, v - b)) for v, b in zip(view, box)]
        if max(map(abs, step)) < 2:
            break
        page.mouse.move(*view)
        page.mouse.down()
        page.mouse.move(view[0] + step[0], view[1] + step[1], steps=4)
        page.mouse.up()
    page.wait_for_function("() => document.querySelector('.crumbs li:last-child')?.textContent === 'TASK_1'")
    assert page.eval_on_selector_all(".crumbs li", "els => els.length") == 2


def test_clicking_a_crumb_fits_its_container(page):
    page.select_option("#depth", "2")
    page.uncheck("#follow")
    page.wait_for_selector(".crumbs button")
    root = page.evaluate("window.fsmscope.status.root_path")
    page.click('.crumbs button[data-path="%s"]' % root)
    frame = page.eval_on_selector('[id="%s"] > polygon' % container_id(root), "el => { const b = el.getBoundingClientRect(); return [b.width, b.height]; }")
    view = page.eval_on_selector("#graph", "el => { const b = el.getBoundingClientRect(); return [b.width, b.height]; }")
    assert max(frame[0] / view[0], frame[1] / view[1]) == pytest.approx(1.0, abs=0.1)


def test_fit_on_the_whole_open_machine_keeps_labels_readable(page):
    open_all(page)
    page.click("#fit")
    sizes = page.evaluate(LABEL_PX)
    assert sizes and min(sizes) >= 9


def test_fit_says_what_it_shows_when_the_whole_would_be_unreadable(page):
    open_all(page)
    page.uncheck("#follow")  # the note goes once the view is another than the fit's: Follow's pan would move it
    page.click("#fit")
    assert "px labels" in page.text_content(".fit-note")
    assert "px labels" in page.get_attribute("#fit", "title")


def test_the_readable_zoom_gives_labels_of_13_px(page):
    page.click("#zoom-out")
    page.click("#zoom-readable")
    assert page.evaluate(LABEL_PX)[0] == pytest.approx(13, abs=0.2)


def test_the_minimap_outlines_the_part_of_the_drawing_in_view(page):
    open_all(page)
    page.uncheck("#follow")  # the view stays where the fit put it
    page.click("#fit")
    page.wait_for_function("""() => {
      const shown = (%s)();
      const rect = document.querySelector('.mm-view');
      return ['x', 'y', 'width', 'height'].every((a, i) => Math.abs(Number(rect.getAttribute(a)) - shown[i]) < 0.5);
    }""" % SHOWN)
    assert page.is_visible("#minimap")


def test_clicking_the_minimap_centres_the_graph_there(page):
    open_all(page)
    page.click("#fit")
    page.click("#minimap svg")  # its centre: the drawing's centre
    vb = page.evaluate(SHOWN)
    base = page.eval_on_selector(".mm-outline rect", "r => ['x', 'y', 'width', 'height'].map((a) => Number(r.getAttribute(a)))")
    assert vb[0] + vb[2] / 2 == pytest.approx(base[0] + base[2] / 2, abs=base[2] * 0.02)
    assert page.is_checked("#follow") is False
