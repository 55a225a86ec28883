"""docs/events.md: the events a run emits through ``smach.attach`` and ``fsm.add_global_hook``."""

import fsm as smach
import fsm.core.log
import pytest
from fsm.observation import introspection

from smach_support import Out, WaitForPreempt, concurrence, machine, preempt_while_running

COMMON = {"v", "seq", "t", "run", "machine", "kind", "path"}


@pytest.fixture
def observe():
    """``observe(container)`` attaches a list observer; every observer is detached after the test."""
    attached = []

    def attach(container, **kwargs):
        events = []
        rep = smach.attach(container, events.append, **kwargs)
        attached.append((rep, events.append))
        return events
    yield attach
    for rep, observer in attached:
        rep.remove_observer(observer)


@pytest.fixture
def nobody_listening(monkeypatch):
    """Hide reporters that other tests left attached, so the global log listener reflects this test alone."""
    monkeypatch.setattr(introspection, "_listening", set())
    monkeypatch.setattr(fsm.core.log, "listener", None)


def _fields(events, expected):
    """The documented fields of each event (extra fields a later schema adds are not compared)."""
    assert len(events) == len(expected)
    return [{k: e.get(k, "<missing>") for k in exp} for e, exp in zip(events, expected)]


def _kinds(events):
    return [(e["kind"], e["path"]) for e in events]


def _writer(key, value, outcome="go"):
    return Out(lambda ud: setattr(ud, key, value) or outcome, outcomes=[outcome], output_keys=[key])


def _nested():
    inner = machine(["ok"], [("LEAF", Out("ok"), {})])
    return machine(["done"], [("FOO", _writer("x", 1), {"go": "SUB"}), ("SUB", inner, {"ok": "done"})])


def test_a_run_emits_structure_start_transition_and_terminate_in_order(observe, logs):
    sm = _nested()
    events = observe(sm)
    assert sm.execute() == "done"
    assert _kinds(events) == [("structure", "/SM_ROOT"), ("start", "/SM_ROOT"),
                              ("transition", "/SM_ROOT"), ("start", "/SM_ROOT/SUB"), ("terminate", "/SM_ROOT/SUB"),
                              ("terminate", "/SM_ROOT")]
    expected = [
        {"initial": ["FOO"], "active": ["FOO"], "userdata": {}},
        {"from": "FOO", "outcome": "go", "to": "SUB", "active": ["SUB"], "changes": {"x": 1}},
        {"initial": ["LEAF"], "active": ["LEAF"], "userdata": {}},
        {"last": ["LEAF"], "outcome": "ok", "active": []},
        {"last": ["SUB"], "outcome": "done", "active": []}]
    assert _fields(events[1:], expected) == expected


def test_every_event_carries_the_common_fields(observe):
    sm = _nested()
    events = observe(sm)
    sm.execute()
    assert all(COMMON <= set(e) for e in events)
    assert {e["v"] for e in events} == {1}
    assert {e["machine"] for e in events} == {"SM_ROOT"}
    assert len({e["run"] for e in events}) == 1
    assert [e["seq"] for e in events] == list(range(events[0]["seq"], events[0]["seq"] + len(events)))


def test_a_rerun_gets_a_new_run_id_and_continues_the_sequence(observe):
    sm = _nested()
    events = observe(sm)
    sm.execute()
    first = len(events)
    sm.execute()
    assert events[first]["kind"] == "start"
    assert events[first]["run"] != events[0]["run"]
    assert events[first]["seq"] == events[first - 1]["seq"] + 1


def test_an_unchanged_machine_is_described_once_across_runs(observe):
    sm = _nested()
    events = observe(sm)
    sm.execute()
    sm.execute()
    assert [e["kind"] for e in events].count("structure") == 1


def test_the_structure_is_sent_again_after_the_tree_changes(observe):
    sm = _nested()
    events = observe(sm)
    sm.execute()
    sm.set_initial_state(["FOO"])
    first = len(events)
    sm.execute()
    assert events[first]["kind"] == "structure"


def test_an_observer_that_joins_later_is_sent_the_structure(observe):
    sm = _nested()
    sm.execute()
    late = observe(sm)
    sm.execute()
    assert late[0]["kind"] == "structure"


