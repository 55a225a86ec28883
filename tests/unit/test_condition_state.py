"""ConditionState (BEHAVIORS.md fact 58): a polled condition, with SMACH's max_checks+1 calls."""

import time
from types import SimpleNamespace

import fsm as smach
import pytest

from fsmscope.server.testing.polling import wait_for
from fsm.ros.condition_state import ConditionState
from smach_support import Background, machine


class Counting:
    """A condition that records its calls and returns the next of ``answers`` (False when exhausted)."""

    def __init__(self, *answers):
        self.answers = list(answers)
        self.calls = 0

    def __call__(self, ud):
        self.calls += 1
        return self.answers.pop(0) if self.answers else False


def test_outcomes_are_true_false_preempted():
    assert set(ConditionState(Counting()).get_registered_outcomes()) == {"true", "false", "preempted"}


def test_true_condition_gives_true_on_the_first_call():
    cond = Counting(True)
    assert ConditionState(cond, poll_rate=0.001).execute(smach.UserData()) == "true"
    assert cond.calls == 1


def test_false_condition_is_called_max_checks_plus_one_times():
    cond = Counting()
    assert ConditionState(cond, poll_rate=0.001, max_checks=3).execute(smach.UserData()) == "false"
    assert cond.calls == 4


def test_default_max_checks_of_one_makes_two_calls():
    cond = Counting()
    assert ConditionState(cond, poll_rate=0.001).execute(smach.UserData()) == "false"
    assert cond.calls == 2


def test_condition_turning_true_on_a_later_poll_gives_true():
    cond = Counting(False, False, True)
    assert ConditionState(cond, poll_rate=0.001, max_checks=5).execute(smach.UserData()) == "true"
    assert cond.calls == 3


def test_timeout_gives_false_with_unlimited_checks():
    cond = Counting()
    t0 = time.monotonic()
    assert ConditionState(cond, poll_rate=0.01, timeout=0.1, max_checks=-1).execute(smach.UserData()) == "false"
    assert 0.09 < time.monotonic() - t0 < 0.5
    assert cond.calls >= 1


def test_durations_may_be_objects_with_to_sec():
    cond = Counting()
    poll = SimpleNamespace(to_sec=lambda: 0.001)
    assert ConditionState(cond, poll_rate=poll, max_checks=2).execute(smach.UserData()) == "false"
    assert cond.calls == 3


def test_exception_raises_invalid_user_code_error():
    def cond(ud):
        raise KeyError("nope")
    with pytest.raises(smach.InvalidUserCodeError, match="Error thrown while executing condition callback"):
        ConditionState(cond).execute(smach.UserData())


def test_preempt_during_the_poll_sleep_gives_preempted_at_once():
    cond = Counting()
    state = ConditionState(cond, poll_rate=10.0, max_checks=-1)
    run = Background(lambda: state.execute(smach.UserData()))
    wait_for(lambda: cond.calls == 1)
    t0 = time.monotonic()
    state.request_preempt()
    assert run.join(1.0) == "preempted"
    assert time.monotonic() - t0 < 0.5 and not state.preempt_requested()


def test_cb_interface_keys_are_registered_and_readable_in_a_state_machine():
    @smach.cb_interface(input_keys=["level"])
    def high(ud):
        return ud.level > 5
    sm = machine(["true", "false", "preempted"], [("CHECK", ConditionState(high, poll_rate=0.001), {})])
    sm.userdata.level = 9
    assert sm.execute() == "true"
    sm.userdata.level = 1
    assert sm.execute() == "false"
