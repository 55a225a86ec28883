"""The debugger in the page (docs/debugging.md): breakpoints from the state menu and their dialog,
their marks on the graph and the tree, the banner saying where and why the machine holds, and
Pause, Resume, Step, Step over and Force outcome; hidden from a viewer, disabled when looking back.
A small local machine for the page's parts (the issue's scenario on the demo is in
test_browser_debugger_demo.py)."""

from __future__ import annotations

import json
import re
import threading
import time

import fsm
import pytest
from browser_support import as_page, banner_saying, served_page
from fsmscope.server.testing.browser import open_page
from fsmscope.server.testing.polling import wait_for
from server_support import client

BREAKPOINTS = "/api/machines/rounds/breakpoints"


def rounds_machine() -> tuple[fsm.StateMachine, threading.Event]:
    """SM_ROOT: SUB (A -> B) -> C, and C -again-> SUB until ``stop`` is set (then 'stop' -> done); C
    counts the rounds in userdata ``n``."""
    stop = threading.Event()

    def leaf(ud):
        time.sleep(0.02)
        return "go"

    def count(ud):
        time.sleep(0.02)
        ud.n += 1
        return "stop" if stop.is_set() else "again"

    sub = fsm.StateMachine(outcomes=["done"])
    with sub:
        fsm.StateMachine.add("A", fsm.CBState(leaf, outcomes=["go"]), {"go": "B"})
        fsm.StateMachine.add("B", fsm.CBState(leaf, outcomes=["go"]), {"go": "done"})
    sm = fsm.StateMachine(outcomes=["done"])
    sm.userdata.n = 0
    with sm:
        fsm.StateMachine.add("SUB", sub, {"done": "C"})
        fsm.StateMachine.add("C", fsm.CBState(count, outcomes=["again", "stop"], input_keys=["n"], output_keys=["n"]),
                             {"again": "SUB", "stop": "done"})
    return sm, stop


@pytest.fixture(scope="module")
def served(browser):
    """A page watching the rounds machine, run by its server (``can_start``); ``page.http`` is an
    operator's client, as that page."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    sm, stop = rounds_machine()
    with served_page(browser, sm, "rounds", can_start=True) as page:
        page.http = as_page(client(page.server), page)
        try:
            yield page
        finally:
            stop.set()
            let_go(page)
            wait_for(lambda: not page.http.get("/api/machines/rounds/status").json()["running"])


def let_go(page) -> None:
    """No breakpoint, no hold: the machine runs free."""
    page.http.put(BREAKPOINTS, json={"breakpoints": []})
    page.http.post("/api/machines/rounds/resume")


@pytest.fixture
def rounds(served):
    """The page, its machine running free, no menu or dialog open; let go again afterwards."""
    let_go(served)
    if not served.http.get("/api/machines/rounds/status").json()["running"]:
        assert served.http.post("/api/machines/rounds/start").status_code == 202
    served.wait_for_selector("#run-state.running")
    served.wait_for_selector("#debug-bar", state="hidden")
    yield served
    served.unroute_all()
    served.keyboard.press("Escape")
    served.evaluate("() => document.querySelectorAll('dialog[open]').forEach((d) => d.close())")
    let_go(served)


def set_breakpoints(page, *breakpoints: dict) -> None:
    """Set the machine's breakpoints over REST (quicker to arrange than through the menu)."""
    assert page.http.put(BREAKPOINTS, json={"breakpoints": list(breakpoints)}).status_code == 200


def breakpoints_set(page) -> list[dict]:
    """The machine's breakpoints as the server has them."""
    return page.http.get(BREAKPOINTS).json()["breakpoints"]


def menu_of(page, path: str):
    """Right-click the state at ``path`` in the hierarchy: its menu's items."""
    page.keyboard.press("Escape")
    page.click('.tree-row[data-path="%s"] .label' % path, button="right")
    return page.locator("#menu button")


# The badge of class `badge` drawn at the node of element id `id`: whether it is displayed and its
# centre lies at the node's drawn box (null: no such badge).
BADGE_AT = """([id, badge]) => {
    const node = document.getElementById(id).getBoundingClientRect();
    for (const el of document.querySelectorAll('#graph svg.graph-marks .' + badge)) {
        if (getComputedStyle(el).display === 'none') continue;
        const b = el.getBoundingClientRect();
        const [x, y] = [b.x + b.width / 2, b.y + b.height / 2];
        if (x >= node.left - 2 && x <= node.right + 2 && y >= node.top - 2 && y <= node.bottom + 2) return true;
    }
    return false;
}"""


