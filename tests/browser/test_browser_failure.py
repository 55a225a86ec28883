"""A run that fails: the failing state and the containers it brought down are drawn failed, and the
machine picker says so."""

from __future__ import annotations

import threading

import fsm
import pytest
from browser_support import mark_style, watch
from fsmscope.server.http_server import ServerThread
from smach_support import failing_machine, run_to_failure

ERROR_RED = "rgb(198, 40, 40)"  # --err of fsmscope/static/style.css


def calm_machine():
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("REST", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "done"})
    return sm


@pytest.fixture(scope="module")
def served():
    """A server with the machine `crash` (not run yet) and `calm` (never run)."""
    srv = ServerThread().start()
    crash = failing_machine()
    srv.hub.add_local(crash, name="crash")
    srv.hub.add_local(calm_machine(), name="calm")
    srv.crash = crash
    yield srv
    srv.stop()


@pytest.fixture(scope="module")
def failed(browser, served):  # noqa: F811
    """A page that watched `crash` fail."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    page = watch(browser, served, "crash")
    runner = threading.Thread(target=run_to_failure, args=(served.crash,))
    runner.start()
    runner.join(10)
    page.wait_for_selector("#run-state.failed")
    yield page
    assert not page.errors


def test_the_failing_state_is_drawn_failed(failed):
    failed.wait_for_selector('[id="s:/SM_ROOT/SUB/BAD"].failed')
    assert mark_style(failed, "s:/SM_ROOT/SUB/BAD", "stroke") == ERROR_RED


def test_an_open_container_that_failed_is_drawn_failed(failed):
    failed.wait_for_selector('[id="c:/SM_ROOT/SUB"].cluster.failed')
    assert mark_style(failed, "c:/SM_ROOT/SUB", "stroke") == ERROR_RED


def test_a_closed_container_that_failed_is_drawn_failed(failed):
    failed.select_option("#depth", "1")  # only the root open: SUB is one node
    failed.wait_for_selector('[id="s:/SM_ROOT/SUB"].failed')
    assert mark_style(failed, "s:/SM_ROOT/SUB", "stroke") == ERROR_RED


def test_the_picker_says_failed_for_the_machine_shown(failed):
    failed.wait_for_selector('#machine-picker option[value="crash"]:has-text("failed")', state="attached")


def test_the_picker_says_failed_for_another_machine_whose_run_failed(browser, served, failed):  # noqa: F811
    page = watch(browser, served, "calm")
    page.wait_for_selector('#machine-picker option[value="crash"]:has-text("failed")', state="attached")
    assert "failed" not in page.text_content('#machine-picker option[value="calm"]')
    assert not page.errors
    page.close()


def test_a_traceback_in_the_event_log_keeps_its_line_breaks_as_text(failed):
    message = failed.locator(".log-row.kind-log.level-error .msg", has_text="Traceback (most recent call last):")
    shown = message.first.evaluate("el => el.innerText")  # the text as laid out: collapsed spaces are gone
    assert "Traceback (most recent call last):\n  File " in shown
    assert shown.rstrip().endswith("ValueError: boom")
    assert message.first.evaluate("el => el.children.length") == 0  # text, never markup
