"""BEHAVIORS.md section B: StateMachine construction (plus Sequence, add_auto, constants)."""

import ast
import threading
import traceback

import fsm as smach
import pytest
from fsm.core.container import Container

from smach_support import Out, machine


def _consistency_parts(message):
    """Split a consistency message into its error lines and its (unordered) available states."""
    head, tail = message.split("\n\n\tAvailable states: ")
    prefix = "State machine failed consistency check: "
    assert head.startswith(prefix)
    return head[len(prefix):], set(ast.literal_eval(tail))


def test_first_added_state_is_the_initial_state():
    sm = machine(["done"], [("A", Out("done"), {}), ("B", Out("done"), {})])
    assert sm.get_initial_states() == ["A"]


def test_set_initial_state_overrides_the_first_added_state():
    a, b = Out("done"), Out("done")
    sm = machine(["done"], [("A", a, {}), ("B", b, {})])
    sm.set_initial_state(["B"])
    assert sm.get_initial_states() == ["B"]
    assert sm.execute() == "done"
    assert (a.runs, b.runs) == (0, 1)


def test_add_fills_unmapped_outcomes_with_none_in_the_callers_dict():
    transitions = {"outcome1": "BAR"}
    sm = smach.StateMachine(outcomes=["outcome2"])
    with sm:
        smach.StateMachine.add("FOO", Out("outcome1", outcomes=["outcome1", "outcome2"]), transitions)
        smach.StateMachine.add("BAR", Out("outcome2"))
    assert transitions == {"outcome1": "BAR", "outcome2": None}
    assert ("outcome2", "FOO", None) in sm.get_internal_edges()


def test_add_keeps_the_callers_transitions_dict_object():
    transitions = {}
    sm = smach.StateMachine(outcomes=["done", "other"])
    with sm:
        smach.StateMachine.add("FOO", Out("done"), transitions)
    transitions["done"] = "other"
    assert ("done", "FOO", "other") in sm.get_internal_edges()


def test_transition_key_that_is_not_a_registered_outcome_raises_at_add(logs):
    sm = smach.StateMachine(outcomes=["done"])
    with pytest.raises(smach.InvalidTransitionError) as info:
        with sm:
            smach.StateMachine.add("BAR", Out("outcome1"), {"nope": "done"})
    assert str(info.value) == ("Specified outcome 'nope' on state 'BAR', which only has available "
                               "registered outcomes: ('outcome1',)")


def test_duplicate_label_raises_invalid_state_error(logs):
    sm = smach.StateMachine(outcomes=["done"])
    with pytest.raises(smach.InvalidStateError) as info:
        with sm:
            smach.StateMachine.add("BAR", Out("done"))
            smach.StateMachine.add("BAR", Out("done"))
    assert str(info.value) == ('Attempting to add state with label "BAR" to state machine, '
                               'but this label is already being used.')


def test_add_with_no_open_container_raises_invalid_state_error(logs):
    with pytest.raises(smach.InvalidStateError) as info:
        smach.StateMachine.add("BAR", Out("done"))
    assert str(info.value) == "Attempting to access the currently opened container, but no container is opened."


def test_consistency_failure_at_with_exit_is_logged_not_raised(logs):
    sm = machine(["done"], [("A", Out("done"), {"done": "NOWHERE"})])
    errors, available = _consistency_parts(logs.error[0][len("InvalidTransitionError: "):])
    assert errors == "\n\tState 'A' references unknown states: ['NOWHERE']"
    assert available == {"A", "done"}
    assert logs.error[1] == "Container consistency check failed."
    assert sm.get_initial_states() == ["A"]


def test_execute_returns_none_after_a_consistency_failure(logs):
    sm = machine(["done"], [("A", Out("done"), {"done": "NOWHERE"})])
    del logs.error[:]
    assert sm.execute() is None
    assert logs.error[-1] == "Container consistency check failed."
    assert logs.error[0].startswith("InvalidTransitionError: State machine failed consistency check: ")
    assert logs.info == []


