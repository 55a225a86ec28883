"""A machine of the original SMACH (each branch's core), watched with ``fsm.attach``: the events it
sends are those of docs/events.md, made from its callbacks and its children's calls."""

import fsm
import pytest
from fsm.observation import schema
from fsm.observation.status import rebuild

from original_support import SCENARIOS, run
from parity_support import kit, normalised


def foo_bar(smach):
    """The tutorial's FOO/BAR loop: FOO counts in userdata and ends the machine on its third run."""

    class Foo(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["outcome1", "outcome2"], input_keys=["counter"], output_keys=["counter"])

        def execute(self, ud):
            ud.counter = ud.counter + 1
            smach.loginfo("counted %d" % ud.counter)
            return "outcome1" if ud.counter < 3 else "outcome2"

    class Bar(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["outcome1"])

        def execute(self, ud):
            return "outcome1"

    sm = smach.StateMachine(outcomes=["outcome4"])
    sm.userdata.counter = 0
    with sm:
        smach.StateMachine.add("FOO", Foo(), transitions={"outcome1": "BAR", "outcome2": "outcome4"})
        smach.StateMachine.add("BAR", Bar(), transitions={"outcome1": "FOO"})
    return sm


def _brief(events):
    return [(e["kind"], e["path"]) + tuple(e.get(k) for k in ("from", "outcome", "to") if k in e) for e in events
            if e["kind"] not in ("structure", "log", "userdata")]


def test_an_original_machine_attached_reports_its_run_as_an_fsm_machine_does(core):
    sm = foo_bar(core)
    events = []
    fsm.attach(sm, events.append)
    assert sm.execute() == "outcome4"
    assert all(schema.validate(e) is None for e in events)
    assert _brief(events) == [
        ("start", "/SM_ROOT"),
        ("transition", "/SM_ROOT", "FOO", "outcome1", "BAR"), ("transition", "/SM_ROOT", "BAR", "outcome1", "FOO"),
        ("transition", "/SM_ROOT", "FOO", "outcome1", "BAR"), ("transition", "/SM_ROOT", "BAR", "outcome1", "FOO"),
        ("terminate", "/SM_ROOT", "outcome4")]
    assert [e["changes"] for e in events if "changes" in e] == [{"counter": 1}, {"counter": 2}, {"counter": 3}]
    assert [e["msg"] for e in events if e["kind"] == "log"] == ["counted 1", "counted 2", "counted 3"]
    status = rebuild(events)["SM_ROOT"]
    assert status.outcome == "outcome4" and status.containers["/SM_ROOT"]["userdata"] == {"counter": 3}


def test_a_step_of_an_original_machine_that_writes_its_userdata_is_one_event_carrying_the_change(core):
    sm = foo_bar(core)
    events = []
    fsm.attach(sm, events.append)
    sm.execute()
    steps = [(e["kind"], e.get("from", e.get("last", [None])[0]), e.get("changes")) for e in events
             if e["kind"] in ("userdata", "transition", "terminate")]
    assert steps == [("transition", "FOO", {"counter": 1}), ("transition", "BAR", None),
                     ("transition", "FOO", {"counter": 2}), ("transition", "BAR", None),
                     ("terminate", "FOO", {"counter": 3})]


def test_the_structure_of_an_original_machine_is_read_from_its_containers(core):
    sm = foo_bar(core)
    events = []
    fsm.attach(sm, events.append)
    sm.execute()
    root = events[0]["root"]
    assert events[0]["kind"] == "structure"
    assert (root["type"], root["initial"], [c["label"] for c in root["children"]]) == ("StateMachine", ["FOO"], ["FOO", "BAR"])
    assert sorted((t["from"], t["outcome"], t["to"]) for t in root["transitions"]) == [
        ("BAR", "outcome1", "FOO"), ("FOO", "outcome1", "BAR"), ("FOO", "outcome2", "outcome4")]
    assert root["children"][0]["input_keys"] == ["counter"]


# The same machines on the original SMACH and on fsm, watched: the same events.

