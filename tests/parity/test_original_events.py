"""A machine of the original SMACH (each branch's core), watched with ``fsm.attach``: the events it
sends are those of docs/events.md, made from its callbacks and its children's calls."""

import fsm
from fsm.observation import schema
from fsm.observation.status import rebuild


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
    assert [e["changes"] for e in events if e["kind"] == "userdata"] == [{"counter": 1}, {"counter": 2}, {"counter": 3}]
    assert [e["msg"] for e in events if e["kind"] == "log"] == ["counted 1", "counted 2", "counted 3"]
    status = rebuild(events)["SM_ROOT"]
    assert status.outcome == "outcome4" and status.containers["/SM_ROOT"]["userdata"] == {"counter": 3}


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
