"""fsmscope/static/shown.js's view(): what the graph shows (active states, running containers, outcomes
reached, last edges, failed paths) from the events of a real run, called in the page as a pure
function."""

from __future__ import annotations

import json

import fsm
import pytest
from browser_support import served_page
from fsm.observation.schema import edge_id, outcome_id
from server_support import nested_machine
from smach_support import failing_machine, run_to_failure


# The view of a fresh page's store after `events` (a list of event dicts).
VIEW_AFTER = """async (events) => {
    const { Store } = await import('/store.js');
    const { view } = await import('/shown.js');
    const store = new Store();
    store.open('m');
    store.apply(events);
    const shown = view(store.state.live);
    for (const list of Object.values(shown)) list.sort();
    return shown;
}"""


@pytest.fixture(scope="module")
def page(browser):
    """A page of the dashboard, there only to import its modules."""
    with served_page(browser, nested_machine(), "nested") as page:
        yield page


def events_of(sm, runs=1, execute=lambda sm: sm.execute()) -> list[dict]:
    """The events of `runs` runs of `sm`, as the stream sends them (JSON)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    events: list[dict] = []
    reporter = fsm.attach(sm, events.append, name="m")
    try:
        for _ in range(runs):
            execute(sm)
    finally:
        reporter.remove_observer(events.append)
    return json.loads(json.dumps(events))


def until(events, **fields) -> list[dict]:
    """The events up to and including the first with all of `fields`."""
    end = next(i for i, e in enumerate(events) if all(e.get(k) == v for k, v in fields.items()))
    return events[:end + 1]


def test_mid_run_the_view_shows_the_active_states_the_running_containers_and_the_edge_taken(page):
    events = until(events_of(nested_machine()), kind="transition", path="/SM_ROOT/SUB", to="B")
    assert page.evaluate(VIEW_AFTER, events) == {
        "active": ["/SM_ROOT/SUB", "/SM_ROOT/SUB/B"],
        "running": ["/SM_ROOT", "/SM_ROOT/SUB"],
        "reached": [],
        "lastEdges": [edge_id("/SM_ROOT/SUB", "A", "go")],
        "failed": [],
    }


def test_after_a_run_the_view_shows_the_outcomes_reached_and_each_containers_last_edge(page):
    shown = page.evaluate(VIEW_AFTER, events_of(nested_machine()))
    assert shown == {
        "active": [],
        "running": [],
        "reached": sorted([outcome_id("/SM_ROOT", "done"), outcome_id("/SM_ROOT/SUB", "done")]),
        "lastEdges": sorted([edge_id("/SM_ROOT", "C", "go"), edge_id("/SM_ROOT/SUB", "B", "go")]),
        "failed": [],
    }


def test_a_new_run_shows_none_of_the_previous_runs_edges_and_outcomes(page):
    two_runs = events_of(nested_machine(), runs=2)
    second_start = [i for i, e in enumerate(two_runs) if e["kind"] == "start" and e["path"] == "/SM_ROOT"][1]
    shown = page.evaluate(VIEW_AFTER, two_runs[:second_start + 1])
    assert (shown["reached"], shown["lastEdges"]) == ([], [])


def test_a_failed_run_shows_the_failing_state_and_every_container_it_brought_down(page):
    shown = page.evaluate(VIEW_AFTER, events_of(failing_machine(), execute=run_to_failure))
    assert shown["failed"] == ["/SM_ROOT", "/SM_ROOT/SUB", "/SM_ROOT/SUB/BAD"]
