"""A newcomer's first view of a machine at 1440 x 900 (issue 31 item 7): a machine of a few dozen
states (the demo's, a 31-state script) is shown whole with labels that can be read, none under the
minimap; a bigger one opens readable on its active path, the whole graph one click away; what the
fit says it shows is true while it is shown and gone once the view is another; the minimap marks
the active state no bigger than it is."""

from __future__ import annotations

import threading

import fsm
import pytest
from browser_support import page_at, serving_while_running
from fsmscope.server.http_server import ServerThread
from fsmscope.server.testing.big_machine import big_machine
from fsmscope.server.testing.mission import mission_machine

WIDTH, HEIGHT = 1440, 900
FLOOR_PX = 9  # a state's label on screen, at least

# Every state's and container's label (a closed container's in its box, an open one's atop its frame): whether its box lies inside the graph pane and clear of the
# minimap (when that is shown), and its size on screen (px).
LABELS = """() => {
  const pane = document.getElementById('graph').getBoundingClientRect();
  const mm = document.getElementById('minimap');
  const map = mm.hidden ? null : mm.getBoundingClientRect();
  return [...document.querySelectorAll('#graph svg.fsm-graph :is(g.node.state, g.node.container, g.cluster) > text')].map((t) => {
    const b = t.getBoundingClientRect();
    const inside = b.left >= pane.left && b.right <= pane.right && b.top >= pane.top && b.bottom <= pane.bottom;
    const under = !!map && b.right > map.left && b.left < map.right && b.bottom > map.top && b.top < map.bottom;
    return { label: t.textContent, inside, under, px: parseFloat(t.getAttribute('font-size')) * t.getScreenCTM().a };
  });
}"""


# LABELS of the elements whose ids hold a path part (an open container's frame and what is in it).
LABELS_IN = """(part) => {
  const all = (%s)();
  const texts = [...document.querySelectorAll('#graph svg.fsm-graph :is(g.node.state, g.node.container, g.cluster) > text')];
  return all.filter((label, i) => texts[i].parentElement.id.includes(part));
}""" % LABELS


def demo_machine():
    """The demo's pick-and-place machine (fsmscope/sim/task.py) on its simulated world, not run."""
    from fsmscope.sim.task import build_task_machine
    from fsmscope.sim.world import World

    return build_task_machine(World())


