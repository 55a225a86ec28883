"""The event log: a text filter over the whole row, several kinds shown at once, a shown / total count."""

from __future__ import annotations

import threading

import fsm
import pytest
from browser_support import filter_log, served_page, watch
from fsmscope.server.http_server import ServerThread
from smach_support import WaitForPreempt, concurrence, machine


def pick_and_lift():
    """SM_ROOT: GRASP (logs, writes `grip`) -> HANDS(LEFT | RIGHT) -> LIFT -> carried."""
    def grasp(ud):
        fsm.loginfo("gripper closed on the cup")
        ud.grip = 0.8
        return "closed"

    hands = fsm.Concurrence(outcomes=["ready"], default_outcome="ready")
    with hands:
        fsm.Concurrence.add("LEFT", fsm.CBState(lambda ud: "ok", outcomes=["ok"]))
        fsm.Concurrence.add("RIGHT", fsm.CBState(lambda ud: "ok", outcomes=["ok"]))
    sm = fsm.StateMachine(outcomes=["carried"])
    with sm:
        fsm.StateMachine.add("GRASP", fsm.CBState(grasp, outcomes=["closed"], output_keys=["grip"]),
                             {"closed": "HANDS"})
        fsm.StateMachine.add("HANDS", hands, {"ready": "LIFT"})
        fsm.StateMachine.add("LIFT", fsm.CBState(lambda ud: "up", outcomes=["up"]), {"up": "carried"})
    return sm


@pytest.fixture(scope="module")
def served():
    fsm.set_loggers(*(lambda msg: None,) * 4)
    srv = ServerThread().start()
    srv.sm = pick_and_lift()
    srv.hub.add_local(srv.sm, name="pick")
    yield srv
    srv.stop()


@pytest.fixture(scope="module")
def logged(browser, served):  # noqa: F811
    """A page whose log holds one whole run of the machine."""
    page = watch(browser, served, "pick")
    served.sm.execute()
    page.wait_for_selector("#run-state:has-text('finished: carried')")
    page.wait_for_selector("#log .log-row.kind-terminate[data-select='/SM_ROOT']")
    yield page
    assert not page.errors


def rows_shown(page):
    """Each row of the log as 'kind: message'."""
    return page.eval_on_selector_all(
        "#log .log-row", "rows => rows.map(r => r.querySelector('.kind').textContent + ': ' + r.querySelector('.msg').textContent)")


def test_the_text_filter_finds_a_transition_by_the_state_it_enters(logged):
    filter_log(logged, "LIFT")
    assert "transition: State machine transitioning 'HANDS':'ready'-->'LIFT'" in rows_shown(logged)


def test_the_text_filter_finds_a_concurrence_start_by_the_states_it_starts(logged):
    filter_log(logged, "RIGHT")
    assert [row for row in rows_shown(logged) if row.startswith("start: Concurrence starting")]


def test_the_text_filter_finds_the_termination_by_its_outcome(logged):
    filter_log(logged, "carried")
    assert "terminate: State machine terminating 'LIFT':'up':'carried'" in rows_shown(logged)


def test_the_text_filter_finds_a_log_line_by_its_message(logged):
    filter_log(logged, "gripper closed")
    assert rows_shown(logged) == ["log: gripper closed on the cup"]


def test_several_kinds_can_be_hidden_at_once(logged):
    filter_log(logged)
    logged.click("#log-kinds > summary")
    logged.uncheck("#log-kinds input[value=userdata]")
    logged.uncheck("#log-kinds input[value=log]")
    logged.keyboard.press("Escape")
    kinds = {row.split(":")[0] for row in rows_shown(logged)}
    assert {"start", "transition", "terminate"} <= kinds and not kinds & {"userdata", "log"}, kinds


def test_every_kind_but_pose_is_shown_by_default(browser, served):  # noqa: F811
    page = watch(browser, served, "pick")
    unchecked = page.eval_on_selector_all("#log-kinds input[type=checkbox]",
                                          "boxes => boxes.filter(b => !b.checked).map(b => b.value)")
    assert unchecked == ["pose"]
    assert page.text_content("#log-kinds > summary") == "all kinds but pose"
    page.close()


