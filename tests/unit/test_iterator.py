"""BEHAVIORS.md section G: Iterator loop semantics and set_initial_state."""

import fsm as smach
import pytest

from smach_support import Out, machine, userdata


def _iterator(items, body, outcomes=None, input_keys=(), output_keys=(), label="BODY", contained=None, **kwargs):
    it = smach.Iterator(outcomes=outcomes if outcomes is not None else ["done"], input_keys=list(input_keys),
                        output_keys=list(output_keys), it=items, **kwargs)
    with it:
        smach.Iterator.set_contained_state(label, body, **(contained or {}))
    return it


def _summing_body(stop_at=None):
    def body(ud):
        ud.total = ud.total + ud.it_data
        return "stop" if ud.it_data == stop_at else "next"
    return Out(body, outcomes=["next", "stop"])


def test_iterator_sums_its_items_and_returns_the_exhausted_outcome_mapped_by_its_parent():
    it = _iterator([1, 2, 3], _summing_body(), input_keys=["total"], output_keys=["total"],
                   contained={"loop_outcomes": ["next"]})
    sm = machine(["done"], [("IT", it, {"exhausted": "done"})])
    sm.userdata.total = 0
    assert sm.execute() == "done"
    assert sm.userdata.total == 6


def test_iterator_iterates_in_order_and_stores_each_item_under_it_label():
    seen = []
    it = _iterator(["a", "b", "c"], Out(lambda ud: seen.append(ud.item) or "next", outcomes=["next"]),
                   it_label="item", contained={"loop_outcomes": ["next"]})
    assert it.execute() == "exhausted"
    assert seen == ["a", "b", "c"]
    assert it.userdata.item == "c"


def test_iterator_calls_a_callable_iterable_for_its_items():
    seen = []
    it = _iterator(lambda: (x * 10 for x in range(3)), Out(lambda ud: seen.append(ud.it_data) or "next",
                                                            outcomes=["next"]), contained={"loop_outcomes": ["next"]})
    assert it.execute() == "exhausted"
    assert it.execute() == "exhausted"
    assert seen == [0, 10, 20, 0, 10, 20]


def test_iterator_contained_state_gets_the_raw_container_userdata_without_key_checks():
    seen = []

    def body(ud):
        seen.append((type(ud), ud.undeclared))
        ud.written = True
        return "next"
    it = _iterator([1], Out(body, outcomes=["next"]), contained={"loop_outcomes": ["next"]})
    it.userdata.undeclared = "visible"
    it.execute()
    assert seen == [(smach.UserData, "visible")]
    assert it.userdata.written is True


def test_with_loop_outcomes_every_other_outcome_breaks():
    it = _iterator([1, 2, 3, 4], _summing_body(stop_at=2), outcomes=["stop"], contained={"loop_outcomes": ["next"]})
    it.userdata.total = 0
    assert it.execute() == "stop"
    assert it.userdata.total == 3


def test_with_break_outcomes_every_other_outcome_loops():
    it = _iterator([1, 2, 3, 4], _summing_body(stop_at=3), outcomes=["stop"], contained={"break_outcomes": ["stop"]})
    it.userdata.total = 0
    assert it.execute() == "stop"
    assert it.userdata.total == 6


def test_break_outcome_is_mapped_through_final_outcome_map():
    it = _iterator([1, 2, 3], _summing_body(stop_at=3), outcomes=["stopped"],
                   contained={"break_outcomes": ["stop"], "final_outcome_map": {"stop": "stopped"}})
    it.userdata.total = 0
    assert it.execute() == "stopped"


def test_exhausted_outcome_is_appended_to_the_callers_outcomes_list():
    outcomes = ["done"]
    it = _iterator([], Out("next", outcomes=["next"]), outcomes=outcomes, contained={"loop_outcomes": ["next"]})
    assert outcomes == ["done", "exhausted"]
    assert sorted(it.get_registered_outcomes()) == ["done", "exhausted"]
    assert it.execute() == "exhausted"


def test_custom_exhausted_outcome_is_returned_when_items_run_out():
    it = _iterator([1], Out("next", outcomes=["next"]), outcomes=["empty"], exhausted_outcome="empty",
                   contained={"loop_outcomes": ["next"]})
    assert it.execute() == "empty"


def test_an_exhausted_iterator_maps_its_outcome_through_final_outcome_map():
    it = _iterator([1, 2], Out("next", outcomes=["next"]), outcomes=["done"],
                   contained={"loop_outcomes": ["next"], "final_outcome_map": {"exhausted": "done"}})
    assert it.execute() == "done"


def test_an_exhausted_iterator_maps_its_exhausted_outcome_not_the_last_state_outcome():
    it = _iterator([1, 2], Out("next", outcomes=["next"]), outcomes=["stopped"],
                   contained={"loop_outcomes": ["next"], "final_outcome_map": {"next": "stopped"}})
    assert it.execute() == "exhausted"