def test_consistency_reports_a_machine_with_no_initial_state(logs):
    sm = smach.StateMachine(outcomes=["done"])
    assert sm.execute() is None
    assert logs.error == ["InvalidTransitionError: State machine failed consistency check: "
                          "\n\tNo initial state set.\n\n\tAvailable states: ['done']",
                          "Container consistency check failed."]


def test_consistency_reports_an_initial_label_that_is_not_a_state(logs):
    sm = machine(["done"], [("A", Out("done"), {})])
    sm.set_initial_state(["X"])
    assert sm.execute() is None
    errors, available = _consistency_parts(logs.error[-2][len("InvalidTransitionError: "):])
    assert errors == "\n\tInitial state label: 'X' is not in the state machine."
    assert available == {"A", "done"}


@pytest.mark.parametrize("target", [None, ""])
def test_consistency_requires_an_implicit_target_to_be_a_container_outcome(logs, target):
    sm = machine(["done"], [("A", Out("x", outcomes=["x"]), {"x": target})])
    assert sm.execute() is None
    errors, _ = _consistency_parts(logs.error[-2][len("InvalidTransitionError: "):])
    assert errors == "\n\tState 'A' references unregistered outcomes: ['x']"


def test_consistency_gathers_every_error_into_one_message(logs):
    sm = machine(["done"], [("A", Out("x", outcomes=["x", "y"]), {"y": "NOWHERE"})])
    sm.set_initial_state(["Z"])
    assert sm.execute() is None
    errors, available = _consistency_parts(logs.error[-2][len("InvalidTransitionError: "):])
    assert errors == ("\n\tInitial state label: 'Z' is not in the state machine."
                      "\n\tState 'A' references unknown states: ['NOWHERE']"
                      "\n\tState 'A' references unregistered outcomes: ['x']")
    assert available == {"A", "done"}


def test_exception_inside_with_closes_the_container_and_propagates(logs):
    broken = smach.StateMachine(outcomes=["done"])
    with pytest.raises(ValueError):
        with broken:
            smach.StateMachine.add("A", Out("done"))
            raise ValueError("user bug")
    assert Container._construction_stack == []
    assert not broken.is_opened()
    sm = machine(["done"], [("B", Out("done"), {})])
    assert sm.execute() == "done"


def test_exception_inside_with_releases_the_global_construction_lock(logs):
    with pytest.raises(ValueError):
        with smach.StateMachine(outcomes=["done"]):
            raise ValueError("user bug")
    acquired = []

    def other_thread():
        acquired.append(Container._construction_lock.acquire(timeout=1))
        if acquired[0]:
            Container._construction_lock.release()
    t = threading.Thread(target=other_thread)
    t.start()
    t.join(2)
    assert acquired == [True]


def test_user_exception_inside_with_logs_the_construction_traceback(logs):
    with pytest.raises(ValueError):
        with smach.StateMachine(outcomes=["done"]):
            raise ValueError("user bug")
    assert len(logs.error) == 1
    assert logs.error[0].startswith("Error raised during SMACH container construction: \n")
    assert "ValueError: user bug" in logs.error[0]


def test_the_construction_traceback_is_joined_with_newlines_as_smach_does(logs):
    error = ValueError("user bug")
    with pytest.raises(ValueError):
        with smach.StateMachine(outcomes=["done"]):
            raise error
    assert logs.error == ["Error raised during SMACH container construction: \n"
                          + "\n".join(traceback.format_exception(ValueError, error, error.__traceback__))]


def test_smach_exception_inside_with_logs_no_construction_traceback(logs):
    with pytest.raises(smach.InvalidStateError):
        with smach.StateMachine(outcomes=["done"]):
            smach.StateMachine.add("A", Out("done"))
            smach.StateMachine.add("A", Out("done"))
    assert not any(e.startswith("Error raised during SMACH container construction") for e in logs.error)


