"""`fsmscope replay LOG --serve` in a real process: the whole log loaded before the URL is printed,
every machine served at the log's end, with its timeline."""

import contextlib

import httpx
from fsm.logfiles.log_reader import read_events, seek
from fsm.observation.status import rebuild

from recording_support import record, replay_served
from server_support import sleeper
from smach_support import machine

TOKEN = "replay-serve-token"


@contextlib.contextmanager
def replaying(log):
    """``fsmscope replay LOG --serve``: yields (an HTTP client of it, the stderr lines before its address)."""
    with replay_served(log, "--token", TOKEN) as (url, said):
        with httpx.Client(base_url=url.split("/?")[0], headers={"Authorization": "Bearer " + TOKEN}) as client:
            yield client, said


def recorded_nested_run(path):
    sub = machine(["done"], [("A", sleeper(0.005), {"go": "B"}), ("B", sleeper(0.005), {"go": "done"})])
    record(machine(["done"], [("SUB", sub, {"done": "C"}), ("C", sleeper(0.005), {"go": "done"})]), path, name="nested")
    return list(read_events(path))


def steps(events):
    return [[e["seq"], e["t"]] for e in events if e["kind"] in ("start", "transition", "terminate")]


def test_right_after_start_the_status_is_the_one_at_the_end_of_the_log(tmp_path):
    events = recorded_nested_run(tmp_path / "nested.jsonl")
    with replaying(tmp_path / "nested.jsonl") as (client, _):
        status = client.get("/api/machines/nested/status").json()
    at_end = rebuild(events)["nested"].to_dict()
    assert (status["last_seq"], status["outcome"], status["running"]) == (events[-1]["seq"], "done", False)
    assert {path: c["outcome"] for path, c in status["containers"].items()} == \
        {path: c["outcome"] for path, c in at_end["containers"].items()}


def test_right_after_start_the_timeline_spans_the_whole_log(tmp_path):
    events = [e for e in recorded_nested_run(tmp_path / "nested.jsonl") if e["kind"] != "snapshot"]
    with replaying(tmp_path / "nested.jsonl") as (client, _):
        got = client.get("/api/machines/nested/timeline").json()
    assert got["last"]["seq"] == events[-1]["seq"] and got["transitions"] == steps(events)
    assert [band[3] for band in got["bands"]["/SM_ROOT"]] == ["SUB", "C", None]
    assert [band[3] for band in got["bands"]["/SM_ROOT/SUB"]] == ["A", "B", None]


def test_the_status_at_any_event_and_the_history_come_from_the_log(tmp_path):
    log = tmp_path / "nested.jsonl"
    events = [e for e in recorded_nested_run(log) if e["kind"] != "snapshot"]
    middle = events[len(events) // 2]["seq"]
    with replaying(log) as (client, _):
        status = client.get("/api/machines/nested/status", params={"seq": middle}).json()
        page = client.get("/api/machines/nested/history").json()
    assert status["last_seq"] == middle
    assert status["containers"]["/SM_ROOT"]["active"] == seek(log, "nested", middle).status.containers["/SM_ROOT"]["active"]
    assert [e["seq"] for e in page["events"]] == [e["seq"] for e in events]


def test_the_machines_are_served_as_replays_at_the_play_speed_given(tmp_path):
    recorded_nested_run(tmp_path / "nested.jsonl")
    with replaying(tmp_path / "nested.jsonl") as (client, _):
        (info,) = client.get("/api/machines").json()
    assert (info["name"], info["source"], info["replay"], info["can_start"]) == ("nested", "replay", {"speed": 1.0},
                                                                                 False)


def test_a_log_with_corrupt_lines_loads_every_complete_event_and_says_what_it_skipped(tmp_path):
    events = recorded_nested_run(tmp_path / "nested.jsonl")
    lines = (tmp_path / "nested.jsonl").read_bytes().splitlines(keepends=True)
    corrupt = tmp_path / "corrupt.jsonl"
    corrupt.write_bytes(b"".join(lines[:3]) + b"{not json\n" + b"".join(lines[3:]) + b'{"v": 1, "seq"')
    with replaying(corrupt) as (client, said):
        got = client.get("/api/machines/nested/timeline").json()
    assert got["transitions"] == steps(events)
    assert any("line 4: not JSON" in line for line in said)
    assert any("truncated last line" in line for line in said)
