""""Set as initial state…" is offered for a state machine's children only: a Concurrence or an
Iterator has no initial state to choose, and a user's subclass of one is still that kind."""

from __future__ import annotations

import fsm
import pytest
from browser_support import served_page


class Arms(fsm.Concurrence):
    """A user's own Concurrence: the structure event names its type "Arms"."""


def machine_with_a_concurrence_subclass():
    """SM_ROOT: PREPARE -> ARMS (an Arms of LEFT and RIGHT) -> done."""
    arms = Arms(outcomes=["ok"], default_outcome="ok")
    with arms:
        for name in ("LEFT", "RIGHT"):
            fsm.Concurrence.add(name, fsm.CBState(lambda ud: "ok", outcomes=["ok"]))
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("PREPARE", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "ARMS"})
        fsm.StateMachine.add("ARMS", arms, {"ok": "done"})
    return sm


@pytest.fixture(scope="module")
def page(browser):
    with served_page(browser, machine_with_a_concurrence_subclass(), "arms", can_start=True) as page:
        yield page


def menu_item(page, path: str):
    page.keyboard.press("Escape")
    page.click('.tree-row[data-path="%s"] .label' % path, button="right")
    return page.locator("#menu button", has_text="Set as initial state")


def test_a_child_of_a_concurrence_subclass_is_not_offered_as_initial_state(page):
    item = menu_item(page, "/SM_ROOT/ARMS/LEFT")
    assert item.is_disabled()
    assert item.get_attribute("title") == "a Concurrence has no initial state to choose"


def test_a_child_of_a_state_machine_is_offered_as_initial_state(page):
    assert menu_item(page, "/SM_ROOT/PREPARE").is_enabled()
