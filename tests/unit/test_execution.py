"""BEHAVIORS.md section C: StateMachine execution."""

import fsm as smach
import pytest

from smach_support import Out, machine


def test_unmapped_outcome_falls_through_to_container_outcome_of_same_name(logs):
    sm = machine(["outcome1"], [("BAR", Out("outcome1"), {})])
    assert sm.execute() == "outcome1"


def test_target_that_is_not_a_state_falls_back_to_the_outcome_name(logs):
    sm = machine(["outcome1", "other"], [("BAR", Out("outcome1"), {})])
    sm._transitions["BAR"]["outcome1"] = "unknown"  # bypass the consistency check as a late edit would
    sm.check_consistency = lambda: None
    assert sm.execute() == "outcome1"


def test_target_naming_both_a_state_and_a_container_outcome_goes_to_the_state(logs):
    a, b = Out("go"), Out("done")
    sm = machine(["B", "done"], [("A", a, {"go": "B"}), ("B", b, {})])
    assert sm.execute() == "done"
    assert b.runs == 1


@pytest.mark.parametrize("returned", ["weird", None])
def test_undeclared_outcome_raises_invalid_transition_error(logs, returned):
    bad = Out(returned, outcomes=["ok"])
    sm = machine(["ok"], [("BAD", bad, {})])
    with pytest.raises(smach.InvalidTransitionError) as info:
        sm.execute()
    assert str(info.value) == ("Attempted to return outcome '%s' from state 'BAD' of type '%s' which only has "
                               "registered outcomes: ('ok',)" % (returned, bad))


def test_exception_in_a_state_is_wrapped_as_invalid_user_code_error(logs):
    def boom(ud):
        raise ValueError("boom")
    bad = Out(boom, outcomes=["done"])
    sm = machine(["done"], [("BAD", bad, {})])
    with pytest.raises(smach.InvalidUserCodeError) as info:
        sm.execute()
    message = str(info.value)
    assert message.startswith("Could not execute state 'BAD' of type '%s': Traceback (most recent call last):" % bad)
    assert message.rstrip().endswith("ValueError: boom")


def test_invalid_user_code_error_from_deeper_is_reraised_unchanged(logs):
    def boom(ud):
        raise ValueError("boom")
    inner = machine(["done"], [("BAD", Out(boom, outcomes=["done"]), {})])
    outer = machine(["done"], [("INNER", inner, {})])
    with pytest.raises(smach.InvalidUserCodeError) as info:
        outer.execute()
    assert str(info.value).startswith("Could not execute state 'BAD' of type ")
    assert logs.error[-1] == "State 'INNER' failed to execute."
    assert [e for e in logs.error if e.startswith("InvalidUserCodeError: ")] == ["InvalidUserCodeError: " + str(info.value)]


def test_after_a_state_error_the_machine_is_not_running_and_outputs_are_not_copied(logs):
    def write_then_fail(ud):
        ud.out = 1
        raise ValueError("boom")
    sm = machine(["done"], [("BAD", Out(write_then_fail, outcomes=["done"], output_keys=["out"]), {})],
                 output_keys=["out"])
    parent = smach.UserData()
    with pytest.raises(smach.InvalidUserCodeError):
        sm.execute(parent)
    assert not sm.is_running()
    assert "out" not in parent
    assert sm.userdata.out == 1


def test_after_a_state_error_no_state_is_reported_active(logs):
    sm = machine(["done"], [("BAD", Out(lambda ud: 1 / 0, outcomes=["done"]), {})])
    with pytest.raises(smach.InvalidUserCodeError):
        sm.execute()
    assert sm.get_active_states() == ["None"]


def test_active_states_are_the_string_none_before_and_after_execution():
    sm = machine(["done"], [("A", Out("done"), {})])
    assert sm.get_active_states() == ["None"]
    sm.execute()
    assert sm.get_active_states() == ["None"]
    assert sm.get_initial_states() == ["A"]


def test_nested_run_reports_the_child_container_label_outside_and_its_state_inside():
    seen = []
    inner = smach.StateMachine(outcomes=["done"])
    outer = smach.StateMachine(outcomes=["done"])
    with outer:
        with inner:
            smach.StateMachine.add("LEAF", Out(lambda ud: seen.append((outer.get_active_states(),
                                                                       inner.get_active_states())) or "done"))
        smach.StateMachine.add("INNER", inner)
    assert outer.execute() == "done"
    assert seen == [(["INNER"], ["LEAF"])]


