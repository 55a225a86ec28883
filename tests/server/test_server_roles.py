"""Roles: the operator's token watches and controls, a viewer's token only watches (fsmscope/server/auth.py)."""

import time

import httpx
import pytest
from fsmscope.server.refusals import EVERY
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from server_support import client, frames, two_state_machine


def viewer(srv):
    return httpx.Client(base_url=srv.base_url, headers={"Authorization": "Bearer " + srv.viewer_token}, timeout=10)


@pytest.fixture
def served(live_server):
    live_server.hub.add_local(two_state_machine(), name="two")
    return live_server


def test_each_token_says_its_role(served):
    assert client(served).get("/api/session").json() == {"role": "operator"}
    assert viewer(served).get("/api/session").json() == {"role": "viewer"}


def test_a_viewer_reads_what_the_operator_reads(served):
    for path in ("/api/machines", "/api/machines/two/status", "/api/machines/two/structure",
                 "/api/machines/two/history", "/api/machines/two/breakpoints"):
        assert viewer(served).get(path).status_code == 200, path


@pytest.mark.parametrize("method, path, body", [
    ("POST", "/api/machines/two/preempt", {}),
    ("POST", "/api/machines/two/start", {}),
    ("POST", "/api/machines/two/initial-state", {"states": ["BAR"]}),
    ("POST", "/api/machines/two/pause", None),
    ("POST", "/api/machines/two/resume", None),
    ("POST", "/api/machines/two/step", None),
    ("POST", "/api/machines/two/force", {"state": "/SM_ROOT/FOO", "outcome": "go"}),
    ("PUT", "/api/machines/two/breakpoints", {"breakpoints": []}),
    ("POST", "/api/topics/sm_stop", "stop"),
])
def test_a_viewers_control_is_403_saying_why(served, method, path, body):
    response = viewer(served).request(method, path, json=body)
    assert response.status_code == 403
    assert "viewer's" in response.json()["detail"]


def refused_controls(srv):
    events = client(srv).get("/api/machines/two/history", params={"kinds": "control", "limit": 100}).json()["events"]
    return [(e["action"], e["client"], e["result"]) for e in events if e["result"] != "accepted"]


@pytest.mark.parametrize("method, path, body, action", [
    ("POST", "/api/machines/two/preempt", {}, "preempt"),
    ("POST", "/api/machines/two/force", {"state": "/SM_ROOT/FOO", "outcome": "go"}, "force"),
    ("PUT", "/api/machines/two/breakpoints", {"breakpoints": []}, "breakpoints"),
    ("POST", "/api/machines/two/lease", {}, "lease"),
])
def test_a_viewers_refused_control_is_in_the_machines_audit_saying_who_what_and_why(served, method, path, body,
                                                                                      action):
    response = viewer(served).request(method, path, json=body, headers={"X-Fsmscope-Page": "viewerpage1"})
    assert response.status_code == 403
    assert refused_controls(served) == [(action, "127.0.0.1 (viewer, page viewerpa)", response.json()["detail"])]


def test_a_viewer_repeating_a_refused_control_is_recorded_once_a_second_not_each_time(served):
    http = viewer(served)
    started = time.monotonic()
    for _ in range(30):
        assert http.post("/api/machines/two/preempt").status_code == 403
    seconds = time.monotonic() - started
    assert 1 <= len(refused_controls(served)) <= seconds // EVERY + 1 < 30


def test_a_viewers_control_of_a_machine_that_is_not_there_is_403_and_recorded_nowhere(served):
    assert viewer(served).post("/api/machines/nope/preempt").status_code == 403
    assert refused_controls(served) == []


def test_a_viewer_streams_the_machine(served):
    url = "ws://127.0.0.1:%d/api/machines/two/stream?token=%s" % (served.port, served.viewer_token)
    with connect(url, compression=None, open_timeout=5) as ws:
        [snapshot] = frames(ws, lambda got: len(got) == 1)
    assert snapshot["type"] == "snapshot"


def test_a_viewer_cannot_publish_machines(served):
    url = "ws://127.0.0.1:%d/api/ingest?token=%s" % (served.port, served.viewer_token)
    with pytest.raises(InvalidStatus) as info:
        connect(url, compression=None, open_timeout=5)
    assert info.value.response.status_code == 403


def test_an_unknown_token_is_still_401(served):
    response = httpx.get(served.base_url + "/api/session", headers={"Authorization": "Bearer nope"})
    assert response.status_code == 401