def test_the_state_menu_offers_break_before_after_and_when_and_remove_once_one_is_set(rounds):
    labels = menu_of(rounds, "/SM_ROOT/C").all_text_contents()
    assert {"Break before", "Break after", "Break when…"} <= set(labels)
    assert not [label for label in labels if label.startswith("Remove")]
    rounds.locator("#menu button", has_text="Break after").click()
    rounds.wait_for_selector('.tree-row[data-path="/SM_ROOT/C"].breakpoint')
    assert breakpoints_set(rounds) == [{"state": "/SM_ROOT/C", "at": "after", "outcome": None, "when": None}]
    remove = menu_of(rounds, "/SM_ROOT/C").filter(has_text="Remove breakpoint")
    assert remove.get_attribute("title") == "after /SM_ROOT/C"
    remove.click()
    rounds.wait_for_selector('.tree-row[data-path="/SM_ROOT/C"]:not(.breakpoint)')
    assert breakpoints_set(rounds) == []


def test_the_root_cannot_take_a_breakpoint_and_its_menu_says_why(rounds):
    item = menu_of(rounds, "/SM_ROOT").filter(has_text="Break before")
    assert item.is_disabled()
    assert item.get_attribute("title") == "the root is in no container that could hold it"


def test_a_breakpoint_is_marked_on_its_node_in_the_graph_and_in_the_tree(rounds):
    set_breakpoints(rounds, {"state": "/SM_ROOT/C", "at": "before", "when": "n < 0"})  # never holds
    rounds.wait_for_selector('.tree-row[data-path="/SM_ROOT/C"].breakpoint')
    wait_for(lambda: rounds.evaluate(BADGE_AT, ["s:/SM_ROOT/C", "bp-badge"]), what="a breakpoint badge on C")
    assert not rounds.evaluate(BADGE_AT, ["s:/SM_ROOT/C", "held-badge"])
    assert rounds.locator(".tree-row.breakpoint").count() == 1


def test_where_the_machine_holds_is_marked_apart_from_its_breakpoint(rounds):
    set_breakpoints(rounds, {"state": "/SM_ROOT/C", "at": "before"})
    rounds.wait_for_selector('.tree-row[data-path="/SM_ROOT/C"].held.breakpoint')
    wait_for(lambda: rounds.evaluate(BADGE_AT, ["s:/SM_ROOT/C", "held-badge"]), what="a held badge on C")
    assert rounds.evaluate(BADGE_AT, ["s:/SM_ROOT/C", "bp-badge"])
    assert rounds.locator(".tree-row.held").count() == 1


def test_the_banner_says_where_and_why_the_machine_holds_in_the_transcripts_words(rounds):
    set_breakpoints(rounds, {"state": "/SM_ROOT/C", "at": "before", "when": "n >= 1"})
    assert banner_saying(rounds) == "Paused in /SM_ROOT: Holding before 'C': hit breakpoint before C when n >= 1"
    n_now = "window.fsmscope.status.containers['/SM_ROOT'].userdata.n"
    held_at = rounds.evaluate(n_now)
    rounds.click("#resume-btn")  # C runs once more, and the breakpoint holds before it again
    rounds.wait_for_function("n => %s === n" % n_now, arg=held_at + 1)
    assert banner_saying(rounds).endswith("hit breakpoint before C when n >= 1")


def test_a_hold_after_a_state_shows_in_the_userdata_panel_what_its_condition_saw(rounds):
    rounds.click("#pause-btn")
    banner_saying(rounds, "Paused in")
    n = rounds.http.get("/api/machines/rounds/status").json()["containers"]["/SM_ROOT"]["userdata"]["n"]
    target = n + 3  # C adds one a round: the first C to reach it writes exactly it
    set_breakpoints(rounds, {"state": "/SM_ROOT/C", "at": "after", "when": "n >= %d" % target})
    rounds.click("#resume-btn")
    banner_saying(rounds, "hit breakpoint after C")
    rounds.click('.tree-row[data-path="/SM_ROOT/C"] .label')  # its container's userdata
    assert rounds.input_value("#ud-container") == "/SM_ROOT"
    row = '#userdata tr.ud-row[data-key="n"]'
    assert rounds.text_content(row + " .ud-line > span:first-child") == str(target)
    assert rounds.text_content(row + " .ud-change") == "was %d" % (target - 1)


def test_a_condition_with_markup_is_shown_as_text(rounds):
    markup = "'<img src=x onerror=alert(1)>' != ''"
    set_breakpoints(rounds, {"state": "/SM_ROOT/C", "at": "before", "when": markup})
    assert banner_saying(rounds).endswith("when " + markup)
    assert rounds.locator("#debug-bar img").count() == 0


def test_pause_holds_the_machine_and_resume_lets_it_run_on(rounds):
    rounds.click("#pause-btn")
    assert re.search(r": paused by 127\.0\.0\.1 \(operator, page [0-9a-f]+\)$", banner_saying(rounds, "Paused in"))
    assert rounds.is_disabled("#pause-btn")
    rounds.click("#resume-btn")
    rounds.wait_for_selector("#debug-bar", state="hidden")
    assert rounds.http.get("/api/machines/rounds/status").json()["debug"]["mode"] == "run"


