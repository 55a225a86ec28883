"""fsm.logfiles.summary: outcome, visits and time per state, transitions taken, errors, exit codes."""

import threading
import time

import fsm
import pytest
from fsm.logfiles.log_reader import read_events
from fsm.logfiles.summary import ERROR, FINISHED, INCOMPLETE, summarize

from recording_support import load_example, record
from smach_support import Out, machine


def _ev(seq, t, kind, path="/SM_ROOT", **fields):
    return dict({"v": 1, "seq": seq, "t": t, "run": "r", "machine": "m", "kind": kind, "path": path}, **fields)


STRUCTURE = {"label": "SM_ROOT", "path": "/SM_ROOT", "type": "StateMachine", "container": True, "outcomes": ["done"],
             "initial": ["A"], "children": [], "transitions": [{"from": "A", "outcome": "go", "to": "B"},
                                                              {"from": "B", "outcome": "ok", "to": "done"}]}


def _timed_run():
    """A for 1 s, B for 2 s, A for 3 s, B for 0.5 s, then 'done'."""
    return [_ev(1, 0.0, "structure", root=STRUCTURE),
            _ev(2, 0.0, "start", initial=["A"], active=["A"], userdata={}),
            _ev(3, 1.0, "transition", **{"from": "A", "outcome": "go", "to": "B", "active": ["B"]}),
            _ev(4, 3.0, "transition", **{"from": "B", "outcome": "back", "to": "A", "active": ["A"]}),
            _ev(5, 6.0, "transition", **{"from": "A", "outcome": "go", "to": "B", "active": ["B"]}),
            _ev(6, 6.5, "terminate", last=["B"], outcome="done", active=[])]


def _two_runs_100_s_apart():
    """The timed run (0 to 6.5 s), 100 s of nothing, then a second run from 106.5 to 108 s."""
    return _timed_run() + [
        _ev(7, 106.5, "start", initial=["A"], active=["A"], userdata={}),
        _ev(8, 107.0, "transition", **{"from": "A", "outcome": "go", "to": "B", "active": ["B"]}),
        _ev(9, 108.0, "terminate", last=["B"], outcome="done", active=[])]


def test_foo_bar_counts_visits_and_transitions(tmp_path):
    path = tmp_path / "run.jsonl"
    record(load_example("foo_bar")["build"](), path)
    m = summarize(read_events(path)).to_dict()["machines"]["m"]
    assert (m["status"], m["outcome"], m["runs"]) == (FINISHED, "end", 1)
    assert {s: v["visits"] for s, v in m["states"].items()} == {"/SM_ROOT/FOO": 4, "/SM_ROOT/BAR": 3}
    assert {(t["from"], t["outcome"], t["to"]): t["count"] for t in m["transitions"]} == {
        ("FOO", "outcome1", "BAR"): 3, ("BAR", "outcome1", "FOO"): 3, ("FOO", "outcome2", "end"): 1}


def test_time_in_state_has_total_median_max_and_last():
    states = summarize(_timed_run()).to_dict()["machines"]["m"]["states"]
    assert states["/SM_ROOT/A"]["time"] == {"total": 4.0, "median": 2.0, "max": 3.0, "last": 3.0}
    assert states["/SM_ROOT/B"]["time"] == {"total": 2.5, "median": 1.25, "max": 2.0, "last": 0.5}


def test_a_state_s_last_outcome_is_the_one_it_returned_last():
    states = summarize(_timed_run()).to_dict()["machines"]["m"]["states"]
    assert (states["/SM_ROOT/A"]["last_outcome"], states["/SM_ROOT/B"]["last_outcome"]) == ("go", "done")


def test_a_finished_run_exits_0():
    assert summarize(_timed_run()).exit_code() == 0


def test_a_log_that_ends_mid_run_is_incomplete_and_exits_1():
    summary = summarize(_timed_run()[:-1])
    assert summary.to_dict()["machines"]["m"]["status"] == INCOMPLETE
    assert summary.exit_code() == 1


def test_a_run_ending_in_an_error_lists_it_and_exits_1(tmp_path):
    path = tmp_path / "run.jsonl"

    def boom(ud):
        raise ValueError("boom")
    with pytest.raises(Exception):
        record(machine(["done"], [("BAD", Out(boom, outcomes=["done"]), {})]), path)
    summary = summarize(read_events(path))
    m = summary.to_dict()["machines"]["m"]
    assert m["status"] == ERROR and m["outcome"] is None
    assert [(e["state"], e["exc_type"]) for e in m["errors"]] == [("BAD", "ValueError")]
    assert summary.exit_code() == 1


def test_a_log_without_events_is_unreadable_and_exits_2():
    assert summarize([]).exit_code() == 2


def test_the_text_summary_names_outcome_states_and_transitions():
    text = summarize(_timed_run()).format()
    assert "machine m: finished with outcome 'done'" in text
    assert "/SM_ROOT/A" in text and "A --go--> B  x2" in text and "errors: none" in text


