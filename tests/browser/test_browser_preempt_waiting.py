"""A preempt that a state never services: after a few seconds the page names the state and counts
the seconds since the preempt was requested, instead of "waiting for the outcome" forever."""

from __future__ import annotations

import re
import threading

import fsm
import pytest
from browser_support import served_page
from server_support import Stubborn
from smach_support import one_state_machine

OVERDUE = re.compile(r"^Preempt requested (\d+) s ago: /SM_ROOT/STUBBORN has not serviced it$")


@pytest.fixture(scope="module")
def preempted(browser):  # noqa: F811
    """A page that preempted a machine whose only state ignores it."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    stubborn = Stubborn()
    sm = one_state_machine("STUBBORN", stubborn)
    runner = threading.Thread(target=sm.execute)
    try:
        with served_page(browser, sm, "stubborn") as page:
            runner.start()
            page.wait_for_selector("#run-state.running")
            page.click("#preempt-btn")
            page.click("#preempt-confirm")
            page.wait_for_selector("#notice:has-text('Preempt accepted')")
            yield page
    finally:
        stubborn.release.set()
        if runner.is_alive():
            runner.join(10)


def overdue_seconds(page) -> int:
    """The seconds the notice says the preempt has waited, once it says so."""
    page.wait_for_function("re => new RegExp(re).test(document.getElementById('notice').textContent)",
                           arg=OVERDUE.pattern, timeout=10000)
    return int(OVERDUE.match(page.text_content("#notice")).group(1))


def test_a_preempt_not_serviced_after_3_s_names_the_state_that_has_not_serviced_it(preempted):
    assert overdue_seconds(preempted) >= 3


def test_the_seconds_since_the_preempt_was_requested_keep_counting(preempted):
    before = overdue_seconds(preempted)
    preempted.wait_for_function("text => document.getElementById('notice').textContent.includes(text)",
                                arg="requested %d s ago" % (before + 1))


def test_the_page_and_python_agree_on_which_states_a_preempt_waits_on(preempted):
    """fsmscope/static/status.js preemptWaitingOn() mirrors fsm/observation/status.py preempt_waiting_on()."""
    import json

    from fsm.observation.status import rebuild
    from event_support import container, ev, leaf

    sub = container("SUB", "/SM_ROOT/SUB", [leaf("A", "/SM_ROOT/SUB")])
    root = container("SM_ROOT", "/SM_ROOT", [sub, leaf("B", "/SM_ROOT")])
    events = [ev(1, "structure", root=root),
              ev(2, "start", initial=["SUB"], active=["SUB"], userdata={}),
              ev(3, "start", path="/SM_ROOT/SUB", initial=["A"], active=["A"], userdata={}),
              ev(4, "preempt", phase="requested"),
              ev(5, "preempt", path="/SM_ROOT/SUB", phase="requested")]
    got = preempted.evaluate("""async (events) => {
        const { Status } = await import('/status.js');
        const s = new Status('m');
        for (const e of events) s.apply(e);
        return s.preemptWaitingOn();
    }""", json.loads(json.dumps(events)))
    want = rebuild(events)["m"].preempt_waiting_on()
    assert got == want == ["/SM_ROOT/SUB/A"]