def test_break_when_shows_the_servers_refusal_with_its_column_and_stays_open_to_be_corrected(rounds):
    menu_of(rounds, "/SM_ROOT/C").filter(has_text="Break when…").click()
    dialog = rounds.locator("#break-dialog")
    dialog.locator("input[name=when]").fill("__import__('os').system('true')")
    dialog.locator("input[name=when]").press("Enter")
    error = dialog.locator(".dlg-error")
    error.filter(has_text="column 1").wait_for()
    assert "a call other than len(...) is not allowed (column 1)" in error.text_content()
    assert dialog.evaluate("d => d.open")
    assert breakpoints_set(rounds) == []
    dialog.locator("input[value=after]").check()
    dialog.locator("select[name=outcome]").select_option("again")
    dialog.locator("input[name=when]").fill("n >= 1000")
    dialog.locator("button[value=send]").click()
    rounds.wait_for_selector("#break-dialog", state="hidden")
    assert breakpoints_set(rounds) == [{"state": "/SM_ROOT/C", "at": "after", "outcome": "again", "when": "n >= 1000"}]


def test_step_holds_at_the_next_transition_anywhere(rounds):
    set_breakpoints(rounds, {"state": "/SM_ROOT/SUB", "at": "before"})
    assert banner_saying(rounds).startswith("Paused in /SM_ROOT: Holding before 'SUB'")
    rounds.click("#step-btn")
    assert banner_saying(rounds, "Holding after 'A'") == "Paused in /SM_ROOT/SUB: Holding after 'A':'go': stepped"


def test_step_over_runs_the_held_states_container_on_to_its_next_transition(rounds):
    set_breakpoints(rounds, {"state": "/SM_ROOT/SUB", "at": "before"})
    assert banner_saying(rounds).startswith("Paused in /SM_ROOT: Holding before 'SUB'")
    rounds.click("#step-over-btn")
    assert banner_saying(rounds, "Holding after 'SUB'") == "Paused in /SM_ROOT: Holding after 'SUB':'done': stepped"


def test_force_outcome_lists_the_held_states_outcomes_and_the_machine_takes_the_one_chosen(rounds):
    set_breakpoints(rounds, {"state": "/SM_ROOT/C", "at": "before"})
    banner_saying(rounds)
    rounds.click("#force-btn")
    items = rounds.locator("#menu button")
    assert items.all_text_contents() == ["C → again", "C → stop"]
    items.filter(has_text="C → stop").click()
    # A held machine is paused: C, not run, takes 'stop' and the machine holds before taking it.
    banner_saying(rounds, "Holding after 'C':'stop': paused")
    rounds.click("#resume-btn")
    rounds.wait_for_selector("#run-state.done")
    assert rounds.text_content("#run-state") == "finished: done"


def test_a_refusal_of_the_server_is_said_in_the_notice(rounds):
    lease = json.dumps({"detail": "another page holds the operator lease"})
    rounds.route("**/api/machines/rounds/pause", lambda route: route.fulfill(status=409, body=lease,
                                                                               content_type="application/json"))
    rounds.click("#pause-btn")
    rounds.wait_for_selector("#notice.error:has-text('Pause failed')")
    assert rounds.text_content("#notice") == "Pause failed: another page holds the operator lease"


def test_a_viewers_page_shows_the_hold_and_no_debugger_control(rounds, browser):
    set_breakpoints(rounds, {"state": "/SM_ROOT/C", "at": "before"})
    page = open_page(browser, rounds.server.viewer_url + "#m=rounds", timeout_ms=8000)
    try:
        assert banner_saying(page).startswith("Paused in /SM_ROOT: Holding before 'C'")
        page.wait_for_function("() => document.getElementById('resume-btn').hidden")
        for button in ("#pause-btn", "#resume-btn", "#step-btn", "#step-over-btn", "#force-btn"):
            assert page.is_hidden(button)
        item = menu_of(page, "/SM_ROOT/C").filter(has_text="Break before")
        assert item.is_disabled()
        assert "viewer's token" in item.get_attribute("title")
        assert not page.errors
    finally:
        page.close()


def test_looking_back_at_a_hold_shows_it_with_the_controls_disabled(rounds, browser):
    set_breakpoints(rounds, {"state": "/SM_ROOT/C", "at": "before"})

    def hold_seq() -> int | None:
        holds = rounds.http.get("/api/machines/rounds/status").json()["debug"]["holds"]
        return holds[0]["seq"] if holds else None

    first = wait_for(hold_seq)
    rounds.http.post("/api/machines/rounds/resume")
    wait_for(lambda: (hold_seq() or first) > first)  # held again, live: only looking back disables the controls
    page = open_page(browser, rounds.server.url + "#m=rounds&seq=%d" % first, timeout_ms=8000)
    try:
        page.wait_for_selector("body.looking-back")
        assert banner_saying(page).startswith("Paused in /SM_ROOT: Holding before 'C'")
        page.wait_for_selector('.tree-row[data-path="/SM_ROOT/C"].held')
        for button in ("#resume-btn", "#step-btn", "#step-over-btn", "#force-btn"):
            assert page.is_disabled(button)
        assert menu_of(page, "/SM_ROOT/C").filter(has_text="Break before").is_disabled()
        assert not page.errors
    finally:
        page.close()
