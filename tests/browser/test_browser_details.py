"""The details of the selected state (fsmscope/static/details.js) at 1440x900 (issue 31, item 10): a state whose
class has no docstring (fsm's own CBState) says so, where a literal `null` was shown."""

from __future__ import annotations

import threading

import fsm
import pytest
from browser_support import page_at
from fsmscope.server.http_server import ServerThread


class Documented(fsm.State):
    """Waits for the test to end."""

    def __init__(self, gate: threading.Event) -> None:
        super().__init__(outcomes=["done"])
        self.gate = gate

    def execute(self, ud):
        self.gate.wait(60)
        return "done"


@pytest.fixture(scope="module")
def page(browser):
    """A page at 1440x900 watching QUIET (a CBState) -> WAIT (Documented) while WAIT waits."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    gate = threading.Event()
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("QUIET", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "WAIT"})
        fsm.StateMachine.add("WAIT", Documented(gate), {"done": "done"})
    srv = ServerThread().start()
    srv.hub.add_local(sm, name="quiet")
    runner = threading.Thread(target=sm.execute)
    runner.start()
    try:
        with page_at(browser, srv.url + "#m=quiet", "#badge.live", 1440, 900, scene=False) as page:
            page.click("#details > summary")
            yield page
    finally:
        gate.set()
        runner.join(10)
        srv.stop()


def details_of(page, path: str) -> str:
    page.click('.tree-row[data-path="%s"] .label' % path)
    page.wait_for_selector('#details .details-path:text-is("%s")' % path)
    return page.text_content("#details .details-body")


def test_a_state_without_a_docstring_says_so_and_shows_no_null(page):
    text = details_of(page, "/SM_ROOT/QUIET")
    assert "null" not in text
    assert page.text_content("#details .details-no-doc") == "no docstring"


def test_a_state_with_a_docstring_shows_it(page):
    details_of(page, "/SM_ROOT/WAIT")
    assert page.text_content("#details .details-doc") == "Waits for the test to end."
    assert page.locator("#details .details-no-doc").count() == 0
