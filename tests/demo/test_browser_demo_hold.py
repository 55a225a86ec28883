"""The demo's episode loop held from the page: "Stop after this run" lets the running episode finish,
then the page says the loop waits for Start; a Preempt confirmed in the pause between two episodes
holds the loop (the server accepts it) and the page says so, not that it failed."""

from __future__ import annotations

import pytest
from demo_support import watching_demo, wait_for_a_fresh_episode as fresh_episode


@pytest.fixture(scope="module")
def watched(browser, shared_demo):
    """The shared demo at real time (episodes of several seconds, a pause of 1 s between them), watched."""
    with watching_demo(browser, shared_demo) as page:
        yield page


@pytest.fixture
def demo_page(watched, demo):
    """The page, its demo running an episode, nobody in control and no notice shown (the demo let go
    afterwards); ``page.demo`` is the process."""
    watched.demo = demo
    watched.wait_for_selector("#run-state.running")
    # A page that lost the lease to the let-go says so: wait until it knows, then clear what it said.
    watched.wait_for_function("() => document.getElementById('lease-state').textContent === 'nobody controls'")
    watched.evaluate("() => window.fsmscope.clearNotice()")
    yield watched
    watched.keyboard.press("Escape")


def wait_for_a_fresh_episode(page) -> None:
    """Until an episode has just started, on the page too: seconds of it ahead, for a control to land in."""
    fresh_episode(page.demo)
    page.wait_for_selector("#run-state.running")


def confirm_the_preempt_as_the_episode_ends(page) -> None:
    """Confirm the open preempt dialog the moment the page shows the episode ended: in the page, as
    the pill changes (the pause between two episodes lasts 1 s, and the 3D view keeps the page too
    busy for a round trip per check)."""
    page.evaluate("""() => new Promise((resolve) => {
        const pill = document.getElementById("run-state");
        const confirm = () => resolve(document.getElementById("preempt-confirm").click());
        if (!pill.classList.contains("running")) return confirm();
        new MutationObserver((records, observer) => {
            if (pill.classList.contains("running")) return;
            observer.disconnect();
            confirm();
        }).observe(pill, { attributes: true, attributeFilter: ["class"] });
    })""")


@pytest.mark.timeout(150)
def test_stop_after_this_run_lets_the_episode_finish_then_the_page_says_the_loop_waits_for_start(demo_page):
    wait_for_a_fresh_episode(demo_page)
    demo_page.click("#hold-btn")
    demo_page.wait_for_selector("#loop-state:has-text('stops after this run')")
    demo_page.wait_for_selector("#run-state.done")
    assert demo_page.text_content("#run-state") != "finished: preempted"  # the episode ran to its own end
    assert demo_page.text_content("#loop-state") == "waiting for Start"
    demo_page.click("#start-btn")
    demo_page.wait_for_selector("#loop-state", state="hidden")


@pytest.mark.timeout(150)
def test_a_preempt_confirmed_between_two_episodes_says_the_loop_waits_for_start(demo_page):
    wait_for_a_fresh_episode(demo_page)
    demo_page.click("#preempt-btn")
    confirm_the_preempt_as_the_episode_ends(demo_page)
    demo_page.wait_for_selector("#notice:has-text('the loop waits for Start')")
    assert "failed" not in demo_page.text_content("#notice")
    assert demo_page.text_content("#loop-state") == "waiting for Start"