def test_with_as_binds_none():
    sm = smach.StateMachine(outcomes=["done"])
    with sm as bound:
        smach.StateMachine.add("A", Out("done"))
    assert bound is None


def test_add_auto_links_connector_outcomes_to_the_next_added_state_overriding_explicit_ones():
    a, b = Out("next", outcomes=["next", "fail"]), Out("done")
    sm = smach.StateMachine(outcomes=["done", "fail"])
    with sm:
        smach.StateMachine.add_auto("A", a, ["next"], transitions={"next": "done"})
        smach.StateMachine.add("B", b)
    assert ("next", "A", "B") in sm.get_internal_edges()
    assert ("fail", "A", None) in sm.get_internal_edges()
    assert sm.execute() == "done"
    assert (a.runs, b.runs) == (1, 1)


def test_add_auto_with_an_unregistered_connector_outcome_raises(logs):
    with pytest.raises(smach.InvalidStateError) as info:
        with smach.StateMachine(outcomes=["done"]):
            smach.StateMachine.add_auto("L", Out("done"), ["nope"])
    assert str(info.value) == ("Attempting to auto-connect states with outcomes ['nope'], "
                               "but state 'L' only has registerd outcomes: ('done',)")


def test_sequence_links_each_state_to_the_next_by_the_connector_outcome():
    order = []
    seq = smach.Sequence(outcomes=["succeeded"], connector_outcome="succeeded")
    with seq:
        for label in ("S1", "S2", "S3"):
            smach.Sequence.add(label, Out(lambda ud, label=label: order.append(label) or "succeeded",
                                          outcomes=["succeeded"]))
    assert seq.execute() == "succeeded"
    assert order == ["S1", "S2", "S3"]


def test_sequence_keeps_an_explicit_connector_transition_and_last_state_falls_through(logs):
    order = []

    def step(label):
        return Out(lambda ud: order.append(label) or "succeeded", outcomes=["succeeded"])
    seq = smach.Sequence(outcomes=["succeeded"], connector_outcome="succeeded")
    with seq:
        smach.Sequence.add("S1", step("S1"), transitions={"succeeded": "S3"})
        smach.Sequence.add("S2", step("S2"))
        smach.Sequence.add("S3", step("S3"))
    edges = seq.get_internal_edges()
    assert ("succeeded", "S1", "S3") in edges
    assert ("succeeded", "S2", "S3") in edges
    assert ("succeeded", "S3", None) in edges
    assert seq.execute() == "succeeded"
    assert order == ["S1", "S3"]
    assert logs.info[-1] == "State machine terminating 'S3':'succeeded':'succeeded'"


def test_a_sequence_state_without_the_connector_outcome_is_logged_at_add_and_the_sequence_still_runs(logs):
    seq = smach.Sequence(outcomes=["done", "next"], connector_outcome="next")
    with seq:
        smach.Sequence.add("S1", Out("done"))
        smach.Sequence.add("S2", Out("done"))
    assert logs.error == ["InvalidTransitionError: Specified outcome 'next' on state 'S1', which only has available "
                          "registered outcomes: ('done',)", "Attempting to construct smach state sequence failed."]
    assert seq.execute() == "done"
    assert logs.error[2:] == []


def test_sequence_with_remapping_passes_userdata_between_states():
    seq = smach.Sequence(outcomes=["succeeded"], connector_outcome="succeeded", output_keys=["result"])
    with seq:
        smach.Sequence.add("PUT", Out(lambda ud: setattr(ud, "x", 5) or "succeeded", outcomes=["succeeded"],
                                      output_keys=["x"]), remapping={"x": "shared"})
        smach.Sequence.add("GET", Out(lambda ud: setattr(ud, "out", ud.y * 2) or "succeeded",
                                      outcomes=["succeeded"], input_keys=["y"], output_keys=["out"]),
                           remapping={"y": "shared", "out": "result"})
    parent = smach.UserData()
    assert seq.execute(parent) == "succeeded"
    assert parent.result == 10
