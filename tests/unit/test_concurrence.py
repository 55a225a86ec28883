"""BEHAVIORS.md section F: Concurrence outcome policy, errors, shared userdata, introspection values."""

import threading

import fsm as smach
import pytest

from fsmscope.server.testing.polling import wait_for
from smach_support import Out, WaitForPreempt, concurrence, machine, userdata

pytestmark = pytest.mark.timeout(10)


def _two(outcome_a, outcome_b, **kwargs):
    return concurrence(kwargs.pop("outcomes", ["x", "y", "d"]), kwargs.pop("default_outcome", "d"),
                       [("A", Out(outcome_a)), ("B", Out(outcome_b))], **kwargs)


def test_no_fully_satisfied_outcome_map_entry_gives_the_default_outcome():
    cc = _two("done", "fail", outcome_map={"x": {"A": "done", "B": "done"}})
    assert cc.execute() == "d"


def test_the_satisfied_outcome_map_entry_with_more_constraints_wins():
    cc = _two("done", "done", outcome_map={"x": {"A": "done"}, "y": {"A": "done", "B": "done"}})
    assert cc.execute() == "y"


def test_on_a_tie_the_first_satisfied_outcome_map_entry_wins():
    cc = _two("done", "done", outcome_map={"x": {"A": "done"}, "y": {"B": "done"}})
    assert cc.execute() == "x"


def test_outcome_cb_gets_a_copy_of_the_outcomes_after_all_children_finish():
    received = []

    def cb(outcomes):
        received.append(dict(outcomes))
        outcomes["A"] = "tampered"
        return "y"
    cc = _two("done", "fail", outcome_cb=cb)
    assert cc.execute() == "y"
    assert received == [{"A": "done", "B": "fail"}]
    assert cc.get_active_states() == []


def test_outcome_cb_returning_none_keeps_the_map_result_with_a_warning(logs):
    cc = _two("done", "done", outcome_map={"x": {"A": "done"}}, outcome_cb=lambda outcomes: None)
    assert cc.execute() == "x"
    assert logs.warn == ["Outcome callback returned None, using outcome 'x'"]


def test_outcome_cb_returning_a_non_string_uses_the_default_outcome(logs):
    cc = _two("done", "done", outcome_map={"x": {"A": "done"}}, outcome_cb=lambda outcomes: 5)
    assert cc.execute() == "d"
    assert logs.error == ["Outcome callback returned a non-string '5', using default outcome 'd'"]


def test_outcome_cb_exception_raises_invalid_user_code_error(logs):
    def cb(outcomes):
        raise RuntimeError("bad cb")
    cc = _two("done", "done", outcome_cb=cb)
    with pytest.raises(smach.InvalidUserCodeError) as info:
        cc.execute()
    assert str(info.value).startswith("Could not execute outcome callback")
    assert "RuntimeError: bad cb" in str(info.value)


@pytest.mark.timeout(5)
def test_child_exception_raises_invalid_state_error_from_execute(logs):
    waiting = WaitForPreempt()
    cc = concurrence(["d"], "d", [("BAD", Out(lambda ud: 1 / 0)), ("WAIT", waiting)])
    with pytest.raises(smach.InvalidStateError) as info:
        cc.execute()
    assert str(info.value) == "A concurrent state raised an exception during execution."
    assert not cc.is_running()


@pytest.mark.timeout(5)
def test_child_exception_logs_the_child_error_with_its_traceback_then_the_concurrence_error(logs):
    def bad(ud):
        raise ValueError("boom")
    cc = concurrence(["d"], "d", [("BOOM", Out(bad))])
    with pytest.raises(smach.InvalidStateError):
        cc.execute()
    child_error, concurrence_error = logs.error
    assert child_error.startswith("InvalidStateError: Could not execute child state 'BOOM': Traceback (most recent call last):")
    assert child_error.endswith("ValueError: boom\n")
    assert concurrence_error == "InvalidStateError: A concurrent state raised an exception during execution."


@pytest.mark.timeout(5)
def test_child_returning_none_ends_the_concurrence_with_an_error_instead_of_hanging(logs):
    cc = concurrence(["d"], "d", [("OK", Out("done")), ("NONE", Out(None, outcomes=["done"]))])
    with pytest.raises(smach.InvalidStateError) as info:
        cc.execute()
    assert "NONE" in str(info.value)


@pytest.mark.timeout(5)
def test_raising_child_termination_cb_ends_the_concurrence_with_an_error(logs):
    def cb(outcomes):
        raise RuntimeError("cb exploded")
    waiting = WaitForPreempt()
    cc = concurrence(["d"], "d", [("A", Out("done")), ("WAIT", waiting)], child_termination_cb=cb)
    with pytest.raises(smach.SmachError) as info:
        cc.execute()
    assert "RuntimeError: cb exploded" in str(info.value)


@pytest.mark.timeout(5)
def test_concurrence_is_reusable_after_a_child_error(logs):
    fail = [True]
    cc = concurrence(["d"], "d", [("A", Out(lambda ud: 1 / 0 if fail[0] else "done")), ("B", Out("done"))])
    with pytest.raises(smach.InvalidStateError):
        cc.execute()
    fail[0] = False
    assert cc.execute() == "d"


def test_child_outcome_is_not_validated_against_its_registered_outcomes(logs):
    cc = _two("weird", "done", outcome_map={"x": {"A": "weird"}})
    assert cc.execute() == "x"
    assert logs.info[-1] == "Concurrent Outcomes: {'A': 'weird', 'B': 'done'}"