def test_transition_callbacks_run_after_each_looping_iteration():
    calls = []
    it = _iterator([1, 2, 3], _summing_body(stop_at=3), outcomes=["stop"], contained={"loop_outcomes": ["next"]})
    it.userdata.total = 0
    it.register_transition_cb(lambda ud, active: calls.append((ud.it_data, active)))
    assert it.execute() == "stop"
    assert calls == [(1, ["BODY"]), (2, ["BODY"])]


def test_termination_callbacks_get_a_string_label_after_output_keys_are_copied():
    calls = []
    it = _iterator([5], Out(lambda ud: setattr(ud, "last", ud.it_data) or "next", outcomes=["next"]),
                   output_keys=["last"], contained={"loop_outcomes": ["next"]})
    parent = smach.UserData()
    it.register_termination_cb(lambda ud, terminal, outcome: calls.append((terminal, outcome, parent.last)))
    assert it.execute(parent) == "exhausted"
    assert calls == [("BODY", "exhausted", 5)]


def test_any_exception_raised_by_the_iterable_counts_as_exhaustion():
    def items():
        yield 1
        raise RuntimeError("iterable broke")
    seen = []
    it = _iterator(items, Out(lambda ud: seen.append(ud.it_data) or "next", outcomes=["next"]),
                   contained={"loop_outcomes": ["next"]})
    assert it.execute() == "exhausted"
    assert seen == [1]


def test_exception_in_the_contained_state_raises_invalid_user_code_error(logs):
    it = _iterator([1], Out(lambda ud: 1 / 0, outcomes=["next"]), contained={"loop_outcomes": ["next"]})
    with pytest.raises(smach.InvalidUserCodeError) as info:
        it.execute()
    assert str(info.value).startswith("Could not execute iterator state 'BODY' of type ")
    assert not it.is_running()


def test_iterator_active_state_is_its_contained_state_only_while_running():
    seen = []
    it = _iterator([1], Out(lambda ud: seen.append(it.get_active_states()) or "next", outcomes=["next"]),
                   contained={"loop_outcomes": ["next"]})
    assert it.get_active_states() == []
    it.execute()
    assert seen == [["BODY"]]
    assert it.get_active_states() == []
    assert it.get_initial_states() == ["BODY"]


def test_shutdown_check_stops_the_iterator_with_the_exhausted_outcome():
    seen = []
    smach.set_shutdown_check(lambda: len(seen) >= 2)
    it = _iterator([1, 2, 3, 4], Out(lambda ud: seen.append(ud.it_data) or "next", outcomes=["next"]),
                   contained={"loop_outcomes": ["next"]})
    assert it.execute() == "exhausted"
    assert seen == [1, 2]


def test_iterator_set_initial_state_merges_userdata():
    it = _iterator([1], Out("next", outcomes=["next"]), contained={"loop_outcomes": ["next"]})
    ud = userdata(x=42)
    it.set_initial_state(["BODY"], ud)
    assert it.userdata.x == 42
    assert it.get_initial_states() == ["BODY"]


def test_iterator_set_initial_state_with_several_states_warns_and_takes_the_first(logs):
    it = _iterator([1], Out("next", outcomes=["next"]), contained={"loop_outcomes": ["next"]})
    ud = userdata(x=1)
    it.set_initial_state(["BODY", "OTHER"], ud)
    assert it.userdata.x == 1
    assert logs.warn == ["Attempting to set initial state to include more than one state, but the Iterator "
                         "container can only have one initial state. Taking the first one."]


def test_iterator_set_initial_state_with_a_wrong_label_warns_and_raises_key_error(logs):
    it = _iterator([1], Out("next", outcomes=["next"]), contained={"loop_outcomes": ["next"]})
    with pytest.raises(KeyError):
        it.set_initial_state(["NOPE"], smach.UserData())
    assert len(logs.warn) == 1


def test_getting_an_unknown_state_from_an_iterator_logs_its_one_state_in_the_singular(logs):
    it = _iterator([1], Out("next", outcomes=["next"]), contained={"loop_outcomes": ["next"]})
    with pytest.raises(KeyError):
        it["NOPE"]
    assert logs.error == ["Attempting to get state 'NOPE' from Iterator container. The only available state is 'BODY'."]


def test_a_wrong_initial_label_is_warned_in_smachs_words(logs):
    it = _iterator([1], Out("next", outcomes=["next"]), contained={"loop_outcomes": ["next"]})
    with pytest.raises(KeyError):
        it.set_initial_state(["NOPE"], smach.UserData())
    assert logs.warn == ["Attempting to set state 'NOPE' as initial state in Iterator container. The only available "
                         "state is 'BODY'."]


def test_an_invalid_user_code_error_from_the_contained_state_is_logged_and_passed_on(logs):
    inner = machine(["done"], [("READ", Out(lambda ud: ud.undeclared), {})])
    it = _iterator([1], inner)
    with pytest.raises(smach.InvalidUserCodeError):
        it.execute()
    assert logs.error[-1] == "Could not execute Iterator state 'BODY'"
