"""A machine published from another process whose publisher went away mid-run: the page says
"disconnected" (pill and picker), not "running", since nobody can tell what it does now."""

from __future__ import annotations

import signal

import fsm
import pytest
from browser_support import watch
from fsmscope.server.http_server import ServerThread
from fsmscope.server.testing.polling import wait_for
from publishing_support import publish, remote


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    """A server with a machine of its own (`calm`) and `remote`, whose publisher was killed mid-run."""
    srv = ServerThread().start()
    calm = fsm.StateMachine(outcomes=["done"])
    with calm:
        fsm.StateMachine.add("REST", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "done"})
    srv.hub.add_local(calm, name="calm")
    srv.publisher = publish(tmp_path_factory.mktemp("publisher"), srv, 30.0)
    try:
        assert srv.publisher.stderr.readline().strip() == "started"
        wait_for(lambda: remote(srv) is not None and remote(srv)["running"], timeout=10)
        yield srv
    finally:
        if srv.publisher.poll() is None:
            srv.publisher.send_signal(signal.SIGKILL)
            srv.publisher.wait(10)
        srv.stop()


@pytest.fixture(scope="module")
def killed(browser, served):  # noqa: F811
    """A page that watched `remote` run until its publisher was killed."""
    page = watch(browser, served, "remote")
    page.wait_for_selector("#run-state.running")
    served.publisher.send_signal(signal.SIGKILL)
    served.publisher.wait(10)
    wait_for(lambda: remote(served)["connected"] is False, timeout=10)
    yield page
    assert not page.errors


def test_the_pill_says_disconnected_not_running(killed):
    killed.wait_for_selector("#run-state.disconnected:text-is('disconnected')")


def test_the_picker_says_disconnected_for_the_machine_shown(killed):
    killed.wait_for_selector('#machine-picker option[value="remote"]:has-text("disconnected")', state="attached")
    assert "running" not in killed.text_content('#machine-picker option[value="remote"]')


def test_the_picker_says_disconnected_for_another_machine(browser, served, killed):  # noqa: F811
    page = watch(browser, served, "calm")
    page.wait_for_selector('#machine-picker option[value="remote"]:has-text("disconnected")', state="attached")
    assert not page.errors
    page.close()
