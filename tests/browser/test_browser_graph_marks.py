"""The graph's marks are drawn by an overlay of copies (fsmscope/static/graph_marks.js): each marked element of the
drawing has a copy lying exactly over it, styled by the mark, while the drawing itself is never restyled (so
Chromium never repaints it when the instant changes)."""

from __future__ import annotations

import threading

import fsm
import pytest
from browser_support import mark_style, page_while_waiting
from fsm.observation.schema import container_id, edge_id, state_id

SUB = "/SM_ROOT/SUB"
WAITING = SUB + "/X"

# For each drawing element with `cls`: [its id, its shape's box], and the boxes of the shapes of the overlay's
# copies with m-<cls> (a shape's box leaves its stroke out, which the mark widens).
COPIES = """(cls) => {
  const box = (el) => {
    const b = el.querySelector('ellipse, polygon, path').getBoundingClientRect();
    return [b.x, b.y, b.width, b.height];
  };
  const copies = [...document.querySelectorAll('#graph svg.graph-marks g.m-' + cls)].map(box);
  return { marked: [...document.querySelectorAll('#graph svg.fsm-graph .' + cls)].map((el) => [el.id, box(el)]),
           copies };
}"""
def nested_machine(gate: threading.Event):
    """SM_ROOT: A -go-> SUB (X waits for `gate`, then ok) -ok-> B -go-> done."""
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "SUB"})
        sub = fsm.StateMachine(outcomes=["ok"])
        with sub:
            fsm.StateMachine.add("X", fsm.CBState(lambda ud: gate.wait(30) and "ok", outcomes=["ok"]), {"ok": "ok"})
        fsm.StateMachine.add("SUB", sub, {"ok": "B"})
        fsm.StateMachine.add("B", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "done"})
    return sm


@pytest.fixture(scope="module")
def waiting_in_x(browser):  # noqa: F811
    """A page watching the machine, drawn with SUB open, while X waits."""
    with page_while_waiting(browser, nested_machine, "nested") as page:
        page.select_option("#depth", page.eval_on_selector("#depth", "s => [...s.options].pop().value"))
        page.wait_for_selector('#graph [id="%s"].active' % state_id(WAITING))
        page.wait_for_function("() => document.querySelectorAll('#graph svg.graph-marks g.m-active').length >= 3")
        yield page


def assert_copies_lie_over(page, cls: str) -> None:
    found = page.evaluate(COPIES, cls)
    assert found["marked"], "nothing is marked %s" % cls
    assert len(found["copies"]) == len(found["marked"])
    for element_id, box in found["marked"]:
        assert any(all(abs(a - b) < 0.75 for a, b in zip(box, copy)) for copy in found["copies"]), element_id


def test_each_active_element_has_a_copy_lying_exactly_over_it(waiting_in_x):
    ids = [i for i, _ in waiting_in_x.evaluate(COPIES, "active")["marked"]]
    assert state_id(WAITING) in ids and container_id(SUB) in ids
    assert_copies_lie_over(waiting_in_x, "active")


def test_the_last_edge_taken_has_a_copy_lying_over_it(waiting_in_x):
    assert [i for i, _ in waiting_in_x.evaluate(COPIES, "last")["marked"]] == [edge_id("/SM_ROOT", "A", "go")]
    assert_copies_lie_over(waiting_in_x, "last")


def test_the_copies_stay_over_their_elements_when_the_graph_is_zoomed(waiting_in_x):
    waiting_in_x.click("#zoom-in")
    try:
        assert_copies_lie_over(waiting_in_x, "active")
    finally:
        waiting_in_x.click("#fit")


def test_the_active_state_is_filled_in_its_copy_and_the_drawing_is_not_restyled(waiting_in_x):
    drawn = waiting_in_x.eval_on_selector('[id="%s"] > path' % state_id(WAITING), "el => getComputedStyle(el).fill")
    assert drawn == "none"  # the state's own shape keeps Graphviz's fill: no repaint of the drawing
    assert mark_style(waiting_in_x, state_id(WAITING), "fill") not in (None, "none")


def test_an_open_containers_copy_is_unfilled_so_the_states_inside_show(waiting_in_x):
    assert mark_style(waiting_in_x, container_id(SUB), "fill") == "none"


def test_a_copy_goes_when_its_element_is_no_longer_marked(waiting_in_x):
    waiting_in_x.click('[id="%s"]' % state_id("/SM_ROOT/A"))
    waiting_in_x.wait_for_selector("#graph svg.graph-marks g.m-selected")
    waiting_in_x.click('[id="%s"]' % state_id("/SM_ROOT/B"))
    waiting_in_x.wait_for_selector('#graph [id="%s"].selected' % state_id("/SM_ROOT/B"))
    assert_copies_lie_over(waiting_in_x, "selected")
    assert [i for i, _ in waiting_in_x.evaluate(COPIES, "selected")["marked"]] == [state_id("/SM_ROOT/B")]
