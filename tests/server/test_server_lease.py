"""The operator lease and the deadman against a real uvicorn (docs/debugging.md, "One operator at a time")."""

import contextlib
import threading

import httpx
import pytest
from fsmscope.server.http_server import ServerThread
from fsmscope.server.lease import Deadman
from fsmscope.server.testing.polling import wait_for

from server_support import client, control_events
from server_support import looping_machine

DEADMAN_AFTER = 1.5
PATIENT_DEADMAN = 120.0


def page(srv, page_id):
    """An operator's page: the token and its page id on every request."""
    http = client(srv)
    http.headers["X-Fsmscope-Page"] = page_id
    return http


@contextlib.contextmanager
def serving(deadman_after: float):
    """The looping machine served as 'loop' (running) by a server whose deadman pauses after ``deadman_after`` s."""
    srv = ServerThread(deadman=Deadman(deadman_after, "pause")).start()
    sm, stop = looping_machine()
    srv.hub.add_local(sm, name="loop")
    runner = threading.Thread(target=sm.execute, daemon=True)
    runner.start()
    try:
        yield srv, stop
    finally:
        stop.set()
        http = client(srv)
        http.delete("/api/machines/loop/lease", headers={"X-Fsmscope-Page": "one"})
        http.post("/api/machines/loop/resume")
        runner.join(5)
        srv.stop()


@pytest.fixture
def served():
    """For the lease's own rules: a deadman far longer than any test, so a slow moment between two
    requests never frees the lease a test is checking."""
    with serving(PATIENT_DEADMAN) as served:
        yield served


@pytest.fixture
def quick_deadman():
    """For the deadman's rules: it pauses after DEADMAN_AFTER s."""
    with serving(DEADMAN_AFTER) as served:
        yield served


def controls(srv, action=None):
    return control_events(client(srv), "loop", action)


def test_a_pages_first_control_takes_the_free_lease(served):
    srv, _ = served
    one = page(srv, "one")
    assert one.post("/api/machines/loop/pause").status_code == 202
    lease = one.get("/api/machines/loop/lease").json()
    assert (lease["holder"]["page"], lease["yours"]) == ("one", True)
    [taken] = controls(srv, "lease")
    assert taken["params"] == {"page": "one", "how": "first control"}


def test_another_page_is_refused_while_one_holds_the_lease(served):
    srv, _ = served
    page(srv, "one").post("/api/machines/loop/pause")
    answer = page(srv, "two").post("/api/machines/loop/resume")
    assert answer.status_code == 409
    assert "127.0.0.1 (operator, page one) controls machine 'loop' since" in answer.json()["detail"]


@pytest.mark.parametrize("method, path, action", [("POST", "/api/machines/loop/resume", "resume"),
                                                   ("POST", "/api/machines/loop/lease", "lease")])
def test_a_control_refused_for_the_lease_another_page_holds_is_in_the_audit(served, method, path, action):
    srv, _ = served
    page(srv, "one").post("/api/machines/loop/pause")
    answer = page(srv, "two").request(method, path, json={})
    assert answer.status_code == 409
    [refused] = [e for e in controls(srv) if e["result"] != "accepted"]
    assert (refused["action"], refused["client"], refused["result"]) == (
        action, "127.0.0.1 (operator, page two)", answer.json()["detail"])


def test_a_script_without_a_page_is_refused_while_a_page_holds_the_lease(served):
    srv, _ = served
    page(srv, "one").post("/api/machines/loop/pause")
    assert client(srv).post("/api/machines/loop/resume").status_code == 409


def test_preempt_needs_no_lease(served):
    srv, stop = served
    page(srv, "one").post("/api/machines/loop/lease")
    assert page(srv, "two").post("/api/machines/loop/preempt", json={"reason": "stop"}).status_code == 202


def test_taking_over_is_explicit_and_recorded(served):
    srv, _ = served
    one, two = page(srv, "one"), page(srv, "two")
    one.post("/api/machines/loop/lease")
    assert two.post("/api/machines/loop/lease").status_code == 409
    assert two.post("/api/machines/loop/lease", json={"takeover": True}).json()["yours"] is True
    over = controls(srv, "lease")[-1]
    assert over["params"]["how"] == "taken over" and over["params"]["from"] == "127.0.0.1 (operator, page one)"
    lost = one.post("/api/machines/loop/lease/beat")
    assert lost.status_code == 409 and "page two" in lost.json()["detail"]


def test_released_lease_lets_another_page_control(served):
    srv, _ = served
    one = page(srv, "one")
    one.post("/api/machines/loop/pause")
    assert one.delete("/api/machines/loop/lease").status_code == 200
    assert controls(srv, "lease")[-1]["params"]["how"] == "released"
    assert page(srv, "two").post("/api/machines/loop/resume").status_code == 202


def test_a_viewer_cannot_take_the_lease(served):
    srv, _ = served
    viewer = httpx.Client(base_url=srv.base_url, timeout=10,
                          headers={"Authorization": "Bearer " + srv.viewer_token, "X-Fsmscope-Page": "v"})
    assert viewer.post("/api/machines/loop/lease").status_code == 403


def test_a_malformed_page_id_is_refused_with_a_message(served):
    srv, _ = served
    answer = page(srv, "no spaces <b>").post("/api/machines/loop/lease")
    assert answer.status_code == 422 and "X-Fsmscope-Page" in answer.json()["detail"]


def test_a_silent_holder_pauses_the_machine_within_the_deadman_time(quick_deadman):
    srv, _ = quick_deadman
    page(srv, "one").post("/api/machines/loop/lease")
    wait_for(lambda: controls(srv, "deadman"), timeout=DEADMAN_AFTER + 3)
    [deadman] = controls(srv, "deadman")
    assert deadman["params"] == {"page": "one", "after": DEADMAN_AFTER, "then": "pause"}
    assert controls(srv, "pause")[-1]["client"] == "deadman"
    wait_for(lambda: client(srv).get("/api/machines/loop/status").json()["debug"]["holds"])
    assert client(srv).get("/api/machines/loop/lease").json()["holder"] is None


def test_a_beating_holder_keeps_the_lease(quick_deadman):
    srv, _ = quick_deadman
    one = page(srv, "one")
    one.post("/api/machines/loop/lease")
    for _ in range(6):
        threading.Event().wait(DEADMAN_AFTER / 3)
        assert one.post("/api/machines/loop/lease/beat").status_code == 200
    assert controls(srv, "deadman") == []


def test_a_deadman_action_outside_pause_preempt_none_is_refused():
    with pytest.raises(ValueError, match="pause, preempt, none"):
        Deadman(3, "explode")
