"""fsm.logfiles.transcript: the replayed lines are the lines SMACH printed live, word for word."""

import threading

import fsm
import pytest
from fsm.logfiles.log_reader import read_events
from fsm.logfiles.transcript import Transcript, messages, transcript

from recording_support import load_example, record
from smach_support import Out, WaitForPreempt, concurrence, machine


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
        sm = example["build"](0.01, action_seconds=1000)  # the stop (0.03 s) always comes first
        logs.all.clear()
        outcome, _ = record(sm, path)
    finally:
        server.shutdown()
    assert outcome == "preempted"
    # Lines logged by threads that run no container (the action server's done callback logs
    # "Action long_task terminated ..." at debug level) carry no machine: they are not events.
    assert [line for line in _replayed(path) if line[0] != "debug"] == [line for line in logs.all if line[0] != "debug"]
    assert "Concurrent Outcomes: {'ACTION': 'preempted', 'MONITOR': 'invalid'}" in logs.info


def test_a_concurrence_without_a_preempted_outcome_that_services_a_preempt_replays_its_outcomes_line(tmp_path, logs):
    left, right = WaitForPreempt(), WaitForPreempt()
    sm = machine(["done"], [("CC", concurrence(["done"], "done", [("LEFT", left), ("RIGHT", right)]), {"done": "done"})])
    preempter = threading.Thread(target=lambda: left.started.wait(5) and right.started.wait(5) and sm.request_preempt())
    preempter.start()
    path = tmp_path / "run.jsonl"
    logs.all.clear()  # construction lines come before any event
    outcome, _ = record(sm, path)
    preempter.join(5)
    assert outcome == "done"
    # A Concurrence's debug lines of its outcome choice are printed, not sent (fsm.core.log.debug_quiet).
    assert _replayed(path) == [line for line in logs.all if line != ("debug", "SMACH Concurrence determining contained state outcomes.")]
    assert "Concurrent Outcomes: {'LEFT': 'preempted', 'RIGHT': 'preempted'}" in logs.info


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


def _control(action, result="accepted", reason=None, params=None, client="127.0.0.1"):
    return {"v": 1, "seq": 1, "t": 0.0, "run": "r", "machine": "m", "kind": "control", "path": "/SM_ROOT",
            "action": action, "reason": reason, "client": client, "result": result, "params": params or {}}


def _control_line(event):
    [line] = Transcript().lines(event)
    return line.level, line.msg


# The expected texts follow fsmscope/static/transcript.js for a control event:
# `Control ${action}${params} from ${client}${reason}: ${result}`.
@pytest.mark.parametrize("event, expected", [
    (_control("preempt", reason="operator"), ("info", "Control preempt from 127.0.0.1 (operator): accepted")),
    (_control("preempt", result="not running"), ("warn", "Control preempt from 127.0.0.1: refused: not running")),
    (_control("start", client="10.0.0.7"), ("info", "Control start from 10.0.0.7: accepted")),
    (_control("publish", params={"topic": "sm_stop", "delivered": 1}),
     ("info", 'Control publish {"topic":"sm_stop","delivered":1} from 127.0.0.1: accepted')),
    (_control("initial-state", result="no state 'X' in /SM_ROOT", params={"states": ["X"], "userdata": {}}),
     ("warn", 'Control initial-state {"states":["X"],"userdata":{}} from 127.0.0.1: refused: no state \'X\' in /SM_ROOT')),
], ids=["preempt", "refused", "start", "publish", "initial-state"])
def test_a_control_event_reads_as_the_browser_writes_it(event, expected):
    assert _control_line(event) == expected


def test_control_params_are_written_as_javascripts_json_stringify_writes_them():
    params = {"speed": 1.0, "tiny": 1e-7, "huge": 1e21, "big": 12345678901234567890, "name": "café", "b": 1, "2": 2}
    assert _control_line(_control("initial-state", params=params))[1] == (
        'Control initial-state {"2":2,"speed":1,"tiny":1e-7,"huge":1e+21,"big":12345678901234567000,"name":"café",'
        '"b":1} from 127.0.0.1: accepted')


def test_long_control_params_are_cut_at_120_characters_with_an_ellipsis():
    text = _control_line(_control("initial-state", params={"states": ["S" * 200]}))[1]
    assert text == 'Control initial-state {"states":["' + "S" * 108 + '… from 127.0.0.1: accepted'


def test_the_cut_counts_characters_as_javascript_does_two_for_an_emoji():
    text = _control_line(_control("initial-state", params={"states": ["\U0001F600" * 100]}))[1]
    assert text == 'Control initial-state {"states":["' + "\U0001F600" * 54 + '… from 127.0.0.1: accepted'