def _by_path(events):
    """Each path's events in order, normalised, without what only says when (seq, t, run): a
    Concurrence's children run on threads of their own, so only the order of one path's events is set.

    A log line's and an error's words are compared up to their first line: past it, the traceback
    that SMACH writes into an InvalidUserCodeError is the runtime's own (its frames, and fsm chains
    the child's exception as the cause of a failed Concurrence's, which the original does not)."""
    paths = {}
    for event in events:
        if event["kind"] == "structure":
            continue
        fields = {k: v.split("\n")[0] if k in ("msg", "error") and isinstance(v, str) else v
                  for k, v in event.items() if k not in ("v", "seq", "t", "run", "machine", "traceback")}
        paths.setdefault(event["path"], []).append(normalised(fields))
    for path, seen in paths.items():  # lines logged by two threads of one Concurrence: in any order
        logs = sorted((e for e in seen if e["kind"] == "log"), key=repr)
        paths[path] = [e for e in seen if e["kind"] != "log"] + logs
    return paths


@pytest.mark.parametrize("scenario", sorted(set(SCENARIOS) - {"raising_grandchild"}))
def test_a_machine_of_the_original_sends_the_events_the_same_machine_sends_on_fsm(core, scenario, tmp_path):
    if scenario == "preempted_concurrence" and "/ros2/" in core.__file__:
        pytest.skip("the ros2 branch's Concurrence, its children's preempt serviced, goes on to its outcome map "
                    "(noetic-devel's and fsm's end 'preempted'): another run, not another way of watching it")
    theirs = run(core, SCENARIOS[scenario], tmp_path / "original.jsonl")["events"]
    ours = run(fsm, SCENARIOS[scenario], tmp_path / "fsm.jsonl")["events"]
    assert _by_path(theirs) == _by_path(ours)
    assert normalised(theirs[0]["root"]) == normalised(ours[0]["root"])


def test_where_the_runtimes_differ_the_events_say_what_each_did(core, tmp_path):
    """A Concurrence child that is a machine and raises: the original's Concurrence then asks it to
    preempt (it preempts every child without an outcome, the failed one too; fsm's skips it), and
    its watched machine says so with a preempt event that fsm's run has not. The rest is the same."""
    theirs = _by_path(run(core, SCENARIOS["raising_grandchild"], tmp_path / "original.jsonl")["events"])
    ours = _by_path(run(fsm, SCENARIOS["raising_grandchild"], tmp_path / "fsm.jsonl")["events"])
    asked = {"kind": "preempt", "path": "/SM_ROOT/CC/SUB", "phase": "requested"}
    assert asked in theirs["/SM_ROOT/CC/SUB"] and asked not in ours["/SM_ROOT/CC/SUB"]
    theirs["/SM_ROOT/CC/SUB"].remove(asked)
    assert theirs == ours


def test_where_userdata_events_differ_from_fsms_a_change_is_a_value_that_differs_not_a_write(core, tmp_path):
    """fsm tracks the keys a state writes; the original's UserData keeps no such record, so a change is
    a value that differs from the last reported one (original_userdata.py). A list appended to in
    place is a change on the original (fsm shows it at the container's next start), and a key written
    with the value it held is none (fsm reports the write)."""

    def scenario(side):
        k = kit(side.sm)

        def append(ud):
            ud.items.append(1)
            return "done"

        def same(ud):
            ud.n = 5
            return "done"

        built = k.machine(["done"], [
            ("APPEND", k.Out(append, io_keys=["items"]), {"done": "SAME"}),
            ("SAME", k.Out(same, output_keys=["n"]), {})])
        built.userdata.items, built.userdata.n = [], 5
        return built

    def changes(sm, log):
        events = run(sm, scenario, tmp_path / log)["events"]
        return [(e["kind"], e.get("from", e.get("last", [None])[0]), e.get("changes")) for e in events
                if e["kind"] in ("userdata", "transition", "terminate")]

    assert changes(core, "original.jsonl") == [("transition", "APPEND", {"items": [1]}), ("terminate", "SAME", None)]
    assert changes(fsm, "fsm.jsonl") == [("transition", "APPEND", None), ("terminate", "SAME", {"n": 5})]
