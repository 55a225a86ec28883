"""A dashboard opened after a run started, or after it ended: its event log shows that run so far
(the history of the stream's first snapshot), and says when the server no longer keeps all of it."""

from __future__ import annotations

import threading

import fsm
import pytest
from browser_support import watch
from fsmscope.server.feed import HISTORY
from fsmscope.server.http_server import ServerThread
from fsmscope.server.testing.polling import wait_for


def gated_machine(gate: threading.Event):
    """SM_ROOT: A -> WAIT (until `gate`) -> B -> done."""
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "WAIT"})
        fsm.StateMachine.add("WAIT", fsm.CBState(lambda ud: gate.wait(30) and "go", outcomes=["go"]), {"go": "B"})
        fsm.StateMachine.add("B", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "done"})
    return sm


def looping_machine(turns: int):
    """SM_ROOT: LOOP -again-> LOOP ... `turns` times, then done: one transition event per turn."""
    left = [turns]

    def turn(ud):
        left[0] -= 1
        return "again" if left[0] > 0 else "stop"

    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("LOOP", fsm.CBState(turn, outcomes=["again", "stop"]), {"again": "LOOP", "stop": "done"})
    return sm


@pytest.fixture(scope="module")
def served():
    """`started` waits in WAIT; `ended` ran to its outcome; `long` ran more events than a history holds."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    srv = ServerThread().start()
    hold, open_gate = threading.Event(), threading.Event()
    open_gate.set()
    machines = {"started": gated_machine(hold), "ended": gated_machine(open_gate),
                "long": looping_machine(HISTORY + 100)}
    for name, sm in machines.items():
        srv.hub.add_local(sm, name=name)
    runner = threading.Thread(target=machines["started"].execute)
    runner.start()
    machines["ended"].execute()
    machines["long"].execute()
    wait_for(lambda: srv.hub.get("started").feed.status_dict()["containers"]["/SM_ROOT"]["active"] == ["WAIT"])
    yield srv
    hold.set()
    runner.join(10)
    srv.stop()


def rows_shown(page):
    """Each row of the log as 'kind: message'."""
    return page.eval_on_selector_all(
        "#log .log-row", "rows => rows.map(r => r.querySelector('.kind').textContent + ': ' + r.querySelector('.msg').textContent)")


def opened(browser, served, name):  # noqa: F811
    page = watch(browser, served, name)
    page.wait_for_selector("#log .log-row")
    return page


def test_a_page_opened_during_a_run_shows_the_runs_start_and_transitions(browser, served):  # noqa: F811
    page = opened(browser, served, "started")
    rows = rows_shown(page)
    assert [row for row in rows if row.startswith("start: State machine starting in initial state 'A'")], rows
    assert "transition: State machine transitioning 'A':'go'-->'WAIT'" in rows
    assert page.is_hidden("#log-partial")
    assert not page.errors
    page.close()


def test_a_page_opened_after_a_run_ended_shows_the_whole_run(browser, served):  # noqa: F811
    page = opened(browser, served, "ended")
    rows = rows_shown(page)
    assert [row for row in rows if row.startswith("start: State machine starting in initial state 'A'")], rows
    assert "transition: State machine transitioning 'A':'go'-->'WAIT'" in rows
    assert "transition: State machine transitioning 'WAIT':'go'-->'B'" in rows
    assert "terminate: State machine terminating 'B':'go':'done'" in rows
    assert not page.errors
    page.close()


def test_the_log_says_when_earlier_events_of_the_run_are_not_kept(browser, served):  # noqa: F811
    page = opened(browser, served, "long")
    page.wait_for_selector("#log-partial:has-text('not kept')")
    assert "terminate: State machine terminating 'LOOP':'stop':'done'" in rows_shown(page)
    assert not page.errors
    page.close()