def test_structure_describes_the_tree_with_paths_sorted_lists_and_transitions(observe):
    sm = _nested()
    events = observe(sm)
    sm.execute()
    root = events[0]["root"]
    assert {k: root[k] for k in ("label", "path", "type", "container", "outcomes", "initial")} == {
        "label": "SM_ROOT", "path": "/SM_ROOT", "type": "StateMachine", "container": True,
        "outcomes": ["done"], "initial": ["FOO"]}
    foo, sub = root["children"]
    assert foo == {"label": "FOO", "path": "/SM_ROOT/FOO", "type": "Out", "container": False, "outcomes": ["go"],
                   "input_keys": [], "output_keys": ["x"], "remapping": {}, "doc": Out.__doc__}
    assert (sub["path"], sub["children"][0]["path"]) == ("/SM_ROOT/SUB", "/SM_ROOT/SUB/LEAF")
    assert root["transitions"] == [{"from": "FOO", "outcome": "go", "to": "SUB"},
                                   {"from": "SUB", "outcome": "ok", "to": "done"}]
    assert sub["transitions"] == [{"from": "LEAF", "outcome": "ok", "to": None}]


def test_structure_of_a_concurrence_has_its_default_outcome_and_outcome_map(observe):
    cc = concurrence(["both", "d"], "d", [("A", Out("a")), ("B", Out("b"))], outcome_map={"both": {"A": "a", "B": "b"}})
    sm = machine(["both", "d"], [("CC", cc, {})])
    events = observe(sm)
    sm.execute()
    node = events[0]["root"]["children"][0]
    assert (node["type"], node["default_outcome"], node["outcome_map"]) == ("Concurrence", "d",
                                                                             {"both": {"A": "a", "B": "b"}})
    assert node["transitions"] == [{"from": "A", "outcome": "a", "to": "both"}, {"from": "B", "outcome": "b", "to": "both"}]


def test_concurrence_events_report_children_finishing_and_their_outcomes(observe):
    cc = concurrence(["d"], "d", [("A", Out("a")), ("B", Out("b"))])
    sm = machine(["d"], [("CC", cc, {})])
    events = observe(sm)
    sm.execute()
    cc_events = [e for e in events if e["path"] == "/SM_ROOT/CC"]
    expected = [{"initial": ["A", "B"], "active": ["A", "B"], "userdata": {}}]
    assert _fields(cc_events[:1], expected) == expected
    finished = [e for e in cc_events if e["kind"] == "transition"]
    assert sorted(e["from"] for e in finished) == ["A", "B"]
    assert all(e["to"] is None for e in finished)
    assert finished[-1]["active"] == []
    expected = [{"last": ["A", "B"], "outcome": "d", "active": [], "outcomes": {"A": "a", "B": "b"}}]
    assert _fields(cc_events[-1:], expected) == expected


def test_iterator_reports_each_looping_iteration_with_its_item_as_a_userdata_change(observe):
    it = smach.Iterator(outcomes=["done"], input_keys=[], output_keys=[], it=[1, 2])
    with it:
        smach.Iterator.set_contained_state("BODY", Out("next", outcomes=["next"]), loop_outcomes=["next"])
    sm = machine(["done", "exhausted"], [("IT", it, {})])
    events = observe(sm)
    assert sm.execute() == "exhausted"
    steps = [e for e in events if e["path"] == "/SM_ROOT/IT" and e["kind"] in ("userdata", "transition")]
    step = {"from": "BODY", "outcome": "next", "to": "BODY", "active": ["BODY"]}
    expected = [dict(step, changes={"it_data": 1}), dict(step, changes={"it_data": 2})]
    assert _fields(steps, expected) == expected


def test_nested_error_emits_exactly_one_error_event_from_the_innermost_container(observe, logs):
    def boom(ud):
        raise ValueError("boom")
    inner = machine(["ok"], [("BAD", Out(boom, outcomes=["ok"]), {})])
    sm = machine(["done"], [("SUB", inner, {"ok": "done"})])
    events = observe(sm)
    with pytest.raises(smach.InvalidUserCodeError) as info:
        sm.execute()
    errors = [e for e in events if e["kind"] == "error"]
    assert len(errors) == 1
    error = errors[0]
    assert (error["path"], error["state"]) == ("/SM_ROOT/SUB", "BAD")
    assert (error["exc_type"], error["message"], error["wrapped_as"]) == ("ValueError", "boom", type(info.value).__name__)
    assert error["traceback"].startswith("Traceback (most recent call last):")
    assert "ValueError: boom" in error["traceback"]
    terminates = [e for e in events if e["kind"] == "terminate"]
    assert [(e["path"], e["outcome"]) for e in terminates] == [("/SM_ROOT/SUB", None), ("/SM_ROOT", None)]
    assert all(e["error"].startswith("InvalidUserCodeError: ") for e in terminates)


