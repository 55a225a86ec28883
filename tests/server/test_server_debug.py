"""The debugger's REST controls against a real uvicorn (docs/debugging.md, docs/api.md)."""

import threading

import pytest
from fsmscope.server.testing.polling import wait_for

from server_support import client, looping_machine


@pytest.fixture
def looping(live_server):
    """The looping machine served as 'loop', running in a thread; stopped and resumed at the end."""
    sm, stop = looping_machine()
    live_server.hub.add_local(sm, name="loop")
    http = client(live_server)
    runner = threading.Thread(target=sm.execute, daemon=True)
    runner.start()
    yield http, stop
    stop.set()
    http.put("/api/machines/loop/breakpoints", json={"breakpoints": []})
    http.post("/api/machines/loop/resume")
    runner.join(5)


def holds(http):
    return http.get("/api/machines/loop/status").json()["debug"]["holds"]


def test_pause_holds_the_machine_and_resume_lets_it_finish(looping):
    http, stop = looping
    assert http.post("/api/machines/loop/pause").status_code == 202
    wait_for(lambda: holds(http))
    [hold] = holds(http)
    assert (hold["at"], hold["reason"]) == ("after", "pause")
    stop.set()
    assert http.post("/api/machines/loop/resume").status_code == 202
    wait_for(lambda: http.get("/api/machines/loop/status").json()["outcome"] == "done")


def test_step_while_running_is_409_saying_to_pause_first(looping):
    http, _ = looping
    response = http.post("/api/machines/loop/step")
    assert response.status_code == 409
    assert "pause it before stepping" in response.json()["detail"]


def test_a_conditional_breakpoint_set_over_rest_holds_the_machine(looping):
    http, _ = looping
    response = http.put("/api/machines/loop/breakpoints",
                        json={"breakpoints": [{"state": "/SM_ROOT/B", "at": "after", "when": "n >= 4"}]})
    assert response.status_code == 200
    assert response.json()["breakpoints"] == [{"state": "/SM_ROOT/B", "at": "after", "outcome": None,
                                               "when": "n >= 4"}]
    wait_for(lambda: holds(http))
    assert holds(http)[0]["detail"] == "hit breakpoint after B when n >= 4"


def test_code_in_a_condition_is_refused_with_its_column_and_the_set_is_unchanged(looping):
    http, _ = looping
    http.put("/api/machines/loop/breakpoints", json={"breakpoints": [{"state": "/SM_ROOT/A", "at": "before",
                                                                      "when": "n > 1000000000"}]})
    response = http.put("/api/machines/loop/breakpoints", json={"breakpoints": [
        {"state": "/SM_ROOT/A", "when": "__import__('os').system('touch /tmp/fsmscope-pwned')"}]})
    assert response.status_code == 422
    assert "a call other than len(...) is not allowed (column 1)" in response.json()["detail"]
    assert http.get("/api/machines/loop/breakpoints").json()["breakpoints"][0]["when"] == "n > 1000000000"


@pytest.mark.parametrize("when", [None, "", "   ", "\t\n"])
def test_a_blank_condition_is_no_condition_whatever_its_spaces(looping, when):
    http, _ = looping
    response = http.put("/api/machines/loop/breakpoints", json={"breakpoints": [{"state": "/SM_ROOT/A", "when": when}]})
    assert response.status_code == 200, response.text
    assert http.get("/api/machines/loop/breakpoints").json()["breakpoints"] == [
        {"state": "/SM_ROOT/A", "at": "before", "outcome": None, "when": None}]
    http.put("/api/machines/loop/breakpoints", json={"breakpoints": []})
    http.post("/api/machines/loop/resume")


@pytest.mark.parametrize("spec, words", [
    ({"state": "/SM_ROOT/NOPE"}, "no state at '/SM_ROOT/NOPE'"),
    ({"state": "/SM_ROOT/A", "at": "after", "outcome": "nope"}, "'nope' is not an outcome of /SM_ROOT/A"),
    ({"state": "/SM_ROOT/A", "at": "whenever"}, "at must be 'before' or 'after'"),
])
def test_a_breakpoint_that_cannot_be_set_is_422_saying_why(looping, spec, words):
    http, _ = looping
    response = http.put("/api/machines/loop/breakpoints", json={"breakpoints": [spec]})
    assert response.status_code == 422
    assert words in response.json()["detail"]


def test_forcing_a_held_transition_takes_the_forced_outcome(looping):
    http, _ = looping
    http.post("/api/machines/loop/pause")
    wait_for(lambda: holds(http))
    state = "/SM_ROOT/" + holds(http)[0]["state"]
    assert http.post("/api/machines/loop/force", json={"state": state, "outcome": "stop"}).status_code == 202
    http.post("/api/machines/loop/resume")
    wait_for(lambda: http.get("/api/machines/loop/status").json()["outcome"] == "done")


@pytest.mark.parametrize("body, status, words", [
    ({"state": "/SM_ROOT/A", "outcome": "nope"}, 422, "'nope' is not an outcome of /SM_ROOT/A"),
    ({"state": "/SM_ROOT/NOPE", "outcome": "stop"}, 422, "no state at '/SM_ROOT/NOPE'"),
])
def test_a_force_that_cannot_be_taken_is_a_4xx_saying_why(looping, body, status, words):
    http, _ = looping
    response = http.post("/api/machines/loop/force", json=body)
    assert response.status_code == status
    assert words in response.json()["detail"]


def test_forcing_a_state_that_is_not_active_is_409(live_server):
    sm, _ = looping_machine()
    live_server.hub.add_local(sm, name="idle")
    response = client(live_server).post("/api/machines/idle/force", json={"state": "/SM_ROOT/B", "outcome": "stop"})
    assert response.status_code == 409
    assert "is not active" in response.json()["detail"]


def test_every_debug_control_is_a_control_event_saying_who_and_the_result(looping):
    http, _ = looping
    http.post("/api/machines/loop/pause")
    http.post("/api/machines/loop/force", json={"state": "/SM_ROOT/A", "outcome": "nope"})
    events = http.get("/api/machines/loop/history", params={"limit": 1000, "order": "desc"}).json()["events"]
    controls = [(e["action"], e["result"]) for e in events if e["kind"] == "control"]
    assert ("pause", "accepted") in controls
    assert any(action == "force" and "is not an outcome" in result for action, result in controls)
    assert all(e["client"] == "127.0.0.1 (operator)" for e in events if e["kind"] == "control")


def test_a_hold_after_a_state_shows_the_userdata_its_condition_saw(looping):
    http, _ = looping
    http.post("/api/machines/loop/pause")
    wait_for(lambda: holds(http))
    n = http.get("/api/machines/loop/status").json()["containers"]["/SM_ROOT"]["userdata"]["n"]
    target = n + 10 - n % 2  # even: B writes the even counts, so B is where n first reaches it
    http.put("/api/machines/loop/breakpoints",
             json={"breakpoints": [{"state": "/SM_ROOT/B", "at": "after", "when": "n >= %d" % target}]})
    http.post("/api/machines/loop/resume")
    wait_for(lambda: holds(http) and holds(http)[0]["reason"] == "breakpoint")
    root = http.get("/api/machines/loop/status").json()["containers"]["/SM_ROOT"]
    assert root["userdata"]["n"] == target
    assert root["changes"] == {"n": {"old": target - 1, "new": target}}
