"""fsm.transcript: the replayed lines are the lines SMACH printed live, word for word."""

import fsm
from fsm.log_reader import read_events
from fsm.transcript import Transcript, messages, transcript

from recording_support import load_example, record
from smach_support import Out, machine


def _replayed(path):
    return [(line.level, line.msg) for line in messages(read_events(path))]


def test_foo_bar_replays_the_live_log_lines_word_for_word(tmp_path, logs):
    path = tmp_path / "run.jsonl"
    sm = load_example("foo_bar")["build"]()
    logs.all.clear()  # construction lines come before any event
    record(sm, path)
    assert _replayed(path) == logs.all


def test_nested_concurrence_replays_the_live_log_lines_word_for_word(tmp_path, logs):
    example = load_example("nested_monitor")
    server = example["start_action_server"](0.01)
    try:
        path = tmp_path / "run.jsonl"
        sm = example["build"](0.01)
        logs.all.clear()
        outcome, _ = record(sm, path)
    finally:
        server.shutdown()
    assert outcome == "preempted"
    # Lines logged by threads that run no container (the action server's done callback logs
    # "Action long_task terminated ..." at debug level) carry no machine: they are not events.
    assert _replayed(path) == [line for line in logs.all if line[0] != "debug"]
    assert "Concurrent Outcomes: {'ACTION': 'preempted', 'MONITOR': 'invalid'}" in logs.info


def test_termination_line_names_the_state_outcome_behind_a_renamed_container_outcome(tmp_path, logs):
    path = tmp_path / "run.jsonl"
    record(machine(["end"], [("FOO", Out("outcome2"), {"outcome2": "end"})]), path)
    assert ("info", "State machine terminating 'FOO':'outcome2':'end'") in _replayed(path)


def test_a_formatted_line_has_time_path_and_smach_prefix(tmp_path, logs):
    path = tmp_path / "run.jsonl"
    record(load_example("foo_bar")["build"](), path)
    first = next(transcript(read_events(path)))
    time_part, rest = first.split(" ", 1)
    assert len(time_part) == len("12:34:56.789") and time_part[2] == ":"
    assert rest == "/SM_ROOT [  INFO ] : State machine starting in initial state 'FOO' with userdata: \n\t[]"


def test_lines_name_the_machine_once_a_log_holds_two(tmp_path, logs):
    path = tmp_path / "run.jsonl"
    record(machine(["done"], [("A", Out("done"), {})]), path, name="one")
    record(machine(["done"], [("A", Out("done"), {})]), path, name="two")
    lines = list(transcript(read_events(path), with_time=False))
    assert lines[-1] == "two:/SM_ROOT [  INFO ] : State machine terminating 'A':'done':'done'"


def test_log_events_keep_their_level(tmp_path, logs):
    path = tmp_path / "run.jsonl"

    def warn(ud):
        fsm.logwarn("careful")
        return "done"
    record(machine(["done"], [("A", Out(warn, outcomes=["done"]), {})]), path)
    assert ("warn", "careful") in _replayed(path)
