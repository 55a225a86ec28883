"""The websocket stream and ingest against a real uvicorn, with the `websockets` client."""

import json
import threading
import time

import fsm
import pytest
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect

from fsm.observation import schema
from fsmscope.server import fanout
from fsmscope.server.publisher import Publisher
from fsmscope.server.testing.clients import stalled_stream
from fsmscope.server.testing.polling import wait_for
from server_support import (blob_loop, client, events_of, frames, nested_machine, stream, two_state_machine,
                            waiting_machine)


def has_terminate(got):
    return any(e["kind"] == "terminate" and e["path"] == "/SM_ROOT" for e in events_of(got))


def test_snapshot_first_then_every_event_in_order(live_server):
    sm = nested_machine()
    live_server.hub.add_local(sm, name="n")
    with stream(live_server, "n") as ws:
        [snap] = frames(ws, lambda got: len(got) == 1)
        assert snap["type"] == "snapshot" and snap["last_seq"] == 0
        assert snap["status"]["structure"]["path"] == "/SM_ROOT"
        sm.execute()
        events = events_of(frames(ws, has_terminate))
    seqs = [e["seq"] for e in events]
    assert seqs == list(range(1, len(seqs) + 1))
    assert events[0]["kind"] == "structure"


def test_since_resumes_with_the_missed_events_and_no_snapshot(live_server):
    sm = two_state_machine()
    live_server.hub.add_local(sm, name="two")
    sm.execute()
    with stream(live_server, "two", since=2) as ws:
        got = frames(ws, has_terminate)
    assert got[0]["type"] == "events"
    assert [e["seq"] for e in events_of(got)][0] == 3


def test_since_beyond_what_is_kept_gets_a_snapshot(live_server, monkeypatch):
    sm = two_state_machine()
    entry = live_server.hub.add_local(sm, name="two")
    sm.execute()
    wait_for(lambda: len(entry.feed.ring) > 3)
    for _ in range(3):
        entry.feed.ring.popleft()  # as if the ring had wrapped
    with stream(live_server, "two", since=1) as ws:
        [snap] = frames(ws, lambda got: len(got) == 1)
    assert snap["type"] == "snapshot" and snap["status"]["outcome"] == "done"


def test_stream_without_token_is_refused_401(live_server):
    live_server.hub.add_local(two_state_machine(), name="two")
    with pytest.raises(InvalidStatus) as info:
        stream(live_server, "two", token=False)
    assert info.value.response.status_code == 401


def test_stream_authenticates_with_the_token_as_a_subprotocol_and_answers_with_its_own(live_server):
    live_server.hub.add_local(two_state_machine(), name="two")
    url = "ws://127.0.0.1:%d/api/machines/two/stream" % live_server.port
    with connect(url, subprotocols=["fsmscope", "fsmscope.token." + live_server.token], open_timeout=5) as ws:
        assert ws.subprotocol == "fsmscope"
        [snap] = frames(ws, lambda got: len(got) == 1)
    assert snap["type"] == "snapshot"


def test_stream_with_a_wrong_token_subprotocol_is_refused_401(live_server):
    live_server.hub.add_local(two_state_machine(), name="two")
    url = "ws://127.0.0.1:%d/api/machines/two/stream" % live_server.port
    with pytest.raises(InvalidStatus) as info:
        connect(url, subprotocols=["fsmscope", "fsmscope.token.wrong"], open_timeout=5)
    assert info.value.response.status_code == 401


def test_stream_from_a_foreign_origin_is_refused_403(live_server):
    live_server.hub.add_local(two_state_machine(), name="two")
    with pytest.raises(InvalidStatus) as info:
        stream(live_server, "two", origin="http://evil.example")
    assert info.value.response.status_code == 403


def test_stream_of_an_unknown_machine_is_refused_404(live_server):
    with pytest.raises(InvalidStatus) as info:
        stream(live_server, "nope")
    assert info.value.response.status_code == 404


