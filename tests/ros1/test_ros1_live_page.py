"""Robots nobody may change, on the dashboard in real Chromium: two real ROS 1 robots
(tests/robots/smach_ros_loop.py: the original SMACH with smach_ros's own IntrospectionServer) followed
by a real ``fsmscope ros1`` process. The page shows both machines live, says why its debugger is not
there, sets a robot's next initial state and preempts its run through its MonitorState, and shows a
robot killed as disconnected."""

from __future__ import annotations

import re
import signal

import pytest
from fsmscope.server.testing.polling import wait_for

from browser_support import page_at

pytestmark = pytest.mark.browser  # real Chromium, as the browser layer's tests


def active_in_work(page) -> str | None:
    return page.evaluate("""() => [...document.querySelectorAll('#graph g.node.active')].map(g => g.id)
                                   .find(id => id.startsWith('s:/SM_ROOT/RUN/WORK/')) || null""")


@pytest.mark.parametrize("name", ["r1", "r2"])
def test_the_page_follows_each_robots_machine_live(browser, live, name):
    with page_at(browser, live.url + "#m=" + name, "#badge.live", scene=False) as page:
        first = wait_for(lambda: active_in_work(page), 30, interval=0.05, what="a state of WORK shown active")
        wait_for(lambda: active_in_work(page) not in (None, first), 30, interval=0.05,
                 what="another state of WORK than %s shown active" % first)


def test_the_page_says_why_a_robots_machine_has_no_debugger(browser, live):
    with page_at(browser, live.url + "#m=r2", "#badge.live", scene=False) as page:
        page.wait_for_selector("#debug-limits:not([hidden])")
        assert "IntrospectionServer in the robot's process" in page.text_content("#debug-limits")
        assert page.is_hidden("#pause-btn")


def test_set_initial_state_and_preempt_from_the_page_start_the_robots_next_run_there(browser, live, robots):
    robot = robots["r1"]
    with page_at(browser, live.url + "#m=r1", "#run-state.running", scene=False) as page:
        page.click('.tree-row[data-path="/SM_ROOT/RUN/WORK/SCAN"] .label', button="right")
        page.click("#menu button:has-text('Set as initial state')")
        page.wait_for_selector("#initial-dialog[open]")
        page.fill("#initial-dialog textarea", '{"rounds": 0}')
        page.click("#initial-dialog button[value=send]")
        page.wait_for_selector("#notice:has-text('Initial state of /SM_ROOT/RUN/WORK set to SCAN')")
        runs = robot.output.count("outcome: ")
        page.click("#preempt-btn")
        page.click("#preempt-confirm")
        page.wait_for_selector("#notice:has-text('Preempt accepted'), #notice:has-text('Preempt failed')")
        assert "Preempt accepted" in page.text_content("#notice")
        wait_for(lambda: robot.output.count("outcome: ") > runs, 15, interval=0.1,
                 what=lambda: "the robot's run to end:\n" + robot.output[-2000:])
        assert robot.output.split("outcome: ")[runs + 1].startswith("stopped")
        wait_for(lambda: re.search(r"outcome: stopped\n(.*\n)*.*starting in initial state 'SCAN'", robot.output),
                 15, interval=0.1, what=lambda: "the next run to start at SCAN:\n" + robot.output[-2000:])


def test_a_robot_killed_shows_disconnected_on_its_page(browser, live, robots):
    with page_at(browser, live.url + "#m=r2", "#badge.live", scene=False) as page:
        robots["r2"].proc.send_signal(signal.SIGKILL)
        page.wait_for_selector("#run-state.disconnected", timeout=30000)
