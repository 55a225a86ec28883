"""The labels the graph marks (fsmscope/static/graph_marks.js draws a mark as a copy over the drawing) are seen
once at 1440x900 (issue 31, item 8): an active or failed container's name, and the label of the edge
last taken, were drawn again in bold over the drawing's own, wider, so both showed, ~9 px apart."""

from __future__ import annotations

import threading

import fsm
import pytest
from browser_support import page_at
from fsmscope.server.http_server import ServerThread
from smach_support import failing_machine, run_to_failure

# The boxes of every text of the graph (the drawing's and the marks' copies) that reads `label`.
LABEL_BOXES = """(label) => [...document.querySelectorAll('#graph svg text')]
  .filter((t) => t.textContent === label)
  .map((t) => { const b = t.getBoundingClientRect(); return [b.x, b.y, b.width, b.height]; })"""


def drawn_once(page, label: str) -> list:
    """The boxes `label` is drawn at, after asserting they lie over each other (seen as one text)."""
    boxes = page.evaluate(LABEL_BOXES, label)
    assert len(boxes) >= 2, "%r has no mark: %s" % (label, boxes)  # the drawing's and its mark's copy
    for box in boxes[1:]:
        assert all(abs(a - b) < 0.75 for a, b in zip(box, boxes[0])), "%r is drawn at %s" % (label, boxes)
    return boxes


def waiting_machine(gate: threading.Event):
    """SM_ROOT: A -onward-> SUB (X waits for `gate`, then ok) -ok-> done."""
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(lambda ud: "onward", outcomes=["onward"]), {"onward": "SUB"})
        sub = fsm.StateMachine(outcomes=["ok"])
        with sub:
            fsm.StateMachine.add("X", fsm.CBState(lambda ud: gate.wait(60) and "ok", outcomes=["ok"]), {"ok": "ok"})
        fsm.StateMachine.add("SUB", sub, {"ok": "done"})
    return sm


@pytest.fixture(scope="module")
def waiting_in_sub(browser):
    """A page at 1440x900 watching the machine while X waits: SUB and SM_ROOT active, A's edge the last."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    gate = threading.Event()
    sm = waiting_machine(gate)
    srv = ServerThread().start()
    srv.hub.add_local(sm, name="waiting")
    runner = threading.Thread(target=sm.execute)
    runner.start()
    try:
        with page_at(browser, srv.url + "#m=waiting", "#badge.live", 1440, 900, scene=False) as page:
            page.wait_for_selector('#graph [id="c:/SM_ROOT/SUB"].cluster.active')
            page.wait_for_function("() => document.querySelectorAll('#graph svg.graph-marks g.m-active').length >= 3")
            yield page
    finally:
        gate.set()
        runner.join(10)
        srv.stop()


@pytest.fixture(scope="module")
def failed_in_sub(browser):
    """A page at 1440x900 showing a run whose SUB failed (BAD raised)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    sm = failing_machine()
    srv = ServerThread().start()
    srv.hub.add_local(sm, name="crash")
    run_to_failure(sm)
    try:
        with page_at(browser, srv.url + "#m=crash", "#run-state.failed", 1440, 900, scene=False) as page:
            page.wait_for_selector('#graph [id="c:/SM_ROOT/SUB"].cluster.failed')
            page.wait_for_selector("#graph svg.graph-marks g.m-cluster.m-failed")
            yield page
    finally:
        srv.stop()


def test_an_active_containers_name_is_seen_once(waiting_in_sub):
    drawn_once(waiting_in_sub, "SUB (StateMachine)")
    drawn_once(waiting_in_sub, "SM_ROOT (StateMachine)")


def test_a_failed_containers_name_is_seen_once(failed_in_sub):
    drawn_once(failed_in_sub, "SUB (StateMachine)")


def test_the_last_edges_label_is_seen_once(waiting_in_sub):
    drawn_once(waiting_in_sub, "onward")
