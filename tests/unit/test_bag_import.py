"""ROS bags of a SMACH run (written by the tests as smach_ros publishes, bag_support.py) read without ROS:
the same events from every layout, what the run did, userdata never run, and clear words for bags
that cannot be read."""

from __future__ import annotations

import os
import pickle
import time

import pytest
from bag_support import GRASP, PLACE, ROOT, messages, write_bag
from recording_support import cli

from fsm.logfiles.log_reader import read_events
from fsm.observation import schema
from fsmscope.interop import bag_reader, smach_events
from fsmscope.interop.testing import container_run, wide_run

LAYOUTS = {"ros1": "run.bag", "ros1-raw": "run.bag", "ros2-sqlite3": "run", "ros2-mcap": "run"}


def events_of(bag) -> list[dict]:
    return list(smach_events.events(bag_reader.read_bag(str(bag))))


@pytest.fixture(scope="module")
def noetic_events(tmp_path_factory):
    return events_of(write_bag(tmp_path_factory.mktemp("noetic") / "run.bag", "ros1"))


@pytest.mark.parametrize("layout", ["ros1-raw", "ros2-sqlite3", "ros2-mcap"])
def test_every_layout_gives_the_events_of_a_noetic_bag(layout, tmp_path, noetic_events):
    assert events_of(write_bag(tmp_path / LAYOUTS[layout], layout)) == noetic_events


def test_every_event_is_one_of_the_schema(noetic_events):
    assert [schema.validate(ev) for ev in noetic_events] == [None] * len(noetic_events)


def test_the_structure_has_the_containers_their_states_and_edges(noetic_events):
    root = noetic_events[0]["root"]
    grasp = next(c for c in root["children"] if c["path"] == GRASP)
    assert [c["label"] for c in root["children"]] == ["FIND", "GRASP", "PLACE"]
    assert grasp["type"] == "Concurrence" and grasp["outcomes"] == ["failed", "grasped"]
    assert {"from": "FIND", "outcome": "found", "to": "GRASP"} in root["transitions"]
    place = next(c for c in root["children"] if c["path"] == PLACE)
    assert {"from": "RELEASE", "outcome": "preempted", "to": None} in place["transitions"]


def test_the_run_is_told_as_it_went(noetic_events):
    told = [(ev["kind"], ev["path"], ev.get("from"), ev.get("outcome"), ev.get("to")) for ev in noetic_events[1:]
            if ev["kind"] in ("start", "transition", "terminate")]
    assert told == [
        ("start", ROOT, None, None, None), ("transition", ROOT, "FIND", "found", "GRASP"),
        ("start", GRASP, None, None, None), ("transition", GRASP, "ARM", "?", None),
        ("transition", GRASP, "GRIPPER", "?", None), ("terminate", GRASP, None, "grasped", None),
        ("transition", ROOT, "GRASP", "grasped", "PLACE"), ("start", PLACE, None, None, None),
        ("transition", PLACE, "MOVE", "moved", "RELEASE"), ("terminate", PLACE, None, "placed", None),
        ("terminate", ROOT, None, "succeeded", None)]


def test_userdata_is_decoded_and_its_changes_are_events(noetic_events):
    start = next(ev for ev in noetic_events if ev["kind"] == "start" and ev["path"] == ROOT)
    assert start["userdata"] == {"target": "cup", "tries": 1, "seen": [0.4, 0.1]}
    changes = [ev["changes"] for ev in noetic_events if ev["kind"] == "userdata"]
    assert changes == [{"opened": True}, {"done": ["ok"]}]


class Shell:
    def __init__(self, marker: str) -> None:
        self.marker = marker

    def __reduce__(self):
        return (os.system, ("touch %s" % self.marker,))


def test_a_userdata_pickle_that_calls_os_system_runs_nothing(tmp_path):
    marker = tmp_path / "ran"
    run = [(t, topic, kind, dict(fields, userdata={"goal": Shell(str(marker))}) if kind == "status" else fields)
           for t, topic, kind, fields in messages()]
    start = next(ev for ev in events_of(write_bag(tmp_path / "evil.bag", "ros1", run)) if ev["kind"] == "start")
    assert not marker.exists()
    assert start["userdata"]["goal"] == {"$repr": "<opaque posix.system>"}


def test_each_introspection_server_is_a_machine(tmp_path):
    both = sorted(messages("left_arm") + messages("right_arm"), key=lambda m: m[0])
    machines = {ev["machine"] for ev in events_of(write_bag(tmp_path / "two.bag", "ros1", both))}
    assert machines == {"left_arm", "right_arm"}


