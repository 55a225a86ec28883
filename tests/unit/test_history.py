"""A machine's past read from its recording (fsmscope/server/history.py's LogHistory, History.from_log): the
status after any event, the seq at a time, pages of events, over real Recorder logs, corrupt ones
and logs without an index."""

import os
import shutil

import pytest
from fsm.logfiles.log_reader import read_events, seek
from fsm.logfiles.recorder import index_path
from fsm.observation.status import Status
from hypothesis import HealthCheck, given, settings, strategies as st

from recording_support import record
from fsmscope.server import history as history_module
from fsm.control.controls import Refused
from fsmscope.server.history import History, LogHistory
from smach_support import counting_machine

ROUNDS = 300
SNAPSHOT_EVERY = 97


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """(the log of a run of counting_machine, the events the recorder was given)."""
    path = str(tmp_path_factory.mktemp("history") / "run.jsonl")
    outcome, seen = record(counting_machine(ROUNDS), path, snapshot_every=SNAPSHOT_EVERY)
    assert outcome == "done" and len(seen) > 10 * SNAPSHOT_EVERY
    return path, seen


def status_after(events, seq, machine="m"):
    """The reference: a fresh Status given every event up to ``seq``."""
    status = Status(machine)
    for event in events:
        if event["seq"] <= seq and event["kind"] != "snapshot":
            status.apply(event)
    return status.to_dict()


def without_index(path, tmp_path):
    """A copy of the log with no .idx beside it (a foreign or hand-made log)."""
    copy = str(tmp_path / "foreign.jsonl")
    shutil.copy(path, copy)
    return copy


