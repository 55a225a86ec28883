"""The panes (fsmscope/static/panes.js): splitters resize the grid's tracks by dragging, the sizes survive a reload
(localStorage), the demo's layout (with the 3D view, 1600x900) gives the hierarchy and the userdata more
than 182 px; and the hierarchy follows the active state (fsmscope/static/tree.js)."""

from __future__ import annotations

import pytest
from browser_support import serving_while_running, watching
from fsmscope.server.testing.big_machine import big_machine
from fsmscope.server.testing.browser import open_page


@pytest.fixture(scope="module")
def served():
    """A server with `big` (280 states), running until the module ends."""
    with serving_while_running(*big_machine(3, 4, 6, tick=0.03), "big") as srv:
        yield srv


@pytest.fixture
def page(browser, served):
    with watching(browser, served, "big") as page:
        yield page


def width(page, selector: str) -> float:
    return page.eval_on_selector(selector, "el => el.getBoundingClientRect().width")


def drag_graph_splitter(page, dx: float) -> None:
    box = page.eval_on_selector(".splitter[data-axis=col]", "el => { const b = el.getBoundingClientRect(); return [b.x + b.width / 2, b.y + b.height / 2]; }")
    page.mouse.move(*box)
    page.mouse.down()
    page.mouse.move(box[0] + dx, box[1], steps=4)
    page.mouse.up()


def test_dragging_the_graphs_splitter_widens_the_right_column(page):
    before = width(page, ".tree-pane")
    drag_graph_splitter(page, -100)
    assert width(page, ".tree-pane") == pytest.approx(before + 100, abs=2)


def test_the_panes_sizes_survive_a_reload(page):
    drag_graph_splitter(page, -80)
    dragged = width(page, ".tree-pane")
    page.reload()
    page.wait_for_selector("#graph svg")
    assert width(page, ".tree-pane") == pytest.approx(dragged, abs=1)
    page.dblclick(".splitter[data-axis=col]")  # the defaults back, for the other tests' pages


def test_the_demos_layout_gives_the_hierarchy_and_userdata_more_than_182_px(browser, served):
    page = open_page(browser, served.url + "#m=big", 1600, 900)
    try:
        page.evaluate("""() => {
          document.getElementById('scene-pane').hidden = false;
          document.querySelector('main.layout').classList.add('with-scene');
        }""")
        heights = [page.eval_on_selector(p, "el => el.getBoundingClientRect().height") for p in (".tree-pane", ".ud-pane")]
        assert min(heights) > 220  # they had 182 px
    finally:
        page.close()


def test_the_hierarchy_scrolls_to_the_active_state_when_following(page):
    page.wait_for_function("""() => {
      const s = window.fsmscope.status;
      const path = s.activePaths().sort((a, b) => b.length - a.length)[0];
      const row = path && document.querySelector(`.tree-row[data-path="${path}"]`);
      const host = document.getElementById('tree');
      if (!row || host.scrollTop < 100) return false;
      const r = row.getBoundingClientRect(), v = host.getBoundingClientRect();
      return r.top >= v.top && r.bottom <= v.bottom;
    }""", timeout=20000)
