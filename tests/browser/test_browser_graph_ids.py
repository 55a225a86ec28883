"""State names the graph's ids must escape (a control character, a percent sign): the page finds
their elements through the same id definition as the server (fsmscope/static/schema.js from fsm/observation/schema/)."""

from __future__ import annotations

import threading

import fsm
import pytest
from browser_support import page_while_waiting
from fsm.observation.schema import edge_id, state_id

PERCENT = "100%"
VT = "VT\x0bBAD"


def odd_machine(gate: threading.Event):
    """SM_ROOT: 100% -go-> VT<vertical tab>BAD (waits for `gate`) -go-> done."""
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add(PERCENT, fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": VT})
        fsm.StateMachine.add(VT, fsm.CBState(lambda ud: gate.wait(30) and "go", outcomes=["go"]), {"go": "done"})
    return sm


@pytest.fixture(scope="module")
def waiting_in_vt(browser):  # noqa: F811
    """A page watching the machine while it waits in VT<vertical tab>BAD, after 100% went there."""
    with page_while_waiting(browser, odd_machine, "odd") as page:
        yield page


def has_class(page, element_id: str, cls: str) -> None:
    page.wait_for_function("([id, cls]) => document.getElementById(id)?.classList.contains(cls)",
                           arg=[element_id, cls])


def test_the_active_state_with_a_control_character_in_its_name_is_highlighted(waiting_in_vt):
    has_class(waiting_in_vt, state_id("/SM_ROOT/" + VT), "active")


def test_the_edge_taken_from_a_state_named_with_a_percent_sign_is_marked_last(waiting_in_vt):
    has_class(waiting_in_vt, edge_id("/SM_ROOT", PERCENT, "go"), "last")


def test_clicking_a_state_with_a_control_character_in_its_name_selects_it(waiting_in_vt):
    waiting_in_vt.click('[id="%s"]' % state_id("/SM_ROOT/" + VT))
    assert waiting_in_vt.get_attribute("#tree .tree-row.selected", "data-path") == "/SM_ROOT/" + VT
