"""A recording replayed into the dashboard (`fsmscope replay LOG --serve`), seen in Chromium."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time

import fsm
import pytest
from browser_support import ACTIVE_LEAF, ROOT
from server.testing.browser import CHROMIUM, launch_chromium, open_page
from server.testing.polling import wait_for


def record_slow_machine(path) -> None:
    """A -> B -> C, 0.4 s each, recorded for real."""
    def slow(ud):
        time.sleep(0.4)
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
    if not os.path.exists(CHROMIUM):
        pytest.skip("Debian's chromium is not installed (make apt)")
    log = tmp_path / "slow.jsonl"
    record_slow_machine(log)
    proc = subprocess.Popen([sys.executable, "-m", "server.cli", "replay", str(log), "--serve", "--speed", "1"],
                            cwd=ROOT, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        for line in proc.stderr:
            found = re.search(r"replaying \S+ at (http://\S+)", line)
            if found:
                yield found.group(1)
                break
        else:
            pytest.fail("fsmscope replay --serve printed no URL")
    finally:
        os.killpg(proc.pid, signal.SIGINT)
        proc.wait(20)


@pytest.fixture
def replay_page(replay_url):
    """The dashboard watching the replay (which starts when it connects)."""
    playwright_api = pytest.importorskip("playwright.sync_api")
    with playwright_api.sync_playwright() as pw:
        browser = launch_chromium(pw)
        page = open_page(browser, replay_url)
        yield page
        assert not page.errors
        browser.close()


@pytest.mark.timeout(60)
def test_a_replayed_run_plays_in_the_dashboard_as_a_view_only_replay(replay_page):
    seen = set()

    def b_and_c_seen() -> bool:
        seen.add(replay_page.evaluate(ACTIVE_LEAF))
        return {"s:/SM_ROOT/B", "s:/SM_ROOT/C"} <= seen

    wait_for(b_and_c_seen, 10, interval=0.05, what=lambda: "B and C active in turn; seen %r" % seen)
    assert {"s:/SM_ROOT/B", "s:/SM_ROOT/C"} <= seen, seen
    assert replay_page.text_content("#badge .badge-text").startswith("replay")
    assert replay_page.is_disabled("#preempt-btn")


@pytest.mark.timeout(60)
def test_a_replayed_machine_offers_no_initial_state_and_says_why(replay_page):
    replay_page.wait_for_selector("#badge.live")
    replay_page.click('.tree-row[data-path="/SM_ROOT/B"] .label', button="right")
    item = replay_page.locator("#menu button", has_text="Set as initial state")
    assert item.is_disabled()
    assert "replay" in item.get_attribute("title")


@pytest.mark.timeout(60)
def test_a_replayed_machine_that_finished_offers_no_start_and_no_stop_after_this_run(replay_page):
    replay_page.wait_for_selector("#run-state:has-text('finished: done')")
    replay_page.wait_for_selector("#badge.live")
    assert replay_page.is_disabled("#start-btn")
    assert replay_page.is_hidden("#hold-btn")
