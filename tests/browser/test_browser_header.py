"""The top bar at 1440 and 1920 px wide (issue 31, item 4): however crowded it gets (a long machine name,
this page holding the lease, "Stop after this run", the debugger's banner, a notice after a control),
the controls that stop a robot stay whole, in view and uncovered, and the notice stays readable."""

from __future__ import annotations

import threading

import fsm
import pytest
from browser_support import page_at
from fsmscope.server.http_server import ServerThread
from fsmscope.server.testing.polling import wait_for

from server_support import looping_machine

LONG_NAME = "pick_and_place_with_recovery_and_retries_v2"

# Each visible control of the right of the bar: whether it lies in the viewport and is what a click
# at its centre reaches (nothing of the bar covers it), and the notice's box.
HEADER_GEOMETRY = """() => {
  const box = (el) => el.getBoundingClientRect();
  const inView = (b) => b.left >= 0 && b.top >= 0 && b.right <= innerWidth && b.bottom <= innerHeight;
  const controls = ['pause-btn', 'hold-btn', 'start-btn', 'preempt-btn'].map((id) => document.getElementById(id))
    .filter((el) => !el.hidden).map((el) => {
      const b = box(el);
      const hit = document.elementFromPoint(b.x + b.width / 2, b.y + b.height / 2);
      return { id: el.id, inView: inView(b), uncovered: el.contains(hit), width: Math.round(b.width) };
    });
  const notice = document.getElementById('notice');
  const n = box(notice);
  return { controls, notice: { width: Math.round(n.width), inView: inView(n),
                               clipped: notice.scrollHeight > notice.clientHeight + 1 } };
}"""


@pytest.fixture
def crowded():
    """A server running LONG_NAME, a loop that can be held ("Stop after this run" shows); stopped at the end."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    sm, stop = looping_machine()
    srv = ServerThread().start()
    srv.hub.add_local(sm, name=LONG_NAME, holder=stop.set)
    runner = threading.Thread(target=sm.execute, daemon=True)
    runner.start()
    try:
        yield srv
    finally:
        stop.set()
        srv.hub.get(LONG_NAME).controls.resume("cleanup")
        runner.join(10)
        srv.stop()


def assert_the_bar_keeps_its_controls_and_notice(page) -> None:
    shown = page.evaluate(HEADER_GEOMETRY)
    assert [c["id"] for c in shown["controls"]] == ["pause-btn", "hold-btn", "start-btn", "preempt-btn"]
    for control in shown["controls"]:
        assert control["inView"] and control["uncovered"], shown
    assert shown["notice"]["inView"] and not shown["notice"]["clipped"], shown
    assert shown["notice"]["width"] >= 120, shown  # it had 17 px: one letter


@pytest.mark.parametrize("size", [(1440, 900), (1920, 1080)], ids=["1440", "1920"])
def test_after_controls_the_bar_keeps_preempt_in_view_and_the_notice_readable(browser, crowded, size):
    with page_at(browser, crowded.url + "#m=" + LONG_NAME, "#badge.live", *size, scene=False) as page:
        page.wait_for_selector("#hold-btn:not([hidden])")
        page.click("#lease-take")
        page.wait_for_selector("#lease-release:not([hidden])")
        page.click("#pause-btn")
        page.wait_for_selector("#debug-bar:not([hidden])")
        wait_for(lambda: "Pause accepted" in page.text_content("#notice"))
        assert_the_bar_keeps_its_controls_and_notice(page)

        page.click("#preempt-btn")
        page.click("#preempt-confirm")
        wait_for(lambda: "Preempt accepted" in page.text_content("#notice"))
        assert_the_bar_keeps_its_controls_and_notice(page)
