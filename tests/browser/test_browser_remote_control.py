"""The page controls a machine published from another process as it controls one of its own: the
publishing script is a real subprocess, the page real Chromium (docs/debugging.md, "Remote machines")."""

from __future__ import annotations

import pytest
from browser_support import watch
from fsmscope.server.testing.polling import wait_for

from publishing_support import published  # noqa: F401 (the fixture: a publishing subprocess)


@pytest.fixture
def page(browser, published):  # noqa: F811
    """A page showing the published machine; it must end without a script error."""
    page = watch(browser, published.srv, "remote")
    yield page
    assert not page.errors
    page.close()


def test_the_page_pauses_steps_and_resumes_a_published_machine(page, published):  # noqa: F811
    page.wait_for_selector("#pause-btn:not([disabled])")
    page.click("#pause-btn")
    page.wait_for_selector("#debug-bar:not([hidden])")
    [hold] = wait_for(published.holds)
    wait_for(lambda: f"in {hold['path']}" in page.locator("#debug-bar .debug-text").text_content())
    page.click("#step-btn")
    wait_for(lambda: [h for h in published.holds() if h["seq"] > hold["seq"]])
    page.click("#resume-btn")
    page.wait_for_selector("#debug-bar", state="hidden")
    assert published.status()["running"]
    wait_for(lambda: page.locator("#lease-state").text_content() == "you control")


def test_the_page_preempts_a_published_machine(page, published):  # noqa: F811
    page.wait_for_selector("#preempt-btn:not([disabled])")
    page.click("#preempt-btn")
    page.click("#preempt-confirm")
    wait_for(lambda: published.status()["outcome"] == "preempted")
    page.wait_for_selector("#run-state.done")


def test_the_page_says_a_published_machine_is_gone_when_its_process_is(page, published):  # noqa: F811
    page.wait_for_selector("#pause-btn:not([disabled])")
    published.proc.kill()
    page.wait_for_selector("#run-state.disconnected", timeout=10000)
    page.wait_for_selector("#pause-btn[disabled]")
