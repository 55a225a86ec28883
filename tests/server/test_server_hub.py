"""The hub's fan-out costs, against a real uvicorn: one encode per event, nothing per event for a stalled client."""

import asyncio
import threading
import time

import fsm
from fsm.observation import delivery
from fsm.observation.status import Status

from recording_support import two_state_loop
from fsmscope.server import fanout, feed
from fsmscope.server.testing.clients import stalled_stream
from fsmscope.server.testing.polling import wait_for
from server_support import blob_loop, events_of, frames, stream, two_state_machine


def has_terminate(got):
    return any(e["kind"] == "terminate" and e["path"] == "/SM_ROOT" for e in events_of(got))


def test_each_event_is_encoded_once_for_all_clients(live_server, monkeypatch):
    encoded = []
    real = delivery.dumps_all

    def counting(events):
        encoded.extend(event["seq"] for event in events)
        return real(events)

    monkeypatch.setattr(delivery, "dumps_all", counting)
    sm = two_state_machine()
    entry = live_server.hub.add_local(sm, name="two")
    sockets = [stream(live_server, "two") for _ in range(3)]
    for ws in sockets:
        frames(ws, lambda got: len(got) == 1)  # the snapshot
    sm.execute()
    for ws in sockets:
        frames(ws, has_terminate)
        ws.close()
    assert sorted(encoded) == list(range(1, entry.local.reporter.last_seq + 1))


class CountingEvent(asyncio.Event):
    def __init__(self):
        super().__init__()
        self.sets = 0

    def set(self):
        self.sets += 1
        super().set()


def test_a_stalled_client_is_not_touched_per_event(live_server, monkeypatch):
    monkeypatch.setattr(fanout, "SEND_TIMEOUT", 60)
    sm = blob_loop(3000)
    entry = live_server.hub.add_local(sm, name="loop")
    raw = stalled_stream(live_server, "loop")
    try:
        wait_for(lambda: len(entry.feed.clients) == 1)
        [client] = list(entry.feed.clients)

        # Fill the socket buffers until a send blocks: one that started and is still not done 0.2 s
        # later (a send that merely happened to be under way would finish and wake the client again).
        def a_send_stays_blocked() -> bool:
            started = client.send_started
            if started is None:
                sm.execute()
                return False
            return time.monotonic() - started >= 0.2

        wait_for(a_send_stays_blocked, 60, interval=0.05)
        counting = client.wake = CountingEvent()
        for _ in range(5):
            sm.execute()  # 5 x 3,000 more events
        wait_for(lambda: entry.feed.loop_seq == entry.local.reporter.last_seq)
        assert client.send_started is not None and counting.sets == 0
        assert client not in entry.feed.idle
    finally:
        raw.close()


def test_a_blocked_loop_bounds_the_handoff_and_clients_end_with_the_true_status(live_server):
    quiet = lambda msg: None  # noqa: E731
    fsm.set_loggers(quiet, quiet, quiet, quiet)
    sm = two_state_loop(100_000)  # 200k transitions
    entry = live_server.hub.add_local(sm, name="flood")
    truth = Status("flood")
    fsm.attach(sm, truth.apply)
    with stream(live_server, "flood") as ws:
        frames(ws, lambda got: len(got) == 1)  # the snapshot
        blocked, release = threading.Event(), threading.Event()
        live_server.hub.loop.call_soon_threadsafe(lambda: (blocked.set(), release.wait(60)))
        assert blocked.wait(5)
        longest = [0]

        def watch(event):
            longest[0] = max(longest[0], len(entry.feed.handoff))
        fsm.attach(sm, watch)
        try:
            assert sm.execute() == "done"
            assert entry.local.reporter.last_seq > 200_000
            assert longest[0] <= feed.HANDOFF_LIMIT  # memory bounded while nobody drains
            assert entry.feed.status_dict()["outcome"] == "done"  # the hub's Status did not wait for the loop
        finally:
            release.set()
        got = frames(ws, lambda got: got and got[-1]["type"] == "snapshot" and
                     got[-1]["last_seq"] == entry.local.reporter.last_seq, timeout=10)
    assert got[-2]["type"] == "missed" and got[-2]["count"] > 0
    expected = truth.to_dict()
    assert got[-1]["status"] == expected
