"""The words the server and the page share (fsm/observation/vocabularies.py): the page's run state
(fsmscope/static/schema.js runState, generated beside it) says what the server's says, for every status, and
the timeline's ticks are of the kinds the page draws."""

from __future__ import annotations

import itertools

from fsm.observation import vocabularies
from node_support import map_in_schema_js, needs_node
from fsmscope.server.timeline import TimelineIndex

CASES = list(itertools.product([True, False], [None, "done"], [None, {"exc_type": "E"}], [None, True, False]))


@needs_node
def test_the_page_and_the_server_give_every_status_the_same_run_state():
    assert map_in_schema_js("c => m.runState(...c)", CASES) == [vocabularies.run_state(*case) for case in CASES]


def test_every_run_state_is_reached():
    assert {vocabularies.run_state(*case) for case in CASES} == set(vocabularies.RUN_STATES)


def test_the_timelines_ticks_are_of_the_kinds_the_page_knows():
    timeline = TimelineIndex()
    events = [
        {"seq": 1, "t": 1.0, "run": "r1", "kind": "start", "path": "/SM_ROOT", "initial": ["A"], "active": ["A"]},
        {"seq": 2, "t": 2.0, "run": "r1", "kind": "error", "path": "/SM_ROOT", "exc_type": "E", "message": "m"},
        {"seq": 3, "t": 3.0, "run": "r1", "kind": "preempt", "path": "/SM_ROOT", "phase": "requested"},
        {"seq": 4, "t": 4.0, "run": "r1", "kind": "control", "path": "/SM_ROOT", "action": "start",
         "result": "accepted"},
    ]
    for event in events:
        timeline.add(event)
    kinds = {tick["kind"] for tick in timeline.answer()["ticks"]}
    assert kinds <= set(vocabularies.TICK_KINDS) and {"run", "error"} <= kinds
