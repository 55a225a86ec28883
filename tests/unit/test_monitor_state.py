"""MonitorState (BEHAVIORS.md fact 57): a topic watched with a condition callback."""

import time

import fsm as smach

from fsmscope.server.testing.polling import wait_for
from fsm.ros.monitor_state import MonitorState
from smach_support import Background, machine


def run_monitor(bus, state) -> Background:
    """Run a state (with empty userdata) or a machine in a thread; return once it has subscribed."""
    run = Background(state.execute if isinstance(state, smach.StateMachine) else lambda: state.execute(smach.UserData()))
    wait_for(lambda: "t" in bus.topics())
    return run


def test_outcomes_are_valid_invalid_preempted(bus):
    state = MonitorState("t", dict, lambda ud, msg: True, bus=bus)
    assert set(state.get_registered_outcomes()) == {"valid", "invalid", "preempted"}


def test_false_condition_gives_invalid(bus):
    state = MonitorState("t", dict, lambda ud, msg: msg["ok"], bus=bus)
    run = run_monitor(bus, state)
    bus.publish("t", {"ok": True})
    bus.publish("t", {"ok": False})
    assert run.join(1.0) == "invalid"


def test_valid_after_max_checks_true_results(bus):
    seen = []
    state = MonitorState("t", int, lambda ud, msg: seen.append(msg) or True, max_checks=3, bus=bus)
    run = run_monitor(bus, state)
    for i in range(5):
        bus.publish("t", i)
    assert run.join(1.0) == "valid"
    assert seen == [0, 1, 2]


def test_with_default_max_checks_true_results_keep_monitoring(bus):
    state = MonitorState("t", int, lambda ud, msg: msg < 100, bus=bus)
    run = run_monitor(bus, state)
    for i in range(50):
        bus.publish("t", i)
    time.sleep(0.02)
    assert "t" in bus.topics()
    bus.publish("t", 100)
    assert run.join(1.0) == "invalid"


def test_condition_exception_is_logged_and_gives_invalid(bus, logs):
    def cond(ud, msg):
        raise ValueError("bad message")
    state = MonitorState("t", int, cond, bus=bus)
    run = run_monitor(bus, state)
    bus.publish("t", 1)
    assert run.join(1.0) == "invalid"
    assert any("Error thrown while executing condition callback" in line and "bad message" in line
               for line in logs.error)


def test_preempt_gives_preempted_at_once(bus):
    state = MonitorState("t", int, lambda ud, msg: True, bus=bus)
    run = run_monitor(bus, state)
    t0 = time.monotonic()
    state.request_preempt()
    assert run.join(1.0) == "preempted"
    assert time.monotonic() - t0 < 0.5 and not state.preempt_requested()


def test_preempt_before_execute_gives_preempted_without_subscribing(bus):
    state = MonitorState("t", int, lambda ud, msg: True, bus=bus)
    state.request_preempt()
    assert state.execute(smach.UserData()) == "preempted"
    assert bus.topics() == []


def test_subscribes_on_entry_and_unsubscribes_on_exit(bus):
    state = MonitorState("t", int, lambda ud, msg: False, bus=bus)
    assert bus.topics() == []
    run = run_monitor(bus, state)
    assert bus.topics() == ["t"]
    bus.publish("t", 1)
    run.join(1.0)
    assert bus.topics() == []


def test_condition_reads_and_writes_userdata_in_a_state_machine(bus):
    def cond(ud, msg):
        ud.last = msg
        return msg < ud.limit
    sm = machine(["valid", "invalid", "preempted"],
                 [("WATCH", MonitorState("t", int, cond, input_keys=["limit"], output_keys=["last"], bus=bus), {})])
    sm.userdata.limit = 3
    run = run_monitor(bus, sm)
    for i in range(5):
        bus.publish("t", i)
    assert run.join(1.0) == "invalid"
    assert sm.userdata.last == 3

