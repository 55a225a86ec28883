"""The debugger in the page on the demo (docs/debugging.md), the issue's scenario: a conditional
breakpoint set from the page holds the arm still, then step, force and resume drive it. A real
``fsmscope demo`` process at real time (shared with the demo's other tests) and real Chromium; the
page's parts on a small machine are in test_browser_debugger.py."""

from __future__ import annotations

import time

import pytest
from browser_support import as_page, banner_saying
from demo_support import DEMO_MACHINE, demo_client, watching_demo

LIFT = "/SM_ROOT/TASK/PICK/LIFT"  # the arm rises with the cube: it moves the moment LIFT runs
WHEN = "attempts >= 1"
LIFT_BREAKPOINT = "hit breakpoint before TASK/PICK/LIFT when " + WHEN
STILL = 1e-3  # rad (the fingers: m): the solver's noise in a held arm, far below what LIFT moves it
BREAKPOINTS = "/api/machines/%s/breakpoints" % DEMO_MACHINE


@pytest.fixture(scope="module")
def watched(browser, shared_demo):
    """The shared demo at real time (episodes of several seconds), watched by a page; ``page.http``
    is an operator's client, as that page."""
    with watching_demo(browser, shared_demo) as page:
        page.http = as_page(demo_client(shared_demo.process()), page)
        yield page


@pytest.fixture
def page(watched):
    """The demo's page with no menu open afterwards. What the test leaves the demo doing stays for
    the next one (``held`` takes a hold before LIFT over); ``watched`` lets the demo go at the end."""
    yield watched
    watched.keyboard.press("Escape")


def held_before_lift(page) -> bool:
    """Whether the demo holds before LIFT on the breakpoint ``attempts >= 1``, and on nothing else."""
    debug = page.http.get("/api/machines/%s/status" % DEMO_MACHINE).json()["debug"] or {}
    holds = [(h["path"] + "/" + h["state"], h["at"]) for h in debug.get("holds", [])]
    breakpoints = page.http.get(BREAKPOINTS).json()["breakpoints"]
    return holds == [(LIFT, "before")] and breakpoints == [{"state": LIFT, "at": "before", "outcome": None, "when": WHEN}]


@pytest.fixture
def held(page):
    """The page, its demo held before LIFT by the breakpoint ``attempts >= 1``. A hold takes up to an
    episode to come: one the test before left (the breakpoint set from the page) is taken over as it is."""
    if not held_before_lift(page):
        page.http.put(BREAKPOINTS, json={"breakpoints": []})
        page.http.post("/api/machines/%s/resume" % DEMO_MACHINE)
        assert page.http.put(BREAKPOINTS, json={"breakpoints": [
            {"state": LIFT, "at": "before", "when": WHEN}]}).status_code == 200
    banner_saying(page, LIFT_BREAKPOINT, timeout=60)
    return page


def joints(page) -> dict[str, float]:
    """The arm's joints in the last pose the demo recorded (fsmscope/sim/pose.py: sampled at 30 Hz, sent when changed)."""
    return page.evaluate("window.fsmscope.liveStatus.pose.joints")


def moved(before: dict[str, float], after: dict[str, float]) -> float:
    """How far the furthest joint moved between two poses."""
    return max(abs(after[name] - position) for name, position in before.items())


@pytest.mark.timeout(120)
def test_on_the_demo_a_conditional_breakpoint_set_from_the_page_holds_the_arm_still_with_its_userdata_shown(page):
    page.click('.tree-row[data-path="%s"] .label' % LIFT, button="right")
    page.locator("#menu button", has_text="Break when…").click()
    page.fill("#break-dialog input[name=when]", WHEN)
    page.click("#break-dialog button[value=send]")
    page.wait_for_selector("#break-dialog", state="hidden")
    page.wait_for_selector('.tree-row[data-path="%s"].breakpoint' % LIFT)
    said = banner_saying(page, LIFT_BREAKPOINT, timeout=60)
    assert said == "Paused in /SM_ROOT/TASK/PICK: Holding before 'LIFT': " + LIFT_BREAKPOINT
    time.sleep(0.5)  # the fingers' last squeeze
    held = joints(page)
    time.sleep(2.0)  # LIFT, were it run, would be raising the arm by now
    assert moved(held, joints(page)) < STILL
    page.click('.tree-row[data-path="%s"] .label' % LIFT)  # its container's userdata
    assert page.input_value("#ud-container") == "/SM_ROOT/TASK/PICK"
    attempts = page.text_content('#userdata tr.ud-row[data-key="attempts"] td.value')
    assert int(attempts) >= 1
    assert '"held":true' in page.text_content('#userdata tr.ud-row[data-key="grasp"] td.value')


@pytest.mark.timeout(150)
def test_on_the_demo_step_force_and_resume_drive_the_held_machine(held):
    before = joints(held)
    held.click("#step-btn")  # LIFT runs, raising the arm, and the machine holds as it returns
    assert banner_saying(held, "Holding after 'LIFT'", timeout=30).endswith(": stepped")
    assert moved(before, joints(held)) > 100 * STILL
    held.click("#force-btn")
    held.locator("#menu button", has_text="LIFT → aborted").click()  # as if the cube had slipped
    pick = "window.fsmscope.liveStatus.containers['/SM_ROOT/TASK/PICK'].last"
    held.wait_for_function("() => %s.from === 'LIFT' && %s.to === 'REOPEN'" % (pick, pick))
    assert held.evaluate(pick + ".outcome") == "aborted"
    held.click('.tree-row[data-path="%s"] .label' % LIFT, button="right")
    held.locator("#menu button", has_text="Remove breakpoint").click()
    held.wait_for_selector('.tree-row[data-path="%s"]:not(.breakpoint)' % LIFT)
    run = held.evaluate("window.fsmscope.liveStatus.run")
    held.click("#resume-btn")
    held.wait_for_selector("#debug-bar", state="hidden")
    held.wait_for_function("run => window.fsmscope.liveStatus.run !== run", arg=run, timeout=60000)  # the episode ended
