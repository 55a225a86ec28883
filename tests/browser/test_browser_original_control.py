"""The page controls a machine of the original smach as it controls one of fsm: its Preempt button
ends it preempted, its Pause holds it and Resume lets it go on (real Chromium, a real server)."""

from __future__ import annotations

import threading
import time

import pytest
from browser_support import watching
from fsmscope.server.testing.polling import wait_for

from original_core import loaded_original


@pytest.fixture(scope="module")
def smach():
    with loaded_original() as module:
        module.set_loggers(*[lambda msg: None] * 4)
        yield module


def working(smach, stop):
    """Returns 'done' when ``stop`` is set, 'preempted' when preempted; re-entered until then."""

    class Work(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["done", "preempted", "again"])

        def execute(self, ud):
            time.sleep(0.01)
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
            return "done" if stop.is_set() else "again"

    return Work()


def loop_machine(live_server, smach, name, stop):
    """WORK, re-entered until ``stop`` (or a preempt), served as ``name`` and running in a thread; its result."""
    sm = smach.StateMachine(outcomes=["done", "preempted"])
    with sm:
        smach.StateMachine.add("WORK", working(smach, stop), {"done": "done", "preempted": "preempted",
                                                             "again": "WORK"})
    live_server.hub.add_local(sm, name=name)
    result = {}
    threading.Thread(target=lambda: result.update(outcome=sm.execute()), daemon=True).start()
    return result


def test_the_pages_preempt_ends_an_original_machine_preempted(browser, live_server, smach):
    stop = threading.Event()
    result = loop_machine(live_server, smach, "orig", stop)
    with watching(browser, live_server, "orig", "#run-state.running") as page:
        page.click("#preempt-btn")
        page.click("#preempt-confirm")
        wait_for(lambda: result.get("outcome") == "preempted")
        page.wait_for_selector("#run-state.done")


def test_the_pages_pause_holds_an_original_machine_and_resume_lets_it_go_on(browser, live_server, smach):
    stop = threading.Event()
    result = loop_machine(live_server, smach, "orig", stop)
    try:
        with watching(browser, live_server, "orig", "#run-state.running") as page:
            page.click("#pause-btn")
            page.wait_for_selector("#debug-bar:not([hidden])")
            wait_for(lambda: "WORK" in page.locator("#debug-bar .debug-text").text_content())
            stop.set()
            page.click("#resume-btn")
            page.wait_for_selector("#debug-bar", state="hidden")
            wait_for(lambda: result.get("outcome") == "done")
    finally:
        stop.set()
