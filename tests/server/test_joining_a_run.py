"""Someone who opens the dashboard after a run started sees that run: its events so far come with
the first snapshot, and a preempt the machine has not serviced is named with the state it waits on."""

from __future__ import annotations

import threading
import time

import fsm

from fsmscope.server.testing.polling import wait_for
from server_support import Stubborn, client, frames, stream, waiting_machine


def test_a_client_joining_mid_run_gets_the_runs_events_so_far_with_its_snapshot(live_server):
    sm, wait = waiting_machine()
    live_server.hub.add_local(sm, name="w")
    wait.release.set()
    sm.execute()  # a first run, then a second one the client joins in the middle of
    wait.release.clear()
    wait.entered.clear()
    worker = threading.Thread(target=sm.execute)
    worker.start()
    try:
        assert wait.entered.wait(5)
        with stream(live_server, "w") as ws:
            [snap] = frames(ws, lambda got: len(got) == 1)
    finally:
        wait.release.set()
        worker.join(5)
    history = snap["history"]
    runs = {e["run"] for e in history["events"]}
    assert history["complete"] and runs == {snap["status"]["run"]}
    assert [e["kind"] for e in history["events"]][-1] == "start"
    assert history["events"][-1]["seq"] == snap["last_seq"]


def test_status_names_the_state_that_has_not_serviced_a_preempt_and_since_when(live_server):
    sm = fsm.StateMachine(outcomes=["done"])
    stubborn = Stubborn()
    with sm:
        fsm.StateMachine.add("STUBBORN", stubborn, {"done": "done"})
    live_server.hub.add_local(sm, name="s")
    worker = threading.Thread(target=sm.execute)
    worker.start()
    http = client(live_server)
    try:
        assert stubborn.entered.wait(5)
        asked = time.time()
        assert http.post("/api/machines/s/preempt", json={"reason": "test"}).status_code == 202
        wait_for(lambda: http.get("/api/machines/s/status").json()["preempt"] is not None)
        status = http.get("/api/machines/s/status").json()
    finally:
        stubborn.release.set()
        worker.join(5)
    assert status["preempt_waiting_on"] == ["/SM_ROOT/STUBBORN"]
    assert abs(status["preempt"]["t"] - asked) < 2 and status["preempt"]["path"] == "/SM_ROOT"
    wait_for(lambda: http.get("/api/machines/s/status").json()["preempt"] is None)
