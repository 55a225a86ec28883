"""fsm.logfiles.log_reader: bad lines, schema versions, following a growing log, seeking."""

import threading
import time

import fsm
import pytest
from fsm.observation.encoding import dumps
from fsm.logfiles.log_reader import LogError, SchemaError, follow, read_events, seek
from fsm.logfiles.recorder import Recorder, index_path
from fsm.observation.status import rebuild

from recording_support import two_state_loop, record


_loop = two_state_loop


@pytest.fixture
def log(tmp_path):
    path = tmp_path / "run.jsonl"
    record(_loop(5), path)
    return path


def _read(path):
    problems = []
    events = list(read_events(path, problems.append))
    return events, problems


def test_a_truncated_last_line_is_reported_with_its_number_and_skipped(log):
    events, _ = _read(log)
    data = log.read_bytes()
    log.write_bytes(data[:-20])
    got, problems = _read(log)
    assert got == events[:-1]
    assert [(p.line, p.truncated) for p in problems] == [(len(events), True)]


def test_a_corrupt_line_is_reported_and_every_other_event_is_read(log):
    events, _ = _read(log)
    lines = log.read_bytes().split(b"\n")
    lines[2] = b'{"v": 1, "seq": garbage'
    log.write_bytes(b"\n".join(lines))
    got, problems = _read(log)
    assert got == events[:2] + events[3:]
    assert [(p.line, p.truncated) for p in problems] == [(3, False)]
    assert "not JSON" in problems[0].message


def test_a_json_line_that_is_not_an_event_is_reported(log):
    with open(log, "ab") as handle:
        handle.write(b'[1, 2]\n{"v": 1, "seq": 9}\n')
    _, problems = _read(log)
    assert [p.message for p in problems] == ["not a JSON object", "invalid event: event lacks 't'"]


def test_an_unknown_schema_version_is_refused_with_a_clear_message(log):
    with open(log, "ab") as handle:
        handle.write(dumps({"v": 2, "seq": 1, "t": 0, "run": "r", "machine": "m", "kind": "start", "path": "/"}) + b"\n")
    with pytest.raises(SchemaError, match="schema version 2 is not supported"):
        _read(log)


def test_a_missing_file_is_a_log_error(tmp_path):
    with pytest.raises(LogError, match="no such file"):
        list(read_events(tmp_path / "nope.jsonl"))


def test_seek_through_the_index_gives_the_state_a_full_replay_gives(tmp_path):
    path = tmp_path / "run.jsonl"
    record(_loop(200), path, snapshot_every=50)
    events = [e for e in read_events(path) if e["kind"] != "snapshot"]
    result = seek(path, "m", 333)
    assert result.used_index and result.offset > 0
    assert result.status.to_dict() == rebuild(e for e in events if e["seq"] <= 333)["m"].to_dict()


def test_seek_falls_back_to_scanning_when_the_index_is_stale(tmp_path):
    path = tmp_path / "run.jsonl"
    record(_loop(200), path, snapshot_every=50)
    with open(index_path(path), "w") as handle:
        handle.write('{"machine": "m", "seq": 300, "offset": 17}\n')
    events = [e for e in read_events(path) if e["kind"] != "snapshot"]
    result = seek(path, "m", 333)
    assert not result.used_index
    assert result.status.to_dict() == rebuild(e for e in events if e["seq"] <= 333)["m"].to_dict()


def test_seek_without_an_index_scans_the_log(tmp_path):
    path = tmp_path / "run.jsonl"
    record(_loop(20), path, snapshot_every=10)
    index_path_ = index_path(path)
    import os
    os.remove(index_path_)
    result = seek(path, "m", 15)
    assert not result.used_index and result.status.last_seq == 15


def test_follow_yields_events_as_they_are_written_and_stops_when_the_writer_closes(tmp_path):
    path = tmp_path / "run.jsonl"
    recorder = Recorder(path)
    got = []
    reader = threading.Thread(target=lambda: got.extend(follow(path, poll=0.02)))
    reader.start()
    sm = _loop(5)
    seen = []
    fsm.attach(sm, recorder, name="m")
    fsm.attach(sm, seen.append)
    sm.execute()
    time.sleep(0.2)
    assert reader.is_alive()  # still following: the writer has not closed the log
    recorder.close()
    reader.join(5)
    assert not reader.is_alive()
    assert got == seen
