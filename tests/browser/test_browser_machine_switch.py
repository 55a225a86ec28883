"""Switching machines in the picker: what the page says about one machine stays with that machine."""

from __future__ import annotations

import threading

import fsm
from browser_support import watch
from server_support import Stubborn
from smach_support import one_state_machine


def test_the_preempt_notice_of_one_machine_is_not_shown_on_another(browser, live_server):
    reach, drive = Stubborn(), Stubborn()
    machines = {"arm": one_state_machine("REACH", reach), "base": one_state_machine("DRIVE", drive)}
    for name, sm in machines.items():
        live_server.hub.add_local(sm, name=name)
    runners = [threading.Thread(target=sm.execute) for sm in machines.values()]
    for runner in runners:
        runner.start()
    try:
        page = watch(browser, live_server, "arm")
        page.wait_for_selector("#run-state.running")
        page.click("#preempt-btn")
        page.click("#preempt-confirm")
        page.wait_for_selector("#notice:has-text('Preempt accepted'):has-text('waiting for the outcome')")
        page.select_option("#machine-picker", "base")
        page.wait_for_selector('[id="s:/SM_ROOT/DRIVE"].active')
        assert page.text_content("#notice") == ""
        assert not page.errors
    finally:
        reach.release.set()
        drive.release.set()
        for runner in runners:
            runner.join(10)