def test_a_client_that_falls_behind_gets_missed_then_a_snapshot(live_server, monkeypatch):
    monkeypatch.setattr(fanout, "CLIENT_QUEUE", 2)  # a run of two_state_machine is 4 events
    sm = two_state_machine()
    entry = live_server.hub.add_local(sm, name="two")
    with stream(live_server, "two") as ws:
        frames(ws, lambda got: len(got) == 1)
        [client] = list(entry.feed.clients)
        client.wake.set = lambda: None  # the sender sleeps through the run: its queue overflows
        sm.execute()
        wait_for(lambda: entry.feed.loop_seq == entry.local.reporter.last_seq)
        asyncio_set(live_server, client)
        got = frames(ws, lambda got: any(f["type"] == "snapshot" for f in got))
    assert got[0]["type"] == "missed" and got[0]["count"] > 2
    assert got[1]["status"]["outcome"] == "done"


def test_every_frame_the_stream_sends_fits_its_definition_in_the_schema(live_server, monkeypatch):
    monkeypatch.setattr(fanout, "CLIENT_QUEUE", 2)
    sm = two_state_machine()
    entry = live_server.hub.add_local(sm, name="two")
    sm.execute()  # a run already: a new page's snapshot carries its history
    with stream(live_server, "two") as ws:
        got = frames(ws, lambda got: len(got) == 1)
        [client] = list(entry.feed.clients)
        client.wake.set = lambda: None  # the sender sleeps through the run: its queue overflows
        sm.execute()
        wait_for(lambda: entry.feed.loop_seq == entry.local.reporter.last_seq)
        asyncio_set(live_server, client)
        got += frames(ws, lambda got: any(f["type"] == "snapshot" for f in got))
        monkeypatch.setattr(fanout, "CLIENT_QUEUE", 4000)
        sm.execute()
        got += frames(ws, has_terminate)
    assert "history" in got[0] and {f["type"] for f in got} == {"snapshot", "missed", "events"}
    assert [schema.frame_problem(f) for f in got] == [None] * len(got)


def asyncio_set(srv, client):
    del client.wake.set
    srv.hub.loop.call_soon_threadsafe(client.wake.set)


def test_a_stalled_client_is_dropped_and_the_machine_does_not_wait(live_server, monkeypatch):
    monkeypatch.setattr(fanout, "SEND_TIMEOUT", 0.5)
    monkeypatch.setattr(fanout, "CLIENT_QUEUE", 100000)
    sm = blob_loop(20000)
    entry = live_server.hub.add_local(sm, name="loop")
    raw = stalled_stream(live_server, "loop")  # never read again
    wait_for(lambda: len(entry.feed.clients) == 1)
    started = time.monotonic()
    assert sm.execute() == "done"
    assert time.monotonic() - started < 5
    wait_for(lambda: not entry.feed.clients, timeout=5)
    raw.close()


def test_publisher_in_another_thread_shows_its_machine_as_ingest(live_server):
    pub = Publisher(live_server.base_url, live_server.token)
    sm = two_state_machine()
    fsm.attach(sm, pub, name="remote")
    assert pub.connected.wait(5)
    sm.execute()
    assert pub.flush(5)
    http = client(live_server)
    wait_for(lambda: http.get("/api/machines/remote/status").status_code == 200 and
             http.get("/api/machines/remote/status").json()["outcome"] == "done")
    [info] = [m for m in http.get("/api/machines").json() if m["name"] == "remote"]
    assert info["source"] == "ingest" and info["can_start"] is False
    assert http.post("/api/machines/remote/preempt", json={}).status_code == 409
    pub.close()


def test_ingest_without_token_is_refused_401(live_server):
    with pytest.raises(InvalidStatus) as info:
        connect("ws://127.0.0.1:%d/api/ingest" % live_server.port, open_timeout=5)
    assert info.value.response.status_code == 401


def test_publisher_keeps_the_machine_running_without_a_server_and_reconnects():
    from fsmscope.server.http_server import ServerThread

    srv = ServerThread().start()
    port, token = srv.port, srv.token
    pub = Publisher(srv.base_url, token, backoff_max=0.2)
    sm, wait = waiting_machine()
    fsm.attach(sm, pub, name="away")
    assert pub.connected.wait(5)
    srv.stop()
    thread = threading.Thread(target=sm.execute, daemon=True)
    thread.start()
    assert wait.entered.wait(5)  # the machine runs while the server is gone
    srv2 = ServerThread(port=port, token=token).start()
    try:
        wait_for(lambda: srv2.hub.get("away") is not None and srv2.hub.get("away").feed.status.running, timeout=10)
        wait.release.set()
        thread.join(5)
        wait_for(lambda: srv2.hub.get("away").feed.status.outcome == "done", timeout=5)
    finally:
        wait.release.set()
        pub.close(1)
        srv2.stop()