def corrupted(path, tmp_path):
    """A copy of the log with damage of every sort: a line overwritten in place, garbage lines inserted
    (the .idx offsets after them go stale), a valid JSON line that is no event, and a last line cut short."""
    with open(path, "rb") as handle:
        lines = handle.readlines()
    damaged = list(lines)
    damaged[len(lines) // 3] = b"#" * (len(lines[len(lines) // 3]) - 1) + b"\n"
    damaged.insert(len(lines) // 2, b"{not json at all\n")
    damaged.insert(2 * len(lines) // 3, b'{"v": 1, "seq": 999999, "machine": "m", "kind": "transition"}\n')
    damaged.append(lines[-1][: len(lines[-1]) // 2])
    copy = str(tmp_path / "corrupt.jsonl")
    with open(copy, "wb") as handle:
        handle.writelines(damaged)
    shutil.copy(index_path(path), index_path(copy))
    return copy


def seqs_of(page):
    return [event["seq"] for event in page["events"]]


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_status_at_any_event_equals_applying_every_event_up_to_it(recorded, data):
    path, seen = recorded
    seq = data.draw(st.integers(1, seen[-1]["seq"]))
    assert LogHistory(path, "m").status_at(seq).to_dict() == status_after(seen, seq)


@pytest.mark.parametrize("seq", [1, 2, SNAPSHOT_EVERY, SNAPSHOT_EVERY + 1, 1000, 1500])
def test_status_at_equals_the_log_readers_seek(recorded, seq):
    path, _ = recorded
    assert LogHistory(path, "m").status_at(seq).to_dict() == seek(path, "m", seq).status.to_dict()


def test_a_log_without_index_is_indexed_by_one_scan_and_answers_the_same(recorded, tmp_path):
    path, seen = recorded
    log = LogHistory(without_index(path, tmp_path), "m", every=50)
    last = seen[-1]["seq"]
    for seq in (1, 49, 50, 51, last // 2, last):
        assert log.status_at(seq).to_dict() == status_after(seen, seq)
    assert log.last() == (last, seen[-1]["t"])


def test_span_is_the_first_and_last_event_of_the_log(recorded):
    path, seen = recorded
    assert History.from_log(path, "m").span() == {"first_seq": 1, "last_seq": seen[-1]["seq"]}


def test_seq_at_a_time_is_the_last_event_at_or_before_it(recorded):
    path, seen = recorded
    log = LogHistory(path, "m")
    for event in seen[:: len(seen) // 25]:
        at_or_before = [e["seq"] for e in seen if e["t"] <= event["t"]]
        assert log.seq_at(event["t"]) == at_or_before[-1]


def test_a_time_before_the_first_event_is_gone(recorded):
    path, seen = recorded
    with pytest.raises(Refused) as caught:
        History.from_log(path, "m").status_at(t=seen[0]["t"] - 1)
    assert caught.value.status == 410 and "reaches back to seq 1" in caught.value.message


def test_status_beyond_the_last_event_is_416(recorded):
    path, seen = recorded
    last = seen[-1]["seq"]
    with pytest.raises(Refused) as caught:
        History.from_log(path, "m").status_at(last + 1)
    assert (caught.value.status, caught.value.message) == (416, "seq %d is beyond the last event (%d)"
                                                           % (last + 1, last))


def test_pages_forward_through_next_return_every_event_once_in_order(recorded):
    path, seen = recorded
    history = History.from_log(path, "m")
    got, since = [], None
    while True:
        page = history.page(since=since, limit=333)
        got += seqs_of(page)
        if not page["more"]:
            break
        since = page["next"]
    assert got == [e["seq"] for e in seen]


def test_pages_backward_through_next_return_every_event_once(recorded):
    path, seen = recorded
    history = History.from_log(path, "m")
    pages, until = [], None
    while True:
        page = history.page(until=until, limit=333, order="desc")
        pages.insert(0, seqs_of(page))
        if not page["more"]:
            break
        until = page["next"]
    assert [seq for page in pages for seq in page] == [e["seq"] for e in seen]
    assert all(page == sorted(page) for page in pages)


def test_a_page_filters_by_kind_and_path(recorded):
    path, seen = recorded
    page = History.from_log(path, "m").page(kinds={"userdata"}, path="/SM_ROOT/SUB", limit=10_000)
    assert seqs_of(page) == [e["seq"] for e in seen if e["kind"] == "userdata" and e["path"] == "/SM_ROOT/SUB"]
    assert page["more"] is False and page["next"] is None


def test_a_page_never_holds_snapshots(recorded):
    path, _ = recorded
    assert "snapshot" not in {e["kind"] for e in History.from_log(path, "m").page(limit=10_000)["events"]}


def test_a_range_entirely_before_the_log_is_gone_and_one_that_overlaps_it_starts_at_its_first(recorded, tmp_path):
    path, seen = recorded
    with open(path, "rb") as handle:
        later = [raw for raw in handle if b'"seq":1,' not in raw and b'"seq":2,' not in raw]
    clipped = str(tmp_path / "clipped.jsonl")
    with open(clipped, "wb") as handle:
        handle.writelines(later)
    history = History.from_log(clipped, "m")
    with pytest.raises(Refused) as caught:
        history.page(since=0, until=2)
    assert caught.value.status == 410 and caught.value.message == "history reaches back to seq 3"
    assert seqs_of(history.page(since=0, limit=2)) == [3, 4]


@pytest.mark.parametrize("indexed", [True, False], ids=["with .idx", "without .idx"])
def test_a_corrupt_log_still_seeks_and_pages_over_every_complete_event(recorded, tmp_path, indexed):
    path, _ = recorded
    damaged = corrupted(path, tmp_path)
    if not indexed:
        os.remove(index_path(damaged))
    complete = [e for e in read_events(damaged) if e["kind"] != "snapshot"]
    log = LogHistory(damaged, "m", every=64)
    for seq in (1, complete[len(complete) // 3]["seq"], complete[len(complete) // 2]["seq"] + 5,
                complete[-1]["seq"]):
        assert log.status_at(seq).to_dict() == status_after(complete, seq)
    assert seqs_of(History(None, log).page(limit=10_000)) == [e["seq"] for e in complete]


def test_a_last_line_being_written_is_left_out_until_it_is_whole(recorded, tmp_path):
    path, seen = recorded
    with open(path, "rb") as handle:
        lines = handle.readlines()
    live = str(tmp_path / "live.jsonl")
    with open(live, "wb") as handle:
        handle.writelines(lines[:-1])
        handle.write(lines[-1][:10])
    log = LogHistory(live, "m")
    before = log.last()
    with open(live, "ab") as handle:
        handle.write(lines[-1][10:])
    assert before == (seen[-2]["seq"], seen[-2]["t"]) and log.last() == (seen[-1]["seq"], seen[-1]["t"])


def test_a_log_of_two_machines_answers_for_the_one_asked(tmp_path):
    path = str(tmp_path / "two.jsonl")
    record(counting_machine(20), path, name="one", snapshot_every=30)
    _, second = record(counting_machine(40), path, name="two", snapshot_every=30)
    log = LogHistory(path, "two")
    seq = second[len(second) // 2]["seq"]
    assert log.status_at(seq).to_dict() == status_after(second, seq, "two")
    assert seqs_of(History(None, log).page(limit=10_000)) == [e["seq"] for e in second]


def test_a_filtered_page_stops_after_its_scan_budget_and_the_next_one_goes_on(recorded, monkeypatch):
    path, seen = recorded
    monkeypatch.setattr(history_module, "SCAN_BUDGET", 500)
    history = History.from_log(path, "m")
    terminates = [e["seq"] for e in seen if e["kind"] == "terminate"]
    first = history.page(kinds={"terminate"})
    assert first["more"] is True and seqs_of(first) == [s for s in terminates if s < first["next"]]
    assert seqs_of(history.page(since=first["next"], kinds={"terminate"}))[0] == \
        [s for s in terminates if s >= first["next"]][0]