def test_the_count_says_shown_of_total_events(logged):
    filter_log(logged)
    total = len(rows_shown(logged))
    filter_log(logged, "LIFT")
    assert logged.text_content("#log-count") == "%d / %d events" % (len(rows_shown(logged)), total)


def test_a_concurrence_that_serviced_a_preempt_shows_no_concurrent_outcomes_line(browser):  # noqa: F811
    """SMACH prints no "Concurrent Outcomes" when its children serviced a preempt; nor does the log."""
    left, right = WaitForPreempt(), WaitForPreempt()
    sm = machine(["stopped"], [("CC", concurrence(["preempted"], "preempted", [("LEFT", left), ("RIGHT", right)]),
                                {"preempted": "stopped"})])
    runner = threading.Thread(target=sm.execute)
    with served_page(browser, sm, "stop") as page:
        runner.start()
        assert left.started.wait(5) and right.started.wait(5)
        sm.request_preempt()
        runner.join(10)
        page.wait_for_selector("#run-state:has-text('finished: stopped')")
        page.wait_for_selector("#log .log-row.kind-terminate[data-select='/SM_ROOT']")
        rows = rows_shown(page)
    assert "log: Concurrence serviced preempt." in rows
    assert not [row for row in rows if "Concurrent Outcomes" in row], rows


# Whether the log shows its newest row (its bottom in view), and that row's seq.
NEWEST_IN_VIEW = """() => {
  const log = document.getElementById('log');
  const rows = log.querySelectorAll('.log-row');
  const newest = rows[rows.length - 1];
  if (!newest) return null;
  const row = newest.getBoundingClientRect(), view = log.getBoundingClientRect();
  return { seq: Number(newest.dataset.seq), inView: row.bottom <= view.bottom + 1 && row.top >= view.top - 1 };
}"""


def ticking(stop: threading.Event):
    """A -> B -> A ... every 40 ms until ``stop`` is set."""
    def tick(ud):
        stop.wait(0.04)
        return "stop" if stop.is_set() else "go"

    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(tick, outcomes=["go", "stop"]), {"go": "B", "stop": "done"})
        fsm.StateMachine.add("B", fsm.CBState(tick, outcomes=["go", "stop"]), {"go": "A", "stop": "done"})
    return sm


def assert_the_log_follows_the_newest_events(page, seconds: float = 3.0) -> None:
    """For ``seconds``, each look finds the newest row in view, and newer rows keep coming."""
    first = page.evaluate(NEWEST_IN_VIEW)["seq"]
    for _ in range(int(seconds / 0.25)):
        page.wait_for_timeout(250)
        newest = page.evaluate(NEWEST_IN_VIEW)
        assert newest["inView"], "the log stopped following at event %d" % newest["seq"]
    assert newest["seq"] > first


@pytest.fixture
def ticking_page(browser):
    """A page at 1440x900 watching `ticking` while it runs, its log holding more rows than it shows."""
    stop = threading.Event()
    sm = ticking(stop)
    with served_page(browser, sm, "ticking") as page:
        runner = threading.Thread(target=sm.execute)
        runner.start()
        try:
            page.set_viewport_size({"width": 1440, "height": 900})
            page.wait_for_function("() => document.getElementById('log').scrollHeight > 2 * document.getElementById('log').clientHeight")
            yield page
        finally:
            stop.set()
            runner.join(10)


def test_the_log_follows_live_events_while_searching_and_once_the_search_is_cleared(ticking_page):
    for search in ("'B'", "A", "transition"):
        ticking_page.fill("#log-filter", search)
        assert_the_log_follows_the_newest_events(ticking_page, 1.5)
        ticking_page.fill("#log-filter", "")
        assert_the_log_follows_the_newest_events(ticking_page)
