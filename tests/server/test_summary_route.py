"""GET /api/machines/{name}/summary: each state's visits, time and last outcome, as ``fsmscope replay``
counts them (fsm/logfiles/summary.py), read incrementally from the machine's history (docs/api.md)."""

import fsm
import pytest
from fsm.logfiles.log_reader import read_events
from fsm.logfiles.recorder import Recorder
from fsm.logfiles.summary import summarize

from fsmscope.server import state_stats
from fsmscope.server.read_budget import ReadBudget
from server_support import client
from smach_support import counting_machine

ROUNDS = 40  # COUNT runs 41 times, SUB and its A and B 40


@pytest.fixture
def served(live_server, tmp_path, logs):
    """counting_machine(ROUNDS) run to its end, recorded and shown as 'm': (http client, the log's path)."""
    path = str(tmp_path / "m.jsonl")
    # The summary's rules, not the read budget's: on a loaded machine two catch-ups from disk cost more
    # than the default budget repays within its hold, and the second was answered 429.
    live_server.app.state.reads = ReadBudget(rate=1.0, burst=10.0)
    sm = counting_machine(ROUNDS)
    with Recorder(path) as recorder:
        fsm.attach(sm, recorder, name="m")
        live_server.hub.add_local(sm, name="m", recording=path)
        assert sm.execute() == "done"
    return client(live_server), path


def test_a_state_s_statistics_are_the_replay_summary_s(served):
    http, path = served
    answer = http.get("/api/machines/m/summary", params={"path": "/SM_ROOT/SUB/A"})
    assert answer.status_code == 200, answer.text
    expected = summarize(read_events(path)).to_dict()["machines"]["m"]["states"]["/SM_ROOT/SUB/A"]
    assert answer.json()["states"] == {"/SM_ROOT/SUB/A": expected}


def test_visits_and_last_outcome_of_a_state(served):
    http, _ = served
    count = http.get("/api/machines/m/summary", params={"path": "/SM_ROOT/COUNT"}).json()["states"]["/SM_ROOT/COUNT"]
    assert (count["visits"], count["last_outcome"]) == (ROUNDS + 1, "enough")


def test_without_a_path_every_visited_state_is_listed(served):
    http, _ = served
    states = http.get("/api/machines/m/summary").json()["states"]
    assert set(states) == {"/SM_ROOT/COUNT", "/SM_ROOT/SUB", "/SM_ROOT/SUB/A", "/SM_ROOT/SUB/B"}


def test_a_state_never_visited_has_no_visits(live_server):
    sm = counting_machine(1)
    live_server.hub.add_local(sm, name="idle")
    answer = client(live_server).get("/api/machines/idle/summary", params={"path": "/SM_ROOT/SUB/A"})
    assert answer.status_code == 200, answer.text
    assert answer.json()["states"]["/SM_ROOT/SUB/A"]["visits"] == 0


def test_the_answer_says_every_event_is_counted(served):
    http, _ = served
    answer = http.get("/api/machines/m/summary").json()
    assert answer["complete"] and answer["counted"]["last_seq"] == answer["last_seq"]


def test_a_question_reads_at_most_a_bounded_number_of_events(served, monkeypatch):
    http, _ = served
    monkeypatch.setattr(state_stats, "CATCH_UP", 50)
    first = http.get("/api/machines/m/summary").json()
    assert (first["complete"], first["counted"]["last_seq"]) == (False, 50)


def test_the_next_question_goes_on_where_the_last_stopped(served, monkeypatch):
    http, _ = served
    monkeypatch.setattr(state_stats, "CATCH_UP", 50)
    http.get("/api/machines/m/summary")
    assert http.get("/api/machines/m/summary").json()["counted"] == {"first_seq": 1, "last_seq": 100}


def test_an_unknown_state_is_404(served):
    http, _ = served
    answer = http.get("/api/machines/m/summary", params={"path": "/SM_ROOT/NOPE"})
    assert answer.status_code == 404 and "NOPE" in answer.json()["detail"]


def test_an_unknown_machine_is_404(live_server):
    assert client(live_server).get("/api/machines/nobody/summary").status_code == 404


def test_a_path_too_long_is_422(served):
    http, _ = served
    answer = http.get("/api/machines/m/summary", params={"path": "/" + "x" * 5000})
    assert answer.status_code == 422


def test_a_machine_without_a_structure_yet_answers_404_for_a_path(live_server):
    refusal = live_server.hub.ingest({"v": 1, "seq": 1, "t": 1.0, "run": "r", "machine": "bare", "kind": "log",
                                      "path": "/SM_ROOT", "level": "info", "msg": "hello"})
    assert refusal is None and live_server.hub.get("bare") is not None
    answer = client(live_server).get("/api/machines/bare/summary", params={"path": "/SM_ROOT"})
    assert answer.status_code == 404
