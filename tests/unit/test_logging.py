"""BEHAVIORS.md section A: logging format and hooks."""

import threading

import fsm as smach
import pytest

from smach_support import Out, concurrence, machine, userdata


@pytest.mark.parametrize("log_fn, prefix", [
    (smach.loginfo, "[  INFO ] : "),
    (smach.logwarn, "[  WARN ] : "),
    (smach.logdebug, "[ DEBUG ] : "),
    (smach.logerr, "[ ERROR ] : "),
])
def test_default_loggers_print_their_prefix_and_str_of_message(capsys, log_fn, prefix):
    log_fn("hello")
    log_fn(42)
    assert capsys.readouterr().out == prefix + "hello\n" + prefix + "42\n"


def test_debug_messages_are_printed_by_default(capsys):
    smach.logdebug("chatty")
    assert capsys.readouterr().out == "[ DEBUG ] : chatty\n"


def test_set_loggers_positional_order_is_info_warn_debug_error():
    got = []
    smach.set_loggers(lambda m: got.append(("info", m)), lambda m: got.append(("warn", m)),
                      lambda m: got.append(("debug", m)), lambda m: got.append(("error", m)))
    smach.loginfo("i")
    smach.logwarn("w")
    smach.logdebug("d")
    smach.logerr("e")
    assert got == [("info", "i"), ("warn", "w"), ("debug", "d"), ("error", "e")]


def test_set_loggers_reroutes_internal_logs(capsys, logs):
    machine(["done"], [("A", Out("done"), {})]).execute()
    assert "State machine starting in initial state 'A' with userdata: \n\t[]" in logs.info
    assert capsys.readouterr().out == ""


def test_start_line_lists_userdata_keys_after_input_keys_are_copied(logs):
    sm = machine(["done"], [("FOO", Out("done"), {})], input_keys=["a"])
    parent = userdata(a=1)
    sm.execute(parent)
    assert logs.info[0] == "State machine starting in initial state 'FOO' with userdata: \n\t['a']"


def test_transition_line_names_source_outcome_and_target(logs):
    sm = machine(["outcome4"], [("FOO", Out("outcome1"), {"outcome1": "BAR"}),
                                ("BAR", Out("outcome4"), {})])
    sm.execute()
    assert logs.info[1] == "State machine transitioning 'FOO':'outcome1'-->'BAR'"


def test_termination_line_names_last_state_outcome_and_container_outcome(logs):
    sm = machine(["outcome4"], [("FOO", Out("outcome2"), {"outcome2": "outcome4"})])
    assert sm.execute() == "outcome4"
    assert logs.info[-1] == "State machine terminating 'FOO':'outcome2':'outcome4'"


def test_nested_termination_line_shows_child_container_label_and_outcome(logs):
    inner = machine(["out3"], [("LEAF", Out("out3"), {})])
    outer = machine(["out2"], [("L3", inner, {"out3": "out2"})])
    assert outer.execute() == "out2"
    assert logs.info[-2:] == ["State machine terminating 'LEAF':'out3':'out3'",
                              "State machine terminating 'L3':'out3':'out2'"]


@pytest.mark.timeout(5)
def test_concurrence_lines_report_finish_order_then_outcomes_in_add_order(logs):
    b_done = threading.Event()

    def a_waits_for_b(ud):
        assert b_done.wait(5)
        return "fail"

    def note_finish(outcomes):
        if outcomes["B"] is not None:
            b_done.set()
        return False

    cc = concurrence(["ok"], "ok", [("A", Out(a_waits_for_b, outcomes=["fail"])), ("B", Out("done"))],
                     child_termination_cb=note_finish)
    assert cc.execute() == "ok"
    assert logs.info == ["Concurrence starting with userdata: \n\t[]",
                         "Concurrent state 'B' returned outcome 'done' on termination.",
                         "Concurrent state 'A' returned outcome 'fail' on termination.",
                         "Concurrent Outcomes: {'A': 'fail', 'B': 'done'}"]


def _iterator(items, state):
    it = smach.Iterator(outcomes=["done"], input_keys=[], output_keys=[], it=items)
    with it:
        smach.Iterator.set_contained_state("BODY", state, loop_outcomes=["next"])
    return it


def test_iterator_logs_each_item_before_the_contained_state_runs(logs):
    body = Out(lambda ud: smach.loginfo("body %s" % ud.it_data) or "next", outcomes=["next"])
    _iterator([1, 2], body).execute()
    assert logs.info == ["Iterating 1 of [1, 2]", "body 1", "Iterating 2 of [1, 2]", "body 2"]


def test_iterator_line_prints_repr_of_a_callable_iterable(logs):
    def items():
        return [7]
    _iterator(items, Out("next", outcomes=["next"])).execute()
    assert logs.info == ["Iterating 7 of %s" % str(items)]


def test_every_smach_error_logs_class_and_message_when_constructed(logs):
    for cls in (smach.InvalidStateError, smach.InvalidTransitionError,
                smach.InvalidUserCodeError, smach.InvalidConstructionError):
        err = cls("boom")
        assert str(err) == "boom"
    assert logs.error == ["InvalidStateError: boom", "InvalidTransitionError: boom",
                          "InvalidUserCodeError: boom", "InvalidConstructionError: boom"]


def test_consistency_failure_logs_the_error_then_the_failure_line(logs):
    machine(["done"], [("A", Out("done"), {"done": "NOWHERE"})])
    assert len(logs.error) == 2
    assert logs.error[0].startswith("InvalidTransitionError: State machine failed consistency check: ")
    assert logs.error[1] == "Container consistency check failed."
