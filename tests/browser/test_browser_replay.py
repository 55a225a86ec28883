"""A recording replayed into the dashboard (`fsmscope replay LOG --serve`), seen in Chromium."""

from __future__ import annotations

import time

import fsm
import pytest
from browser_support import page_at
from recording_support import replay_served


def record_abc(path) -> None:
    """A -> B -> C, 50 ms each, recorded for real."""
    def slow(ud):
        time.sleep(0.05)
        return "next"
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(slow, outcomes=["next"]), transitions={"next": "B"})
        fsm.StateMachine.add("B", fsm.CBState(slow, outcomes=["next"]), transitions={"next": "C"})
        fsm.StateMachine.add("C", fsm.CBState(slow, outcomes=["next"]), transitions={"next": "done"})
    recorder = fsm.Recorder(path)
    fsm.attach(sm, recorder, name="slow")
    sm.execute()
    recorder.close()


@pytest.fixture
def replay_url(tmp_path):
    log = tmp_path / "abc.jsonl"
    record_abc(log)
    with replay_served(log) as (url, _):
        yield url


@pytest.fixture
def replay_page(browser, replay_url):
    """The dashboard showing the replay, the whole log loaded before the URL was printed."""
    with page_at(browser, replay_url) as page:
        yield page


@pytest.mark.timeout(60)
def test_a_replayed_run_is_in_the_dashboard_whole_as_a_view_only_replay(replay_page):
    replay_page.wait_for_selector("#badge.live")
    assert replay_page.text_content("#badge .badge-text").startswith("replay")
    assert replay_page.is_disabled("#preempt-btn")
    ids = replay_page.locator("#graph g.node").evaluate_all("nodes => nodes.map(n => n.id)")
    assert {"s:/SM_ROOT/A", "s:/SM_ROOT/B", "s:/SM_ROOT/C"} <= set(ids)


@pytest.mark.timeout(60)
def test_a_replay_reloaded_after_its_end_still_has_its_whole_run(replay_page):
    replay_page.wait_for_selector("#log .log-row.kind-terminate")
    replay_page.reload()
    replay_page.wait_for_selector("#badge.live")
    replay_page.wait_for_selector("#log .log-row.kind-start")
    replay_page.wait_for_selector("#log .log-row.kind-terminate")


@pytest.mark.timeout(60)
def test_a_replayed_machine_offers_no_initial_state_and_says_why(replay_page):
    replay_page.wait_for_selector("#badge.live")
    replay_page.click('.tree-row[data-path="/SM_ROOT/B"] .label', button="right")
    item = replay_page.locator("#menu button", has_text="Set as initial state")
    assert item.is_disabled()
    assert "replay" in item.get_attribute("title")


@pytest.mark.timeout(60)
def test_a_replayed_machine_offers_no_start_and_no_stop_after_this_run(replay_page):
    replay_page.wait_for_selector("#badge.live")
    assert replay_page.is_disabled("#start-btn")
    assert replay_page.is_hidden("#hold-btn")