def loop_in_background(sm):
    """Run ``sm`` in a thread; returns the thread."""
    runner = threading.Thread(target=sm.execute, daemon=True)
    runner.start()
    return runner


def ticking_loop(n, delay, halt=None):
    """A one-state loop that runs ``n`` times, sleeping ``delay`` s each time, or until ``halt`` is set.

    (A preempt would not end it: SMACH preempts the next state, and a CBState never looks.)"""
    count = {"n": 0}

    def tick(ud):
        time.sleep(delay)
        count["n"] += 1
        return "stop" if count["n"] >= n or (halt and halt.is_set()) else "again"

    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(tick, outcomes=["again", "stop"]), {"again": "A", "stop": "done"})
    return sm


def test_a_paced_client_gets_every_event_in_at_most_one_frame_per_pace(live_server):
    sm = ticking_loop(1000, 0.001)  # about 2,000 events in 1.5 s
    entry = live_server.hub.add_local(sm, name="loop")
    with stream(live_server, "loop") as ws:
        frames(ws, lambda got: len(got) == 1)
        ws.send(json.dumps({"type": "pace", "ms": 400}))
        wait_for(lambda: [c.pace for c in entry.feed.clients] == [0.4])
        started = time.monotonic()
        loop_in_background(sm)
        got = frames(ws, lambda got: any(e["kind"] == "terminate" and e["path"] == "/SM_ROOT"
                                         for e in events_of(got)), timeout=30)
        elapsed = time.monotonic() - started
    seqs = [e["seq"] for e in events_of(got)]
    assert seqs == list(range(seqs[0], seqs[0] + len(seqs)))  # nothing lost, nothing twice
    assert len(got) <= elapsed / 0.4 + 2


def test_a_pace_of_zero_ends_a_wait_for_the_old_pace_at_once(live_server):
    halt = threading.Event()
    sm = ticking_loop(100000, 0.001, halt)
    entry = live_server.hub.add_local(sm, name="loop")
    runner = None
    try:
        with stream(live_server, "loop") as ws:
            frames(ws, lambda got: len(got) == 1)
            ws.send(json.dumps({"type": "pace", "ms": 10000}))
            wait_for(lambda: [c.pace for c in entry.feed.clients] == [10.0])
            runner = loop_in_background(sm)
            with pytest.raises(TimeoutError):  # the snapshot went just now: the next frame waits 10 s
                ws.recv(timeout=0.5)
            ws.send(json.dumps({"type": "pace", "ms": 0}))
            asked = time.monotonic()
            [frame] = frames(ws, lambda got: len(got) == 1, timeout=5)
            assert time.monotonic() - asked < 2
            assert frame["type"] == "events"
    finally:
        halt.set()  # the machine's log lines must not reach the tests after this one
        if runner:
            runner.join(5)


@pytest.mark.parametrize("message", ["not json", '{"type": "hold"}', '{"type": "pace", "ms": -1}',
                                     '{"type": "pace", "ms": 1.5}', '{"type": "pace", "ms": 99999}', "[]"])
def test_a_message_other_than_a_pace_closes_the_stream_saying_why(live_server, message):
    live_server.hub.add_local(two_state_machine(), name="two")
    with stream(live_server, "two") as ws:
        frames(ws, lambda got: len(got) == 1)
        ws.send(message)
        with pytest.raises(ConnectionClosed) as info:
            while True:
                ws.recv(timeout=5)
    assert info.value.rcvd.code == 1007
    assert "pace" in info.value.rcvd.reason or "JSON" in info.value.rcvd.reason


def test_a_flood_wakes_the_event_loop_at_most_once_per_drain_interval(live_server, monkeypatch):
    drains = []
    original = fanout.Fanout._drain
    monkeypatch.setattr(fanout.Fanout, "_drain", lambda self: (drains.append(time.monotonic()), original(self)))
    sm = blob_loop(5000, size=10)
    live_server.hub.add_local(sm, name="loop")
    started = time.monotonic()
    sm.execute()
    elapsed = time.monotonic() - started
    assert len(drains) <= elapsed / fanout.DRAIN_INTERVAL + 3
