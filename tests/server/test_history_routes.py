"""GET /api/machines/{name}/status?seq=|t= and GET .../history against a real uvicorn, with real machines
recorded by a real Recorder (docs/api.md, "Time travel")."""

import fsm
import pytest
from fsm.logfiles.log_reader import read_events, seek
from fsm.logfiles.recorder import Recorder

from fsmscope.server import feed, history
from fsmscope.server.history import LogHistory
from fsmscope.server.testing.polling import wait_for
from server_support import client
from smach_support import counting_machine


def past(status):
    """A status as GET .../status?seq= answers it, comparable with log_reader.seek's."""
    data = dict(status)
    data.pop("structure", None)
    data.pop("preempt_waiting_on", None)
    return data


def run_recorded(srv, tmp_path, rounds, name="m", recording=True):
    """Run counting_machine(rounds) shown by the server and recorded; returns the log's path."""
    path = str(tmp_path / ("%s.jsonl" % name))
    sm = counting_machine(rounds)
    with Recorder(path) as recorder:
        fsm.attach(sm, recorder, name=name)
        srv.hub.add_local(sm, name=name, recording=path if recording else None)
        assert sm.execute() == "done"
    return path


@pytest.fixture
def quiet(logs):
    """The runtime's log lines captured instead of printed (long runs print thousands)."""
    return logs


@pytest.fixture
def recorded(live_server, tmp_path, quiet):
    """A machine 'm' run for 600 rounds (about 3,000 events), recorded and shown: (server, http, log path)."""
    return live_server, client(live_server), run_recorded(live_server, tmp_path, 600)


def test_status_at_a_seq_equals_the_log_readers_seek(recorded):
    srv, http, path = recorded
    for seq in (1, 2, 777, 2001, 2500):
        answer = http.get("/api/machines/m/status", params={"seq": seq})
        assert answer.status_code == 200
        assert past(answer.json()) == past(seek(path, "m", seq).status.to_dict())


def test_status_without_seq_or_t_is_the_present(recorded):
    _, http, path = recorded
    last = [e for e in read_events(path) if e["kind"] != "snapshot"][-1]["seq"]
    status = http.get("/api/machines/m/status").json()
    assert status["last_seq"] == last and status["outcome"] == "done" and "structure" not in status