def test_duration_is_the_time_the_runs_took_and_the_idle_time_between_them_is_apart():
    m = summarize(_two_runs_100_s_apart()).to_dict()["machines"]["m"]
    assert (m["runs"], m["duration"], m["idle"]) == (2, 8.0, 100.0)


def test_a_run_still_open_when_the_log_ends_counts_until_its_last_event():
    m = summarize(_two_runs_100_s_apart()[:-1]).to_dict()["machines"]["m"]
    assert (m["status"], m["duration"], m["idle"]) == (INCOMPLETE, 7.0, 100.0)


def test_the_text_summary_gives_the_running_time_and_the_idle_time_between_runs():
    text = summarize(_two_runs_100_s_apart()).format()
    assert "machine m: finished with outcome 'done' after 8.000 s running (2 runs, 9 events, " \
           "100.000 s idle between runs)" in text


def _two_writers(tmp_path):
    """The lines of two processes' runs of one machine "m" (each recorded to its own file)."""
    logs = []
    for i in range(2):
        record(machine(["done"], [("A", Out("go"), {"go": "B"}), ("B", Out("done"), {"done": "done"})]),
               tmp_path / ("w%d.jsonl" % i))
        logs.append((tmp_path / ("w%d.jsonl" % i)).read_text().splitlines())
    return logs


def test_a_log_two_processes_wrote_at_once_is_said_and_not_clean(tmp_path):
    first, second = _two_writers(tmp_path)
    mixed = tmp_path / "mixed.jsonl"
    mixed.write_text("".join(a + "\n" + b + "\n" for a, b in zip(first, second)))
    summary = summarize(read_events(str(mixed)))
    assert summary.machines["m"].interleaved > 0 and summary.exit_code() == 1
    assert "written by two processes at once" in summary.format()


def test_a_log_appended_to_by_a_second_process_is_not_two_writers(tmp_path):
    first, second = _two_writers(tmp_path)
    appended = tmp_path / "appended.jsonl"
    appended.write_text("\n".join(first + second) + "\n")
    summary = summarize(read_events(str(appended)))
    assert summary.machines["m"].interleaved == 0 and summary.exit_code() == 0


class _Waiting(fsm.State):
    """Waits until preempted, services it and returns 'preempted'; ``entered`` is set once it runs."""

    def __init__(self):
        fsm.State.__init__(self, outcomes=["preempted"])
        self.entered = threading.Event()

    def execute(self, ud):
        self.entered.set()
        while not self.preempt_requested():
            time.sleep(0.002)
        self.service_preempt()
        return "preempted"


def _concurrence_that_ends_its_other_child():
    """RUN (Concurrence): FAST returns at once; its child_termination_cb then preempts SLOW, a machine
    waiting in WAIT. Nobody preempts the machine."""
    slow = fsm.StateMachine(outcomes=["preempted"])
    with slow:
        fsm.StateMachine.add("WAIT", _Waiting(), {"preempted": "preempted"})
    run = fsm.Concurrence(outcomes=["done"], default_outcome="done", child_termination_cb=lambda outcomes: True)
    with run:
        fsm.Concurrence.add("FAST", fsm.CBState(lambda ud: "done", outcomes=["done"]))
        fsm.Concurrence.add("SLOW", slow)
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("RUN", run, {"done": "done"})
    return sm


def test_preempts_a_container_made_inside_the_machine_are_not_said_to_be_asked_of_it(tmp_path):
    path = tmp_path / "run.jsonl"
    record(_concurrence_that_ends_its_other_child(), path)
    summary = summarize(read_events(path))
    assert summary.to_dict()["machines"]["m"]["preempts"]["of_machine"] == 0
    [line] = [line for line in summary.format().splitlines() if line.startswith("  preempts:")]
    assert line.startswith("  preempts: none asked of the machine; serviced ")
    assert "requested" not in line


def test_a_preempt_of_the_machine_is_counted_once_however_many_states_serviced_it(tmp_path):
    path = tmp_path / "run.jsonl"
    wait = _Waiting()
    sub = fsm.StateMachine(outcomes=["preempted"])
    with sub:
        fsm.StateMachine.add("WAIT", wait, {"preempted": "preempted"})
    sm = fsm.StateMachine(outcomes=["preempted"])
    with sm:
        fsm.StateMachine.add("SUB", sub, {"preempted": "preempted"})
    threading.Thread(target=lambda: wait.entered.wait(10) and sm.request_preempt()).start()
    record(sm, path)
    summary = summarize(read_events(path))
    preempts = summary.to_dict()["machines"]["m"]["preempts"]
    assert preempts["of_machine"] == 1 and preempts["serviced"] > 1
    assert "  preempts: 1 asked of the machine, serviced %d times" % preempts["serviced"] in summary.format()