@pytest.fixture(scope="module")
def served():
    """One server with the demo's machine (never run) and a 31-state script waiting in its first step."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    gate = threading.Event()
    mission = mission_machine(gate)
    srv = ServerThread().start()
    srv.hub.add_local(demo_machine(), name="demo")
    srv.hub.add_local(mission, name="mission")
    runner = threading.Thread(target=mission.execute)
    runner.start()
    yield srv
    gate.set()
    runner.join(10)
    srv.stop()


@pytest.fixture(scope="module", params=["demo", "mission"])
def first_view(request, browser, served):
    """The labels of the first view of each machine, as a new page shows it."""
    with page_at(browser, served.url + "#m=" + request.param, "#badge.live", WIDTH, HEIGHT) as page:
        page.wait_for_selector("#graph svg.fsm-graph")
        page.wait_for_timeout(300)  # the first frames: the marks, a fit made again on the active state
        yield page.evaluate(LABELS), page


def test_the_first_view_shows_every_state(first_view):
    labels, _ = first_view
    assert len(labels) >= 19
    assert [label["label"] for label in labels if not label["inside"]] == []


def test_the_first_view_labels_are_readable(first_view):
    labels, _ = first_view
    assert min(label["px"] for label in labels) >= FLOOR_PX


def test_the_minimap_covers_no_state_of_the_first_view(first_view):
    labels, _ = first_view
    assert [label["label"] for label in labels if label["under"]] == []


def test_fit_shows_the_whole_machine_and_says_nothing_more(first_view):
    _, page = first_view
    page.click("#zoom-in")
    page.click("#fit")
    labels = page.evaluate(LABELS)
    assert all(label["inside"] and not label["under"] for label in labels)
    assert page.text_content(".fit-note") == ""


# ------------------------------------------------------------------ a machine of 600 states

@pytest.fixture(scope="module")
def big():
    """600 states (40 containers), running: each leaf 0.2 s; beside it the 31-state mission."""
    with serving_while_running(*big_machine(3, 4, 14, tick=0.2), "big") as srv:
        srv.hub.add_local(mission_machine(), name="mission")  # never run
        yield srv


@pytest.fixture
def big_page(browser, big):
    with page_at(browser, big.url + "#m=big", "#run-state.running", WIDTH, HEIGHT) as page:
        yield page


def open_all(page) -> None:
    """Every container drawn open (the deepest depth)."""
    page.select_option("#depth", page.eval_on_selector("#depth", "s => [...s.options].filter(o => /^\\d+$/.test(o.value)).pop().value"))
    page.wait_for_function("() => document.querySelectorAll('#graph g.cluster').length === 40", timeout=30000)


def test_a_big_machine_opens_on_its_active_state_with_readable_labels(big_page):
    active = big_page.wait_for_function("""() => {
      const ids = [...document.querySelectorAll('#graph g.node.active')].map((g) => g.id).sort((a, b) => b.length - a.length);
      return ids[0] || null;
    }""").json_value()
    box = big_page.eval_on_selector('[id="%s"]' % active, "el => { const b = el.getBoundingClientRect(); return [b.left, b.top, b.right, b.bottom]; }")
    pane = big_page.eval_on_selector("#graph", "el => { const b = el.getBoundingClientRect(); return [b.left, b.top, b.right, b.bottom]; }")
    assert pane[0] <= box[0] and box[2] <= pane[2] and pane[1] <= box[1] and box[3] <= pane[3]
    shown = [label["px"] for label in big_page.evaluate(LABELS) if label["inside"]]
    assert shown and min(shown) >= FLOOR_PX


def test_the_fit_note_offers_the_whole_graph_in_one_click(big_page):
    open_all(big_page)
    big_page.uncheck("#follow")  # the view stays the fit's until the click
    big_page.click("#fit")
    assert "px labels" in big_page.text_content(".fit-note")
    big_page.click(".fit-whole")
    assert big_page.text_content(".fit-note") == ""
    assert big_page.is_hidden("#minimap")  # the whole graph is in view: no map is needed
    assert all(label["inside"] for label in big_page.evaluate(LABELS))


@pytest.mark.parametrize("move", ["#zoom-in", "#zoom-out", "drag"])
def test_the_fit_note_goes_once_the_view_is_another(big_page, move):
    open_all(big_page)
    big_page.uncheck("#follow")
    big_page.click("#fit")
    assert "Fit shows" in big_page.text_content(".fit-note")
    if move == "drag":
        big_page.mouse.move(500, 500)
        big_page.mouse.down()
        big_page.mouse.move(400, 420, steps=4)
        big_page.mouse.up()
    else:
        big_page.click(move)
    assert big_page.text_content(".fit-note") == ""
    assert "Fit shows" not in big_page.get_attribute("#fit", "title")


def test_the_fit_note_goes_with_the_machine_it_was_about(big_page):
    open_all(big_page)
    big_page.uncheck("#follow")
    big_page.click("#fit")
    assert "Fit shows" in big_page.text_content(".fit-note")
    big_page.select_option("#machine-picker", "mission")
    big_page.wait_for_selector('#graph [id="s:/SM_ROOT/SHUTDOWN"]', state="attached")
    assert big_page.text_content(".fit-note") == ""
    assert all(label["inside"] for label in big_page.evaluate(LABELS))


def test_a_fit_of_the_selections_container_keeps_its_states_clear_of_the_minimap(big_page):
    open_all(big_page)
    big_page.uncheck("#follow")
    big_page.keyboard.press("Control+k")  # the search palette: the state chosen is selected
    big_page.fill("#search-dialog input", "W_0_0_0_13")
    big_page.wait_for_selector("#search-dialog li[aria-selected=true]")
    big_page.keyboard.press("Enter")
    big_page.click("#fit")
    assert "Fit shows TASK_0_0_0" in big_page.text_content(".fit-note")
    assert big_page.is_visible("#minimap")
    labels = big_page.evaluate(LABELS_IN, "/TASK_0/TASK_0_0/TASK_0_0_0")
    assert len(labels) == 15  # its 14 states and its own label
    assert [label["label"] for label in labels if label["under"] or not label["inside"]] == []
    frame = big_page.eval_on_selector('[id="c:%s/TASK_0/TASK_0_0/TASK_0_0_0"] > polygon' % big_page.evaluate("window.fsmscope.status.root_path"),
                                      "el => { const b = el.getBoundingClientRect(); return [b.left, b.top, b.right, b.bottom]; }")
    minimap = big_page.eval_on_selector("#minimap", "el => { const b = el.getBoundingClientRect(); return [b.left, b.top, b.right, b.bottom]; }")
    assert frame[3] <= minimap[1] or frame[2] <= minimap[0]  # the whole frame above or left of the minimap


def test_the_minimap_marks_the_active_state_no_bigger_than_it_is(big_page):
    open_all(big_page)
    big_page.click("#fit")
    sizes = big_page.wait_for_function("""() => {
      const g = document.querySelector('#graph g.node.active');
      const mark = document.querySelector('.mm-active');
      if (!g || !mark || !mark.getBBox().width) return null;
      const ids = [...document.querySelectorAll('#graph g.node.active')].map((n) => n.id).sort((a, b) => b.length - a.length);
      const el = document.getElementById(ids[0]).querySelector(':scope > :is(polygon, path, ellipse)');
      const box = el.getBBox();
      const base = document.querySelector('#minimap svg').viewBox.baseVal;
      const m = mark.getBBox();
      return { mark: [m.width, m.height], state: [box.width, box.height], floor: Math.max(base.width, base.height) / 50 };
    }""").json_value()
    for mark, state in zip(sizes["mark"], sizes["state"]):
        assert mark <= max(state, sizes["floor"]) + 0.5


def test_the_minimap_can_be_hidden(big_page):
    open_all(big_page)
    big_page.uncheck("#follow")
    big_page.click("#fit")
    assert big_page.is_visible("#minimap")
    big_page.uncheck("#minimap-on")
    big_page.wait_for_selector("#minimap", state="hidden")
    big_page.click("#zoom-in")
    assert big_page.is_hidden("#minimap")