def test_start_callback_gets_userdata_and_initial_states_after_the_start_line(logs):
    calls = []
    sm = machine(["done"], [("A", Out("done"), {})])
    sm.register_start_cb(lambda ud, initial, extra: calls.append(
        (ud is sm.userdata, initial, extra, sm.get_active_states(), list(logs.info))), ["x"])
    sm.execute()
    assert calls == [(True, ["A"], "x", ["A"], ["State machine starting in initial state 'A' with userdata: \n\t[]"])]


def test_transition_callback_sees_the_new_active_state_after_the_transition_line(logs):
    calls = []
    sm = machine(["done"], [("A", Out("go"), {"go": "B"}), ("B", Out("done"), {})])
    sm.register_transition_cb(lambda ud, active, extra: calls.append((active, extra, logs.info[-1])), ["x"])
    sm.execute()
    assert calls == [(["B"], "x", "State machine transitioning 'A':'go'-->'B'")]


def test_termination_callback_runs_after_the_termination_line_before_outputs_reach_the_parent(logs):
    calls = []
    inner = smach.StateMachine(outcomes=["done"], output_keys=["out"])
    with inner:
        smach.StateMachine.add("LAST", Out(lambda ud: setattr(ud, "out", 3) or "done", output_keys=["out"]))
    outer = machine(["done"], [("INNER", inner, {})])
    inner.register_termination_cb(lambda ud, terminal, outcome, extra: calls.append(
        (terminal, outcome, extra, inner.get_active_states(), logs.info[-1], "out" in outer.userdata)), ["x"])
    outer.execute()
    assert calls == [(["LAST"], "done", "x", ["None"], "State machine terminating 'LAST':'done':'done'", False)]
    assert outer.userdata.out == 3


def test_no_transition_callback_for_initial_entry_or_termination():
    calls = []
    sm = machine(["done"], [("A", Out("done"), {})])
    sm.register_transition_cb(lambda ud, active: calls.append(active))
    assert sm.execute() == "done"
    assert calls == []


def _failing(*args):
    raise RuntimeError("cb failed")


@pytest.mark.parametrize("kind", ["start", "transition", "termination"])
def test_a_failing_callback_skips_the_rest_of_its_kind_and_execution_continues(logs, kind):
    later = []
    sm = machine(["done"], [("A", Out("go"), {"go": "B"}), ("B", Out("done"), {})])
    register = getattr(sm, "register_%s_cb" % kind)
    register(_failing)
    register(lambda *args: later.append(args))
    assert sm.execute() == "done"
    assert later == []
    assert len(logs.error) == 1
    assert logs.error[0].startswith("Could not execute %s callback: Traceback" % kind)
    assert "RuntimeError: cb failed" in logs.error[0]


def test_userdata_persists_across_runs_of_the_same_machine():
    def count(ud):
        ud.n = ud.n + 1 if "n" in ud else 1
        return "done"
    sm = machine(["done"], [("A", Out(count, io_keys=["n"]), {})])
    assert [sm.execute() for _ in range(3)] == ["done"] * 3
    assert sm.userdata.n == 3


def test_shutdown_check_stops_execute_after_the_start_line_and_callbacks(logs):
    started = []
    a = Out("done")
    sm = machine(["done"], [("A", a, {})])
    sm.register_start_cb(lambda ud, initial: started.append(initial))
    smach.set_shutdown_check(lambda: True)
    assert smach.is_shutdown()
    assert sm.execute() is None
    assert a.runs == 0
    assert started == [["A"]]
    assert logs.info == ["State machine starting in initial state 'A' with userdata: \n\t[]"]


def test_shutdown_check_turning_true_stops_before_the_next_state():
    stop = []
    smach.set_shutdown_check(lambda: bool(stop))
    b = Out("done")
    sm = machine(["done"], [("A", Out(lambda ud: stop.append(1) or "go", outcomes=["go"]), {"go": "B"}),
                            ("B", b, {})])
    assert sm.execute() is None
    assert b.runs == 0


def test_constants_are_written_before_every_execution_of_their_state():
    seen = []

    def use_k(ud):
        seen.append(ud.k)
        ud.k = "changed"
        return "again" if len(seen) < 3 else "done"
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", Out(use_k, outcomes=["again", "done"], io_keys=["k"]), {"again": "A"},
                               constants={"k": 7})
    assert sm.execute() == "done"
    assert seen == [7, 7, 7]


def test_constants_still_need_an_input_key_to_be_read(logs):
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", Out(lambda ud: ud.k), constants={"k": "done"})
    with pytest.raises(smach.InvalidUserCodeError):
        sm.execute()
    assert sm.userdata.k == "done"
