"""The dashboard in Firefox (Debian's firefox-esr over WebDriver BiDi) against a real server."""

from __future__ import annotations

import os
import threading
import time

import fsm
import pytest
from browser_support import ACTIVE_LEAF, FIREFOX, ROOT, Firefox

XSS = "<img src=x onerror=alert(1)>"

def looping_machine() -> fsm.StateMachine:
    """A -> XSS-named state -> A ..., until shut down."""
    def step(outcome):
        def cb(ud):
            time.sleep(0.15)
            return outcome
        return cb

    sm = fsm.StateMachine(outcomes=["preempted"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(step("next"), outcomes=["next"]), transitions={"next": XSS})
        fsm.StateMachine.add(XSS, fsm.CBState(step("next"), outcomes=["next"]), transitions={"next": "A"})
    return sm


@pytest.fixture(scope="module")
def served():
    if not os.path.exists(FIREFOX):
        pytest.skip("Debian's firefox-esr is not installed (make apt)")
    from fsmscope.server.introspection_server import IntrospectionServer

    sm = looping_machine()
    stop = threading.Event()

    def run():
        while not stop.is_set():
            sm.execute()
    sis = IntrospectionServer("firefox_probe", sm).start()
    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    yield sis
    stop.set()
    fsm.set_shutdown_check(lambda: True)
    thread.join(5)
    fsm.set_shutdown_check(lambda: False)
    sis.stop()


@pytest.fixture(scope="module")
def firefox(served):
    browser = Firefox()
    browser.goto(served.url)
    browser.wait_for("document.querySelector('#graph svg') !== null", timeout=30)
    yield browser
    shots = ROOT / "build" / "screenshots"
    shots.mkdir(parents=True, exist_ok=True)
    browser.screenshot(shots / "firefox-1280x800.png")
    browser.close()


@pytest.mark.timeout(90)
def test_firefox_highlights_the_active_state_as_it_changes(firefox):
    first = firefox.wait_for(ACTIVE_LEAF)
    firefox.wait_for("%s !== %r" % (ACTIVE_LEAF, first))


@pytest.mark.timeout(60)
def test_firefox_renders_state_names_as_text(firefox):
    firefox.wait_for("document.getElementById('tree').textContent.includes(%r)" % XSS)
    assert firefox.evaluate("document.querySelectorAll('img').length") == 0
