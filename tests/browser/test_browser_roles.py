"""A page opened with a viewer's token shows the machine and no control; the operator's shows them."""

from __future__ import annotations

import urllib.parse

from browser_support import served_page
from fsmscope.server.testing.browser import open_page
from server_support import two_state_machine

CONTROLS = ("#preempt-btn", "#start-btn")


def test_a_viewers_page_shows_the_machine_and_no_control(browser):
    with served_page(browser, two_state_machine(), "two", can_start=True) as operator:
        for selector in CONTROLS:
            assert operator.is_visible(selector)
        srv = operator.server
        page = open_page(browser, srv.viewer_url + "#m=" + urllib.parse.quote("two"), timeout_ms=8000)
        try:
            page.wait_for_selector("#badge.live")
            page.wait_for_function("() => document.getElementById('preempt-btn').hidden")
            for selector in CONTROLS:
                assert page.is_hidden(selector)
            assert page.is_visible("#graph svg")
            assert not page.errors
        finally:
            page.close()


def test_a_viewers_menu_says_why_it_cannot_set_an_initial_state(browser):
    with served_page(browser, two_state_machine(), "two", can_start=True) as operator:
        srv = operator.server
        page = open_page(browser, srv.viewer_url + "#m=" + urllib.parse.quote("two"), timeout_ms=8000)
        try:
            page.wait_for_function("() => document.getElementById('preempt-btn').hidden")
            page.click('.tree-row[data-path="/SM_ROOT/BAR"] .label', button="right")
            item = page.locator("#menu button", has_text="Set as initial state")
            assert item.is_disabled()
            assert "viewer's token" in item.get_attribute("title")
        finally:
            page.close()
