"""The dashboard a real ROS 1 robot serves (tests/robots/ros1_robot.py: the original SMACH with
smach_ros on rospy, fsmscope's IntrospectionServer in place of smach_ros's), in real Chromium: the
page follows its patrol live, and its Preempt stops the robot's machine."""

from __future__ import annotations

import pytest
from fsmscope.server.testing.polling import wait_for

from browser_support import page_at

pytestmark = pytest.mark.browser  # real Chromium, as the browser layer's tests

WORK = "s:/SM_ROOT/PATROL/WORK/"


@pytest.fixture(scope="module")
def robot(ros):
    robot = ros.robot("ros1_robot.py", str(ros.home / "page.jsonl"))
    yield robot
    robot.stop()


@pytest.fixture(scope="module")
def page(browser, robot):
    with page_at(browser, robot.url + "#m=robot", "#badge.live", scene=False) as page:
        yield page


def active_in_work(page) -> str | None:
    """The id of the state of WORK the graph shows active (MONITOR_STOP, beside it, is active throughout)."""
    return page.evaluate("""(work) => [...document.querySelectorAll('#graph g.node.active')].map(g => g.id)
                                          .find(id => id.startsWith(work)) || null""", WORK)


def test_the_page_follows_the_robots_patrol_live(page):
    first = wait_for(lambda: active_in_work(page), 30, interval=0.05, what="a state of WORK shown active")
    wait_for(lambda: active_in_work(page) not in (None, first), 30, interval=0.05,
             what="another state of WORK than %s shown active" % first)


def test_preempt_on_the_page_stops_the_robots_machine_preempted(page, robot):
    page.click("#preempt-btn")
    page.wait_for_selector("#preempt-dialog[open]")
    page.click("#preempt-confirm")
    page.wait_for_selector("#run-state:has-text('finished: preempted')")
    assert robot.outcome() == "preempted"
