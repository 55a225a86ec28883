"""One operator at a time, seen in real Chromium: the lease's pill, taking control over, the deadman
when the operator's page is killed (on the demo), and the audit of every control."""

from __future__ import annotations

import os
import threading

import httpx
import pytest
from browser_support import banner_saying, served_page, watch
from fsmscope.server.testing.browser import CHROMIUM, open_page
from fsmscope.server.testing.demo_process import DemoProcess
from fsmscope.server.testing.polling import wait_for

from server_support import looping_machine

LEASE_PILL = "#lease-state"


@pytest.fixture
def loop_page(browser):
    """A page of the looping machine, running, served alone; stopped at the end."""
    sm, stop = looping_machine()
    with served_page(browser, sm, "loop") as page:
        runner = threading.Thread(target=sm.execute, daemon=True)
        runner.start()
        try:
            yield page
        finally:
            stop.set()
            cleanup = httpx.Client(base_url=page.server.base_url, headers={
                "Authorization": "Bearer " + page.server.token, "X-Fsmscope-Page": "cleanup"})
            cleanup.post("/api/machines/loop/lease", json={"takeover": True})
            cleanup.post("/api/machines/loop/resume")
            runner.join(5)


def pill_text(page) -> str:
    return page.locator(LEASE_PILL).text_content()


def test_taking_control_shows_you_control(loop_page):
    loop_page.wait_for_selector(LEASE_PILL + ":not([hidden])")
    assert pill_text(loop_page) == "nobody controls"
    loop_page.click("#lease-take")
    wait_for(lambda: pill_text(loop_page) == "you control")
    assert loop_page.is_visible("#lease-release")


def test_a_second_page_sees_who_controls_and_can_take_control_over(loop_page, browser):
    loop_page.wait_for_selector(LEASE_PILL + ":not([hidden])")
    loop_page.click("#lease-take")
    wait_for(lambda: pill_text(loop_page) == "you control")
    second = watch(browser, loop_page.server, "loop")
    try:
        wait_for(lambda: pill_text(second).startswith("controlled by page "))
        second.once("dialog", lambda dialog: dialog.accept())
        second.click("#lease-take")
        wait_for(lambda: pill_text(second) == "you control")
        wait_for(lambda: "You no longer control loop" in loop_page.locator("#notice").text_content())
        wait_for(lambda: pill_text(loop_page).startswith("controlled by"))
        assert not second.errors
    finally:
        second.close()


def test_the_banner_says_the_deadman_paused_the_machine_and_why(loop_page, browser):
    operator = watch(browser, loop_page.server, "loop")
    operator.wait_for_selector(LEASE_PILL + ":not([hidden])")
    operator.click("#lease-take")
    wait_for(lambda: pill_text(operator) == "you control")
    operator.close()  # its heartbeat stops: after the deadman's 3 s, the machine is paused
    said = banner_saying(loop_page, "paused by deadman", timeout=10)
    assert said.endswith("paused by deadman (the page in control sent no heartbeat for 3 s)")


def test_the_audit_lists_each_control_with_who_held_control(loop_page):
    loop_page.wait_for_selector(LEASE_PILL + ":not([hidden])")
    loop_page.click("#lease-take")
    wait_for(lambda: pill_text(loop_page) == "you control")
    loop_page.click("#lease-release")
    wait_for(lambda: pill_text(loop_page) == "nobody controls")
    loop_page.click("#audit-btn")
    rows = loop_page.locator("#audit-dialog tbody tr")
    wait_for(lambda: rows.count() == 2)
    cells = [rows.nth(i).locator("td").all_text_contents() for i in range(2)]
    assert [c[3] for c in cells] == ["lease", "lease"]
    assert "released" in cells[0][4] and "page " in cells[0][2]
    assert "asked" in cells[1][4]
    loop_page.fill("#audit-dialog input[name=text]", "released")
    wait_for(lambda: rows.count() == 1)
    assert loop_page.locator("#audit-dialog .dlg-count").text_content() == "1 of 2 controls"


def test_the_audit_lists_a_control_refused_to_a_viewers_token_with_why(loop_page):
    viewer = httpx.Client(base_url=loop_page.server.base_url, timeout=10,
                          headers={"Authorization": "Bearer " + loop_page.server.viewer_token})
    refusal = viewer.post("/api/machines/loop/preempt").json()["detail"]
    loop_page.click("#audit-btn")
    loop_page.select_option("#audit-dialog select[name=result]", "refused")
    row = loop_page.locator("#audit-dialog tbody tr.refused")
    row.wait_for()
    cells = row.locator("td").all_text_contents()
    assert (cells[1], cells[3], cells[5]) == ("127.0.0.1 (viewer)", "preempt", refusal)


def debug_mode(http, name) -> str:
    """The debugger's mode of machine ``name`` ("run" when no debugger ever acted on it)."""
    debug = http.get("/api/machines/%s/status" % name).json()["debug"]
    return debug["mode"] if debug else "run"


@pytest.mark.timeout(120)
def test_killing_the_operators_page_pauses_the_demo_within_the_deadman_time(browser, tmp_path):
    if not os.path.exists(CHROMIUM):
        pytest.skip("Debian's chromium is not installed (make apt)")
    # Four beats' time (one a second): the demo, Chromium and the other tests share two cores, and a
    # beat answered late under that load must not pass for a page gone (2 s did once, in CI).
    deadman = 4.0
    demo = DemoProcess(tmp_path / "demo.jsonl", "--deadman", str(deadman))
    try:
        http = httpx.Client(base_url="http://127.0.0.1:%d" % demo.port,
                            headers={"Authorization": "Bearer " + demo.token}, timeout=10)
        name = http.get("/api/machines").json()[0]["name"]
        page = open_page(browser, demo.url, 1400, 900, scene=False)
        page.wait_for_selector(LEASE_PILL + ":not([hidden])")
        wait_for(lambda: http.get("/api/machines/%s/status" % name).json()["running"], timeout=30)
        page.click("#lease-take")
        wait_for(lambda: pill_text(page) == "you control")
        page.wait_for_timeout((deadman + 1.5) * 1000)  # beating: no deadman while the page lives
        assert debug_mode(http, name) == "run"
        page.close()
        wait_for(lambda: debug_mode(http, name) == "pause", timeout=deadman + 1.5)
        controls = http.get("/api/machines/%s/history" % name, params={"kinds": "control", "limit": 100}).json()
        assert [e["action"] for e in controls["events"]][-2:] == ["deadman", "pause"]
    finally:
        assert demo.stop() == 130