@pytest.mark.timeout(5)
def test_concurrence_child_error_emits_one_error_event(observe, logs):
    cc = concurrence(["d"], "d", [("OK", Out("done")), ("BAD", Out(lambda ud: 1 / 0))])
    sm = machine(["d"], [("CC", cc, {})])
    events = observe(sm)
    with pytest.raises(smach.InvalidUserCodeError):  # the machine wraps the Concurrence's InvalidStateError
        sm.execute()
    errors = [e for e in events if e["kind"] == "error"]
    assert [(e["path"], e["state"], e["exc_type"]) for e in errors] == [("/SM_ROOT/CC", "BAD", "ZeroDivisionError")]
    assert "ZeroDivisionError" in errors[0]["traceback"]


def test_consistency_failure_terminates_without_an_outcome(observe, logs):
    sm = machine(["done"], [("A", Out("done"), {"done": "NOWHERE"})])
    events = observe(sm)
    assert sm.execute() is None
    expected = [{"last": [], "outcome": None, "active": [], "error": "consistency check failed"}]
    assert _fields(events[-1:], expected) == expected


@pytest.mark.timeout(5)
def test_preempt_emits_requested_and_serviced_events(observe, logs):
    wait = WaitForPreempt()
    inner = machine(["preempted"], [("WAIT", wait, {})])
    sm = machine(["preempted"], [("SUB", inner, {})])
    events = observe(sm)
    assert preempt_while_running(sm, wait) == "preempted"
    preempts = [(e["path"], e["phase"]) for e in events if e["kind"] == "preempt"]
    assert preempts[:2] == [("/SM_ROOT", "requested"), ("/SM_ROOT/SUB", "requested")]
    assert ("/SM_ROOT/SUB/WAIT", "serviced") in preempts
    assert preempts[-1] == ("/SM_ROOT", "serviced")


def test_global_hook_sees_every_top_level_machine_but_not_nested_ones():
    seen = []
    first, second = _nested(), machine(["done"], [("A", Out("done"), {})])
    smach.add_global_hook(seen.append)
    try:
        first.execute()
        second.execute()
        first.execute()
    finally:
        smach.remove_global_hook(seen.append)
    assert seen == [first, second, first]
    second.execute()
    assert len(seen) == 3


def test_global_hook_can_attach_before_the_first_event(observe):
    runs = []

    def hook(container):
        runs.append(observe(container))
    sm = _nested()
    smach.add_global_hook(hook)
    try:
        sm.execute()
    finally:
        smach.remove_global_hook(hook)
    assert [(events[0]["kind"], events[-1]["kind"]) for events in runs] == [("structure", "terminate")]


def test_log_events_carry_the_innermost_container_path(observe, logs):
    inner = machine(["ok"], [("LEAF", Out(lambda ud: smach.logwarn("deep") or "ok", outcomes=["ok"]), {})])
    sm = machine(["done"], [("TOP", Out(lambda ud: smach.loginfo("shallow") or "go", outcomes=["go"]), {"go": "SUB"}),
                            ("SUB", inner, {"ok": "done"})])
    events = observe(sm)
    sm.execute()
    assert [(e["path"], e["level"], e["msg"]) for e in events if e["kind"] == "log"] == [
        ("/SM_ROOT", "info", "shallow"), ("/SM_ROOT/SUB", "warn", "deep")]


def test_runtime_start_transition_and_termination_lines_are_not_log_events(observe, logs):
    sm = _nested()
    events = observe(sm)
    sm.execute()
    assert logs.info
    assert [e for e in events if e["kind"] == "log"] == []