def test_a_bag_without_smach_topics_says_which_topics_it_has(tmp_path):
    chatter = [(t, "/chatter/smach/other", kind, fields) for t, _, kind, fields in messages()[:1]]
    bag = write_bag(tmp_path / "other.bag", "ros1", chatter)
    with pytest.raises(bag_reader.BagError, match="no SMACH introspection topics .* 1 topics: /chatter/smach/other"):
        events_of(bag)


def test_a_truncated_bag_cannot_be_read_and_says_so(tmp_path):
    bag = write_bag(tmp_path / "cut.bag", "ros1")
    bag.write_bytes(bag.read_bytes()[: bag.stat().st_size // 2])
    with pytest.raises(bag_reader.BagError, match="cut.bag: cannot read this bag"):
        events_of(bag)


def test_import_writes_a_log_that_reads_back_as_the_same_events(tmp_path, noetic_events):
    bag = write_bag(tmp_path / "run.bag", "ros1")
    done = cli("import", bag, "-o", tmp_path / "run.jsonl")
    assert done.returncode == 0, done.stderr
    kept = [ev for ev in read_events(str(tmp_path / "run.jsonl")) if ev["kind"] != "snapshot"]
    assert kept == noetic_events


def test_import_of_a_truncated_bag_exits_2_and_writes_nothing(tmp_path):
    bag = write_bag(tmp_path / "cut.bag", "ros1")
    bag.write_bytes(bag.read_bytes()[:100])
    done = cli("import", bag, "-o", tmp_path / "cut.jsonl")
    assert done.returncode == 2 and "cannot read this bag" in done.stderr
    assert not (tmp_path / "cut.jsonl").exists()


def test_import_of_a_bag_without_smach_topics_exits_2(tmp_path):
    bag = write_bag(tmp_path / "other.bag", "ros1", [(t, "/chatter/smach/other", k, f) for t, _, k, f in messages()[:1]])
    done = cli("import", bag, "-o", tmp_path / "other.jsonl")
    assert done.returncode == 2 and "no SMACH introspection topics" in done.stderr


def test_replay_of_a_bag_prints_the_run_and_its_statistics(tmp_path):
    bag = write_bag(tmp_path / "run", "ros2-mcap")
    done = cli("replay", bag, "--no-time")
    assert done.returncode == 0, done.stderr
    assert "State machine transitioning 'GRASP':'grasped'-->'PLACE'" in done.stdout
    assert "machine pick_place: finished with outcome 'succeeded'" in done.stdout


def test_replay_of_a_bag_without_smach_topics_exits_2_and_says_why(tmp_path):
    bag = write_bag(tmp_path / "other.bag", "ros1", [(t, "/chatter/smach/other", k, f) for t, _, k, f in messages()[:1]])
    done = cli("replay", bag)
    assert done.returncode == 2 and "no SMACH introspection topics" in done.stderr


def test_a_humble_sqlite3_bag_without_message_definitions_reads_with_ours(tmp_path, noetic_events):
    import sqlite3

    bag = write_bag(tmp_path / "humble", "ros2-sqlite3")
    with sqlite3.connect(next(bag.glob("*.db3"))) as db:  # Humble's rosbag2 stored no definitions
        db.execute("DELETE FROM message_definitions")
    assert events_of(bag) == noetic_events


def with_userdata(userdata) -> list:
    """The run, every status's userdata ``userdata`` (a value, or the pickle itself when bytes)."""
    return [(t, topic, kind, dict(fields, userdata=userdata) if kind == "status" else fields)
            for t, topic, kind, fields in messages()]


def shared_levels(levels: int = 14, width: int = 10) -> list:
    """A list of ``width`` references to a list of ... : 368 bytes as a pickle, ``width ** levels`` items written out."""
    value: list = []
    for _ in range(levels):
        value = [value] * width
    return value


GIB = 1 << 30


def test_import_and_replay_of_userdata_huge_only_when_written_out_take_little_memory_and_time(tmp_path):
    bag = write_bag(tmp_path / "bomb.bag", "ros1", with_userdata({"bomb": shared_levels()}))
    done = cli("import", bag, "-o", tmp_path / "bomb.jsonl", memory=GIB, timeout=60)
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr[-2000:]
    start = next(ev for ev in read_events(str(tmp_path / "bomb.jsonl")) if ev["kind"] == "start")
    assert start["userdata"]["bomb"]["$truncated"] is True
    replayed = cli("replay", bag, memory=GIB, timeout=60)
    assert replayed.returncode == 0 and "Traceback" not in replayed.stderr, replayed.stderr[-2000:]


def test_import_of_an_int_too_long_for_text_writes_a_marker(tmp_path):
    bag = write_bag(tmp_path / "big.bag", "ros1", with_userdata({"big": 10 ** 5000}))
    done = cli("import", bag, "-o", tmp_path / "big.jsonl")
    assert done.returncode == 0, done.stderr[-2000:]
    start = next(ev for ev in read_events(str(tmp_path / "big.jsonl")) if ev["kind"] == "start")
    assert start["userdata"]["big"] == {"$repr": "<int of 16610 bits>"}


def test_import_of_a_dict_key_nested_deeper_than_hashing_can_go_says_the_userdata_was_not_read(tmp_path):
    key = b")" + b"\x85" * 1_000_000  # ((((...)))) a million deep, built opcode by opcode
    run = messages()
    first = next(i for i, (_, _, kind, _) in enumerate(run) if kind == "status")
    run[first] = run[first][:3] + (dict(run[first][3], userdata=b"\x80\x02}" + key + b"K\x01s."),)
    done = cli("import", write_bag(tmp_path / "deep.bag", "ros1", run), "-o", tmp_path / "deep.jsonl", memory=GIB,
               timeout=60)
    assert done.returncode == 0, done.stderr[-2000:]
    said = [ev["msg"] for ev in read_events(str(tmp_path / "deep.jsonl")) if ev["kind"] == "log"]
    assert said == ["userdata not read: a pickle with a dict key or set item nested deeper than 64 levels"]


@pytest.mark.timeout(60)
def test_a_container_of_twenty_thousand_states_is_read_in_seconds(tmp_path):
    bag = write_bag(tmp_path / "wide.bag", "ros1", wide_run(20_000))
    started = time.monotonic()
    read = events_of(bag)
    assert time.monotonic() - started < 10  # 2 s here; the time was the square of the states' number (> 120 s)
    assert len(read[0]["root"]["children"]) == 20_000 and read[-1]["kind"] == "terminate"


def nested_run(levels: int) -> list:
    """A container in a container ... ``levels`` deep, each going from its one child to 'done'."""
    paths = ["/ROOT" + "/C" * i for i in range(levels + 1)]
    structures = {path: (["C"], [("ok", "C", "done")], ["done"]) for path in paths}
    return container_run("nested", structures, [(0.0, paths[0], ["C"], ["C"], {}), (1.0, paths[0], ["C"], ["None"], {})])


def test_import_of_containers_nested_deeper_than_the_schema_allows_says_why_and_writes_nothing(tmp_path):
    bag = write_bag(tmp_path / "nested.bag", "ros1", nested_run(200))
    done = cli("import", bag, "-o", tmp_path / "nested.jsonl")
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr[-2000:]
    assert "skipped machine nested, whose structure does not fit the schema: structure.root the structure is " \
           "deeper than %d levels" % schema.MAX_STRUCTURE_DEPTH in done.stderr
    assert "nested.bag: no events" in done.stderr and not (tmp_path / "nested.jsonl").exists()


def test_import_refuses_a_path_longer_than_the_schema_allows_as_replay_does_and_says_why(tmp_path):
    path = "/" + "x" * schema.MAX_PATH
    bag = write_bag(tmp_path / "long.bag", "ros1", container_run("long", {path: (["A"], [("ok", "A", "done")], ["done"])},
                                                                 [(0.0, path, ["A"], ["A"], {})]))
    why = "event.path must be a string of 1 to %d characters" % schema.MAX_PATH
    for done in (cli("import", bag, "-o", tmp_path / "long.jsonl"), cli("replay", bag)):
        assert done.returncode == 2 and why in done.stderr, done.stderr[-2000:]
    assert not (tmp_path / "long.jsonl").exists()


def test_an_event_the_schema_refuses_is_not_written_and_the_rest_are(tmp_path):
    from fsmscope.interop.to_log import write_log

    good = schema.build.log(1, 1.0, None, "m", "/ROOT", "info", "kept")
    told = []
    assert write_log([good, dict(good, seq=-1)], str(tmp_path / "some.jsonl"), told.append) == 1
    assert told == ["an event that does not fit the schema: event.seq must be an integer from 0 to 2^53-1, not an integer"]


def test_a_sqlite3_bag_whose_definitions_rosbag2_marked_unknown_reads_with_ours(tmp_path, noetic_events):
    import sqlite3

    bag = write_bag(tmp_path / "jazzy", "ros2-sqlite3")
    with sqlite3.connect(next(bag.glob("*.db3"))) as db:  # rosbag2 had no definition of smach_msgs' types
        db.execute("UPDATE message_definitions SET encoding = 'unknown', encoded_message_definition = ''")
    assert events_of(bag) == noetic_events
    assert cli("replay", bag, "--no-transcript").returncode == 0