def test_concurrence_without_an_outcome_policy_raises(logs):
    with pytest.raises(smach.InvalidStateError) as info:
        smach.Concurrence(outcomes=["a"], default_outcome=None)
    assert str(info.value) == "Concurrence requires an outcome policy"


def test_unregistered_default_outcome_raises(logs):
    with pytest.raises(smach.InvalidStateError) as info:
        smach.Concurrence(outcomes=["a"], default_outcome="zz", outcome_map={"a": {}})
    assert str(info.value) == "Errors specifying outcome policy of concurrence: \n\tDefault outcome 'zz' is unregistered."


def test_executing_an_empty_concurrence_raises(logs):
    cc = smach.Concurrence(outcomes=["a"], default_outcome="a")
    with pytest.raises(smach.InvalidStateError) as info:
        cc.execute()
    assert str(info.value) == "No states was added to concurrence"


def test_outcome_map_naming_an_outcome_the_child_lacks_is_logged_at_close(logs):
    concurrence(["a"], "a", [("A", Out("done"))], outcome_map={"a": {"A": "nope"}})
    assert logs.error[0].startswith("InvalidTransitionError: Outcome map in SMACH Concurrence references a state "
                                    "outcome that does not exist. Requested state outcome: 'nope'")
    assert logs.error[1] == "Container consistency check failed."


def test_children_share_the_concurrence_userdata_through_their_remappings():
    def writer(key, value):
        return Out(lambda ud: setattr(ud, "out", value) or "done", output_keys=["out"])
    cc = concurrence(["d"], "d", [("A", writer("r1", 11), {"out": "r1"}), ("B", writer("r2", 12), {"out": "r2"})],
                     output_keys=["r1", "r2"])
    parent = smach.UserData()
    assert cc.execute(parent) == "d"
    assert (cc.userdata.r1, cc.userdata.r2) == (11, 12)
    assert (parent.r1, parent.r2) == (11, 12)


def test_concurrence_output_keys_reach_the_parent_after_termination_callbacks():
    seen = []
    cc = concurrence(["d"], "d", [("A", Out(lambda ud: setattr(ud, "r", 1) or "done", output_keys=["r"]))],
                     output_keys=["r"])
    sm = machine(["d"], [("CC", cc, {})])
    cc.register_termination_cb(lambda ud, terminal, outcome: seen.append((terminal, outcome, "r" in sm.userdata)))
    assert sm.execute() == "d"
    assert seen == [(["A"], "d", False)]
    assert sm.userdata.r == 1


def test_concurrence_initial_states_are_all_children_and_idle_active_states_are_empty():
    cc = _two("done", "done")
    assert cc.get_initial_states() == ["A", "B"]
    assert cc.get_active_states() == []
    cc.execute()
    assert cc.get_active_states() == []


def test_concurrence_set_initial_state_merges_userdata():
    cc = _two("done", "done")
    ud = userdata(x=42)
    cc.set_initial_state(["A", "B"], ud)
    assert cc.userdata.x == 42
    assert cc.get_initial_states() == ["A", "B"]


def test_concurrence_start_line_lists_the_copied_input_keys(logs):
    cc = concurrence(["d"], "d", [("A", Out("done"))], input_keys=["k"])
    parent = userdata(k=1)
    cc.execute(parent)
    assert logs.info[0] == "Concurrence starting with userdata: \n\t['k']"


def test_concurrence_does_not_start_a_thread_per_child_per_execution(logs):
    labels = "ABCD"
    cc = concurrence(["d"], "d", [(label, Out("done")) for label in labels])
    for _ in range(10):  # warm the worker pool up
        cc.execute()
    before = threading.active_count()
    for _ in range(50):
        assert cc.execute() == "d"
    # A thread per child per run would add 150. The shared pool may add a spare worker when a
    # back-to-back run arrives before the last workers are idle again, never one per run.
    assert threading.active_count() - before < len(labels)


def test_shutdown_check_stops_the_concurrence_waiting_for_its_children(logs):
    stuck_started, release = threading.Event(), threading.Event()
    smach.set_shutdown_check(lambda: True)
    # A returns only once STUCK runs on a worker thread, so the caller cannot take STUCK back.
    first = Out(lambda ud: stuck_started.wait(5) and "done")
    blocked = Out(lambda ud: stuck_started.set() or (release.wait(5) and "done"))
    cc = concurrence(["d"], "d", [("A", first), ("STUCK", blocked)])
    try:
        assert cc.execute() == "d"
        assert not cc.is_running()
    finally:
        release.set()
        # STUCK's worker then finishes it and logs that the run stopped waiting: not into the next test's lines.
        wait_for(lambda: cc._pending == 0, 5, what="STUCK's worker to finish")


def test_a_run_logs_smachs_debug_lines_when_it_stops_waiting_and_while_it_picks_the_mapped_outcome(logs):
    cc = _two("done", "done", outcome_map={"x": {"A": "done", "B": "done"}, "y": {"A": "done"}})
    assert cc.execute() == "x"
    assert logs.debug == ["SMACH Concurrence preempting running states.",
                          "SMACH Concurrence determining contained state outcomes.",
                          "Terminating concurrent split with mapped outcome.",
                          "Skipping mapped outcome 'y' with fewer constraints."]
