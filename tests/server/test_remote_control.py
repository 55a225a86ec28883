"""A machine published from another process takes the dashboard's controls back over its ingest
connection (docs/debugging.md, "Remote machines"): the publishing script runs in a real subprocess,
the server is a real uvicorn, and every control goes through the server's REST API."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
import time

import fsm
import pytest
from fsm.control.frames import answer
from fsm.control.handle import MachineHandle
from websockets.sync.client import connect

from browser_support import ROOT
from event_support import flat_root, run_of
from fsmscope.server import remote_control
from fsmscope.server.testing.polling import wait_for
from publishing_support import Published, published  # noqa: F401 (the fixture: a publishing subprocess)
from server_support import client, sleeper


def controls(pub: Published) -> list[dict]:
    return pub.http.get("/api/machines/remote/history", params={"kinds": "control", "limit": 1000}).json()["events"]


def test_the_machine_list_says_a_published_machine_takes_controls(published):
    info = published.info()
    assert (info["source"], info["connected"], info["controllable"], info["can_start"]) == ("ingest", True, True, False)


def test_a_preempt_over_rest_is_applied_and_recorded_by_the_publishing_process(published):
    response = published.http.post("/api/machines/remote/preempt", json={"reason": "stop the arm"})
    assert response.status_code == 202
    seq = response.json()["seq"]
    page = published.http.get("/api/machines/remote/history", params={"since": seq, "until": seq}).json()
    [event] = page["events"]  # already here when the answer came: the publisher answers after its events
    assert (event["kind"], event["action"], event["reason"], event["result"]) == ("control", "preempt", "stop the arm",
                                                                                   "accepted")
    wait_for(lambda: published.status()["outcome"] == "preempted")
    wait_for(lambda: any((e["seq"], e["kind"]) == (seq, "control") for e in published.own_events()))


def test_pause_step_and_resume_drive_the_published_machine(published):
    http = published.http
    assert http.post("/api/machines/remote/pause").status_code == 202
    [hold] = wait_for(published.holds)
    assert http.post("/api/machines/remote/step").status_code == 202
    [stepped] = wait_for(lambda: [h for h in published.holds() if h["seq"] > hold["seq"]])
    assert (stepped["reason"], stepped["state"]) == ("step", "A" if hold["state"] == "B" else "B")
    assert http.post("/api/machines/remote/resume").status_code == 202
    moving = published.status()["last_seq"]
    wait_for(lambda: not published.holds() and published.status()["last_seq"] > moving + 10)


def test_breakpoints_put_over_rest_hold_the_published_machine_and_read_back(published):
    spec = {"state": "/SM_ROOT/B", "at": "after", "outcome": None, "when": "n >= 6"}
    response = published.http.put("/api/machines/remote/breakpoints", json={"breakpoints": [spec]})
    assert response.status_code == 200 and response.json()["breakpoints"] == [spec]
    assert published.http.get("/api/machines/remote/breakpoints").json()["breakpoints"] == [spec]
    [hold] = wait_for(published.holds)
    assert hold["detail"] == "hit breakpoint after B when n >= 6"


def test_forcing_a_held_state_of_the_published_machine_ends_it_with_that_outcome(published):
    http = published.http
    http.post("/api/machines/remote/pause")
    [hold] = wait_for(published.holds)
    response = http.post("/api/machines/remote/force", json={"state": "/SM_ROOT/" + hold["state"], "outcome": "stop"})
    assert response.status_code == 202
    wait_for(lambda: published.status()["outcome"] == "done")


def test_a_422_of_the_publishing_process_reaches_the_client_with_its_message(published):
    response = published.http.post("/api/machines/remote/force", json={"state": "/SM_ROOT/A", "outcome": "nope"})
    assert response.status_code == 422
    assert response.json()["detail"] == ("'nope' is not an outcome of /SM_ROOT/A "
                                         "(its outcomes: ['go', 'preempted', 'stop'])")
    refused = [e for e in controls(published) if e["action"] == "force"]
    assert refused and refused[-1]["result"] == response.json()["detail"]


def test_a_control_while_the_publisher_is_disconnected_is_409_saying_so(published):
    published.proc.kill()
    wait_for(lambda: published.info()["connected"] is False)
    assert published.info()["controllable"] is False
    response = published.http.post("/api/machines/remote/pause")
    assert response.status_code == 409
    assert response.json()["detail"] == ("the publishing process of 'remote' is not connected: its controls are "
                                         "unavailable")


def held_lease(pub: Published, after: float) -> None:
    """The operator's lease of the machine is held (as fsmscope/server/lease.py says it), and the publisher
    has it: a control sent after the lease frame is answered after the publisher read it."""
    pub.srv.hub.get("remote").controls.lease_changed(True, after, "pause")
    assert pub.http.get("/api/machines/remote/breakpoints").status_code == 200


def deadman_events(pub: Published) -> list[dict]:
    return [e for e in pub.own_events() if e["kind"] == "control" and e["action"] == "deadman"]


def test_a_publisher_cut_off_while_a_lease_is_held_pauses_its_machine_itself(published):
    held_lease(published, 0.5)
    cut = time.time()
    published.srv.stop()
    [deadman] = wait_for(lambda: deadman_events(published), timeout=5)
    assert (deadman["client"], deadman["result"]) == ("publisher", "accepted")
    assert deadman["reason"] == "the connection to the dashboard was lost for 0.5 s"
    assert deadman["t"] >= cut + 0.5
    wait_for(lambda: any(e["kind"] == "debug" and e["action"] == "hold" and e["seq"] > deadman["seq"]
                         for e in published.own_events()))


def test_a_publisher_back_before_the_deadman_delay_does_not_apply_it(published):
    from fsmscope.server.http_server import ServerThread

    held_lease(published, 1.5)
    published.srv.stop()
    again = ServerThread(port=published.srv.port, token=published.srv.token).start()
    try:
        wait_for(lambda: (published.info() or {}).get("connected"), timeout=5)
        time.sleep(2.0)
        assert deadman_events(published) == []
        assert [e for e in published.own_events() if e["kind"] == "debug"] == []
    finally:
        again.stop()


@pytest.fixture
def fake_publisher(live_server):
    """A raw ingest connection that says its machine 'm' takes controls and then answers none."""
    url = "ws://127.0.0.1:%d/api/ingest?token=%s" % (live_server.port, live_server.token)
    with connect(url, compression=None, open_timeout=5) as ws:
        ws.send(json.dumps({"type": "hello", "controllable": ["m"], "can_start": {}}))
        run = run_of(flat_root("A", "B"))
        ws.send(json.dumps(run))
        wait_for(lambda: client(live_server).get("/api/machines").json())
        yield ws


def test_a_publisher_that_does_not_answer_is_504_saying_so(live_server, fake_publisher, monkeypatch):
    monkeypatch.setattr(remote_control, "ANSWER_TIMEOUT", 0.3)
    response = client(live_server).post("/api/machines/m/pause")
    assert response.status_code == 504
    assert response.json()["detail"] == "the publishing process of 'm' did not answer within 0.3 s"
    assert json.loads(fake_publisher.recv(timeout=5))["action"] == "pause"


def test_a_malformed_answer_closes_the_publisher_with_1007(fake_publisher):
    fake_publisher.send(json.dumps({"type": "answer", "id": "one", "status": 202}))
    with pytest.raises(Exception):
        fake_publisher.recv(timeout=5)
    assert (fake_publisher.close_code, fake_publisher.close_reason) == (1007, "answer.id must be an integer")


def test_a_hello_whose_machines_are_not_names_closes_the_publisher_with_1007(fake_publisher):
    fake_publisher.send(json.dumps({"type": "hello", "controllable": "m", "can_start": {}}))
    with pytest.raises(Exception):
        fake_publisher.recv(timeout=5)
    assert (fake_publisher.close_code, fake_publisher.close_reason) == (
        1007, "hello.controllable must be a list of machine names")


def test_a_control_frame_with_params_of_the_wrong_type_is_answered_422_and_one_without_id_ignored():
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", sleeper(outcome="done"), {"done": "done"})
    reporter = fsm.attach(sm, name="m")
    handles = {"m": MachineHandle(sm, reporter, can_start=False)}
    frame = {"id": 7, "machine": "m", "action": "force", "params": ["not", "an", "object"], "client": "me"}
    assert answer(handles, frame) == ("m", {"type": "answer", "id": 7, "status": 422,
                                            "detail": "params must be an object"})
    assert answer(handles, dict(frame, id="7")) is None


def test_a_publishing_script_needs_no_web_framework():
    loaded = subprocess.run([sys.executable, "-c", "import sys, fsmscope.server.publisher; print(' '.join(sys.modules))"],
                            cwd=ROOT, capture_output=True, text=True, check=True).stdout.split()
    assert [m for m in loaded if m.split(".")[0] in ("fastapi", "starlette", "pydantic", "uvicorn")] == []


def test_a_start_waits_for_a_run_of_another_thread_to_return():
    """The page may ask for the next run as soon as the outcome is out, while the thread that ran
    the machine (the process's own, not the handle's) is still returning from execute()."""
    runs = []

    def slow(ud):
        runs.append(time.monotonic())
        time.sleep(0.3)
        return "done"

    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(slow, outcomes=["done"]), {"done": "done"})
    handle = MachineHandle(sm, fsm.attach(sm, name="m"), can_start=True)
    own = threading.Thread(target=sm.execute)
    own.start()
    wait_for(lambda: runs, 5)
    handle.start("me")  # raised Refused(409, "machine is running") before it waited
    own.join(5)
    handle.join(5)
    assert len(runs) == 2