def test_without_an_observer_there_are_no_events_and_no_log_listener(nobody_listening):
    seen_listener = []
    sm = machine(["done"], [("A", Out(lambda ud: seen_listener.append(fsm.core.log.listener) or "done"), {})])
    rep = smach.attach(sm)
    sm.execute()
    assert rep.last_seq == 0
    assert seen_listener == [None]
    assert fsm.core.log.listener is None


def test_removing_the_last_observer_clears_the_log_listener(nobody_listening):
    sm = _nested()
    events = []
    rep = smach.attach(sm, events.append)
    assert fsm.core.log.listener is not None
    rep.remove_observer(events.append)
    assert fsm.core.log.listener is None
    sm.execute()
    assert events == []


@pytest.mark.timeout(10)
def test_seq_is_strictly_increasing_across_concurrent_children(observe, logs):
    def chatty(key):
        def body(ud):
            for i in range(50):
                smach.loginfo("%s %d" % (key, i))
                setattr(ud, key, i)
            return "done"
        return Out(body, output_keys=[key])
    cc = concurrence(["d"], "d", [(k, chatty(k)) for k in ("a", "b", "c", "d")])
    events = observe(cc)
    for _ in range(5):
        assert cc.execute() == "d"
    seqs = [e["seq"] for e in events]
    assert len(events) > 5 * 200
    assert all(later > earlier for earlier, later in zip(seqs, seqs[1:]))


def test_an_observer_that_cannot_take_events_is_reported_once_and_the_others_get_every_event(observe, logs, capsys):
    def refuses(event):
        raise ValueError("cannot take %s" % event["kind"])

    sm = _nested()
    smach.attach(sm, refuses, name="picker")
    events = observe(sm)
    try:
        sm.execute()
        sm.execute()
    finally:
        introspection.reporter_of(sm).remove_observer(refuses)
    told = capsys.readouterr().err
    assert told.count("an observer of machine 'picker' failed") == 1
    assert "ValueError: cannot take structure" in told
    assert [e["kind"] for e in events].count("terminate") == 4


def test_a_machine_attached_under_a_name_no_key_or_address_can_hold_is_refused_at_once():
    with pytest.raises(ValueError, match=r"a machine's name must not hold '#'"):
        smach.attach(_nested(), name="task#2")


def _writes_a_huge_int(ud):
    ud.big = 10 ** 5000  # more digits than Python turns into text (4,300)
    return "done"


def test_a_value_that_cannot_be_written_as_text_is_a_marker_and_the_run_ends_as_unobserved(observe):
    unobserved = machine(["done"], [("PUT", Out(_writes_a_huge_int, output_keys=["big"]), {"done": "done"})])
    observed = machine(["done"], [("PUT", Out(_writes_a_huge_int, output_keys=["big"]), {"done": "done"})])
    events = observe(observed)
    assert observed.execute() == unobserved.execute() == "done"
    written = next(e["changes"] for e in events if e["kind"] == "terminate")
    assert written == {"big": {"$repr": "<int of 16610 bits>"}}


class Wordless(Exception):
    def __str__(self):
        raise RuntimeError("no words")


def _raises_wordless(ud):
    raise Wordless()


def test_an_exception_that_cannot_say_what_it_is_ends_the_run_as_it_does_unobserved(observe):
    def run(observed):
        sm = machine(["done"], [("BAD", Out(_raises_wordless), {"done": "done"})])
        events = observe(sm) if observed else []
        with pytest.raises(smach.InvalidUserCodeError) as raised:
            sm.execute()
        return type(raised.value.__cause__), events
    assert run(observed=True)[0] is run(observed=False)[0] is Wordless
    error = next(e for e in run(observed=True)[1] if e["kind"] == "error")
    assert error["exc_type"] == "Wordless" and error["message"] == "<exception str() failed>"


def test_a_value_that_raises_when_looked_at_is_a_marker_and_the_run_ends_as_unobserved(observe):
    class Haunted:
        def __getattr__(self, name):
            raise RuntimeError("no attribute may be read")

    def writes(ud):
        ud.ghost = Haunted()
        return "done"
    sm = machine(["done"], [("A", Out(writes, output_keys=["ghost"]), {"done": "done"})])
    events = observe(sm)
    assert sm.execute() == "done"
    written = next(e["changes"] for e in events if e["kind"] == "terminate")
    assert written == {"ghost": {"$repr": "<unencodable Haunted: RuntimeError>"}}