def test_status_at_a_time_is_the_status_after_the_last_event_at_or_before_it(recorded):
    _, http, path = recorded
    events = [e for e in read_events(path) if e["kind"] != "snapshot"]
    event = events[len(events) // 2]
    status = http.get("/api/machines/m/status", params={"t": event["t"]}).json()
    assert status["last_seq"] == [e["seq"] for e in events if e["t"] <= event["t"]][-1]


def test_a_container_status_says_its_last_transition_and_the_keys_it_changed(recorded):
    _, http, _ = recorded
    sub = http.get("/api/machines/m/status", params={"seq": 30}).json()["containers"]["/SM_ROOT/SUB"]
    assert set(sub) >= {"last", "changes", "written"}


def test_history_pages_forward_with_next(recorded):
    _, http, path = recorded
    got, since = [], None
    while True:
        page = http.get("/api/machines/m/history", params={"limit": 1000} if since is None else
                        {"limit": 1000, "since": since}).json()
        got += [e["seq"] for e in page["events"]]
        if not page["more"]:
            break
        since = page["next"]
    assert got == [e["seq"] for e in read_events(path) if e["kind"] != "snapshot"]
    assert page["first_seq"] == 1 and page["last_seq"] == got[-1]


def test_history_desc_returns_the_newest_of_the_range_oldest_first(recorded):
    _, http, _ = recorded
    page = http.get("/api/machines/m/history", params={"until": 1000, "limit": 10, "order": "desc"}).json()
    assert [e["seq"] for e in page["events"]] == list(range(991, 1001))
    assert page["more"] is True and page["next"] == 990


def test_history_filters_by_kinds_and_path(recorded):
    _, http, path = recorded
    page = http.get("/api/machines/m/history", params={"kinds": "start,terminate", "path": "/SM_ROOT/SUB",
                                                        "limit": 10000}).json()
    assert [e["seq"] for e in page["events"]] == [e["seq"] for e in read_events(path)
                                                  if e["kind"] in ("start", "terminate")
                                                  and e["path"] == "/SM_ROOT/SUB"]


@pytest.mark.parametrize("route, params, message", [
    ("status", {"seq": 1, "t": 1.0}, "give seq or t, not both"),
    ("status", {"seq": -1}, "query.seq: Input should be greater than or equal to 0"),
    ("status", {"seq": "1.5"}, "query.seq: Input should be a valid integer"),
    ("status", {"seq": "abc"}, "query.seq: Input should be a valid integer"),
    ("status", {"t": "nan"}, "t must be a finite number of seconds, not nan"),
    ("status", {"t": "inf"}, "t must be a finite number of seconds, not inf"),
    ("history", {"limit": 10001}, "query.limit: Input should be less than or equal to 10000"),
    ("history", {"limit": 0}, "query.limit: Input should be greater than or equal to 1"),
    ("history", {"since": 10, "until": 5}, "since (10) is after until (5)"),
    ("history", {"kinds": "transition,bogus"}, "kinds: 'bogus' is not an event kind"),
    ("history", {"order": "sideways"}, "query.order: Input should be 'asc' or 'desc'"),
])
def test_a_bad_request_is_422_with_a_message(recorded, route, params, message):
    _, http, _ = recorded
    answer = http.get("/api/machines/m/" + route, params=params)
    assert answer.status_code == 422 and answer.json()["detail"].startswith(message)


def test_a_seek_beyond_the_last_event_is_416(recorded):
    _, http, _ = recorded
    last = http.get("/api/machines/m/status").json()["last_seq"]
    answer = http.get("/api/machines/m/status", params={"seq": last + 5})
    assert answer.status_code == 416
    assert answer.json()["detail"] == "seq %d is beyond the last event (%d)" % (last + 5, last)


def test_an_unknown_machine_is_404_for_both(live_server):
    http = client(live_server)
    assert http.get("/api/machines/nope/status", params={"seq": 1}).status_code == 404
    assert http.get("/api/machines/nope/history").status_code == 404


def test_history_needs_the_token(live_server):
    assert client(live_server, token=False).get("/api/machines/m/history").status_code == 401


def test_a_long_run_keeps_memory_bounded_and_seeks_its_beginning_in_the_recording(live_server, tmp_path, quiet):
    rounds = 3 * feed.RING_SIZE // 5  # about 3 rings of events
    path = run_recorded(live_server, tmp_path, rounds)
    http = client(live_server)
    status = http.get("/api/machines/m/status", params={"seq": 5})
    entry = live_server.hub.get("m")
    assert status.status_code == 200 and past(status.json()) == past(seek(path, "m", 5).status.to_dict())
    assert entry.feed.status.last_seq > 2 * feed.RING_SIZE
    assert len(entry.feed.ring) == feed.RING_SIZE
    assert len(entry.past.keyframes.kept) <= feed.RING_SIZE // history.KEYFRAME_EVERY + 2
    assert entry.past.keyframes.kept[0][0] >= entry.feed.ring[0][0] - 2 * history.KEYFRAME_EVERY
    assert http.get("/api/machines/m/history", params={"limit": 3}).json()["first_seq"] == 1


def test_without_a_recording_history_reaches_back_as_far_as_the_ring(live_server, tmp_path, quiet):
    run_recorded(live_server, tmp_path, 2 * feed.RING_SIZE // 5, recording=False)
    http = client(live_server)
    page = http.get("/api/machines/m/history", params={"limit": 1}).json()
    first = page["first_seq"]
    assert first > 1 and page["events"][0]["seq"] == first
    answer = http.get("/api/machines/m/status", params={"seq": first - 1})
    assert answer.status_code == 410 and answer.json()["detail"] == "history reaches back to seq %d" % first
    assert http.get("/api/machines/m/status", params={"seq": first}).json()["last_seq"] == first


def test_the_recent_past_from_memory_equals_the_recording(live_server, tmp_path, quiet):
    path = run_recorded(live_server, tmp_path, 600, recording=False)
    http = client(live_server)
    for seq in (1, 999, 1000, 1001, 2345):
        assert past(http.get("/api/machines/m/status", params={"seq": seq}).json()) == \
            past(seek(path, "m", seq).status.to_dict())


def test_a_machine_served_from_a_log_alone_answers_from_it(live_server, tmp_path, quiet):
    path = run_recorded(live_server, tmp_path, 100, name="recorded")
    first = next(read_events(path))
    live_server.hub.loop.call_soon_threadsafe(live_server.hub.ingest, dict(first, machine="replayed"), "replay")
    wait_for(lambda: live_server.hub.get("replayed") is not None)
    http = client(live_server)
    live_server.hub.get("replayed").read_past_from(LogHistory(path, "recorded"))
    status = http.get("/api/machines/replayed/status", params={"seq": 300}).json()
    assert past(status) == past(seek(path, "recorded", 300).status.to_dict())
    assert http.get("/api/machines/replayed/history", params={"since": 300, "limit": 2}).json()["next"] == 302


def test_openapi_documents_both_with_examples(live_server):
    spec = client(live_server).get("/openapi.json").json()
    status = spec["paths"]["/api/machines/{name}/status"]["get"]
    history = spec["paths"]["/api/machines/{name}/history"]["get"]
    assert {"410", "416", "422"} <= set(status["responses"]) and {"410", "422"} <= set(history["responses"])
    assert {p["name"] for p in status["parameters"]} >= {"seq", "t"}
    assert {p["name"] for p in history["parameters"]} >= {"since", "until", "limit", "kinds", "path", "order"}
    for name in ("MachineStatus", "HistoryPage"):
        assert spec["components"]["schemas"][name]["examples"]


def test_a_machine_of_another_process_answers_its_recent_past_from_memory(live_server, tmp_path, quiet):
    path = run_recorded(live_server, tmp_path, 600, name="recorded")
    events = [dict(e, machine="remote") for e in read_events(path) if e["kind"] != "snapshot"]
    for event in events:
        live_server.hub.loop.call_soon_threadsafe(live_server.hub.ingest, event, "ingest")
    http = client(live_server)
    wait_for(lambda: http.get("/api/machines/remote/status").json()["last_seq"] == events[-1]["seq"])
    for seq in (1, 1000, 1001, 2345):
        assert past(http.get("/api/machines/remote/status", params={"seq": seq}).json()) == \
            dict(past(seek(path, "recorded", seq).status.to_dict()), machine="remote")


def test_without_a_recording_the_timeline_says_how_far_back_an_instant_can_be_shown(live_server, tmp_path, quiet):
    run_recorded(live_server, tmp_path, 2 * feed.RING_SIZE // 5, recording=False)
    http = client(live_server)
    first = http.get("/api/machines/m/history", params={"limit": 1}).json()["first_seq"]
    timeline = http.get("/api/machines/m/timeline").json()
    assert timeline["first"]["seq"] == 1 and timeline["history_from"] == first > 1
