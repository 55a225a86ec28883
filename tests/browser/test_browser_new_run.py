"""A new run of the machine: the page shows that run, none of the previous run's marks."""

from __future__ import annotations

import threading

import fsm
import pytest
from browser_support import watch
from fsmscope.server.http_server import ServerThread
from smach_support import two_level_machine

SUB = "/SM_ROOT/SUB"


def gated_machine(gate: threading.Event):
    """SM_ROOT: FIRST (waits for `gate`) -> SUB(A -> B, B writes SUB's `x`) -> done."""
    return two_level_machine(first=fsm.CBState(lambda ud: gate.wait(30) and "go", outcomes=["go"]))


@pytest.fixture(scope="module")
def second_run(browser):  # noqa: F811
    """A page that saw a whole first run, showing the second run waiting in FIRST (SUB has not run again)."""
    gate = threading.Event()
    sm = gated_machine(gate)
    srv = ServerThread().start()
    srv.hub.add_local(sm, name="twice")
    runner = None
    try:
        page = watch(browser, srv, "twice")
        page.select_option("#ud-container", SUB)
        gate.set()
        sm.execute()
        # The first run's marks are there: SUB's outcome, its last edge, the key B wrote.
        page.wait_for_selector('[id="o:%s:ok"].reached' % SUB)
        page.wait_for_selector('[id="e:%s:B:go"].last' % SUB)
        page.wait_for_selector('.tree-row[data-path="%s"] .outcome:has-text("ok")' % SUB)
        page.wait_for_selector('#userdata tr.changed[data-key="x"]')
        gate.clear()
        runner = threading.Thread(target=sm.execute)
        runner.start()
        page.wait_for_selector('[id="s:/SM_ROOT/FIRST"].active')
        yield page
        assert not page.errors
    finally:
        gate.set()
        if runner is not None:
            runner.join(10)
        srv.stop()


def test_a_new_run_clears_the_previous_runs_marks_on_the_graph(second_run):
    assert second_run.eval_on_selector_all("#graph .reached, #graph .last", "els => els.map(e => e.id)") == []


def test_a_new_run_clears_the_previous_runs_outcomes_in_the_hierarchy(second_run):
    assert second_run.text_content('.tree-row[data-path="%s"] .outcome' % SUB) == ""


def test_a_new_run_clears_the_previous_runs_changed_userdata_marks(second_run):
    assert second_run.get_attribute('#userdata tr[data-key="x"]', "class") == "ud-row"
