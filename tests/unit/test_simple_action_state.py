"""SimpleActionState (API.md §14) against a real SimpleActionServer on a private bus."""

import threading
import time
from types import SimpleNamespace

import fsm as smach
import pytest

from bus_support import serve, until_preempted
from fsmscope.server.testing.polling import wait_for
from fsm.ros.actionlib import GoalStatus
from fsm.ros.simple_action_state import SimpleActionState
from smach_support import Background, machine, userdata


def doubler(bus, servers, name="act"):
    """A server that succeeds with ``{"double": 2 * goal["n"]}`` and records its goals."""
    goals = []

    def execute(goal):
        goals.append(goal)
        server.set_succeeded({"double": 2 * goal["n"]})
    server = serve(bus, servers, execute, name, auto_start=False)
    server.start()
    return goals


def state(bus, **kwargs) -> SimpleActionState:
    kwargs.setdefault("server_wait_timeout", 0.5)
    return SimpleActionState("act", bus=bus, **kwargs)


def test_outcomes_always_include_succeeded_aborted_preempted(bus):
    @smach.cb_interface(outcomes=["partial"])
    def result_cb(ud, status, result):
        return None
    s = state(bus, result_cb=result_cb, outcomes=["extra"])
    assert set(s.get_registered_outcomes()) == {"succeeded", "aborted", "preempted", "extra", "partial"}


def test_goal_succeeds_and_the_result_goes_to_the_result_key(bus, servers):
    goals = doubler(bus, servers)
    ud = userdata()
    assert state(bus, goal={"n": 4}, result_key="res").execute(ud) == "succeeded"
    assert goals == [{"n": 4}] and ud.res == {"double": 8}


def test_goal_comes_from_the_goal_key_and_its_slots(bus, servers):
    goals = doubler(bus, servers)
    ud = userdata(g={"n": 1, "speed": 0}, speed=5)
    assert state(bus, goal_key="g", goal_slots=["speed"]).execute(ud) == "succeeded"
    assert goals == [{"n": 1, "speed": 5}]


def test_default_goal_is_built_from_the_spec_with_slots_set_as_attributes(bus, servers):
    goals = []
    server = serve(bus, servers, lambda goal: (goals.append(goal), server.set_succeeded()))

    class Goal:
        __slots__ = ("x",)
    assert state(bus, action_spec=Goal, goal_slots=["x"]).execute(userdata(x=3)) == "succeeded"
    assert isinstance(goals[0], Goal) and goals[0].x == 3


def test_goal_slot_missing_from_a_slotted_goal_type_is_refused(bus):
    class Goal:
        __slots__ = ("x",)
    with pytest.raises(smach.InvalidStateError, match="Goal slots specified are not valid slots"):
        state(bus, action_spec=Goal, goal_slots=["y"])


def test_callable_goal_is_refused(bus):
    with pytest.raises(smach.InvalidStateError, match="Goal object given to SimpleActionState that IS a function"):
        state(bus, goal=lambda: {})


def test_goal_cb_return_replaces_the_goal(bus, servers):
    goals = doubler(bus, servers)
    s = state(bus, goal_cb=lambda ud, goal: {"n": ud.k}, input_keys=["k"])
    assert s.execute(userdata(k=7)) == "succeeded"
    assert goals == [{"n": 7}]


def test_goal_cb_exception_aborts_without_sending(bus, servers, logs):
    goals = doubler(bus, servers)
    assert state(bus, goal_cb=lambda ud, goal: 1 / 0).execute(userdata()) == "aborted"
    assert goals == [] and logs.error[0].startswith("Could not execute goal callback: ")


def test_result_slots_are_written_to_userdata(bus, servers):
    server = serve(bus, servers, lambda goal: server.set_succeeded(SimpleNamespace(pose=1, error=0.1)))
    ud = userdata()
    assert state(bus, result_slots=["pose", "error"]).execute(ud) == "succeeded"
    assert (ud.pose, ud.error) == (1, 0.1)


def test_result_cb_gets_status_and_result_and_its_outcome_wins(bus, servers):
    server = serve(bus, servers, lambda goal: server.set_aborted("why", "failed"))
    seen = []

    @smach.cb_interface(outcomes=["retry"])
    def result_cb(ud, status, result):
        seen.append((status, result))
        return "retry"
    assert state(bus, result_cb=result_cb).execute(userdata()) == "retry"
    assert seen == [(GoalStatus.ABORTED, "why")]


def test_unregistered_result_cb_outcome_aborts(bus, servers, logs):
    doubler(bus, servers)
    s = state(bus, goal={"n": 1}, result_cb=lambda ud, status, result: "weird")
    assert s.execute(userdata()) == "aborted"
    assert "was not registered with the result_cb_outcomes argument" in logs.error[0]


def test_result_cb_exception_aborts(bus, servers, logs):
    doubler(bus, servers)
    assert state(bus, goal={"n": 1}, result_cb=lambda ud, status, result: 1 / 0).execute(userdata()) == "aborted"
    assert logs.error[0].startswith("Could not execute result callback: ")


def test_aborted_goal_gives_aborted(bus, servers):
    server = serve(bus, servers, lambda goal: server.set_aborted())
    assert state(bus).execute(userdata()) == "aborted"


def test_goal_preempted_by_the_server_itself_gives_aborted(bus, servers):
    server = serve(bus, servers, lambda goal: server.set_preempted())
    assert state(bus).execute(userdata()) == "aborted"


def test_preempt_cancels_the_goal_and_gives_preempted(bus, servers, logs):
    server = serve(bus, servers, lambda goal: until_preempted(server)(goal))
    s = state(bus)
    run = Background(lambda: s.execute(userdata()))
    wait_for(server.is_active)
    s.request_preempt()
    assert run.join(1.0) == "preempted"
    assert not s.preempt_requested()
    assert "Preempt requested on action 'act'" in logs.info
    assert any(line.startswith("Preempt on action 'act' cancelling goal") for line in logs.info)


def test_preempt_before_execute_gives_preempted_without_a_goal(bus, servers, logs):
    goals = doubler(bus, servers)
    s = state(bus, goal={"n": 1})
    s.request_preempt()
    assert s.execute(userdata()) == "preempted"
    assert goals == [] and "Preempting act before sending goal." in logs.info


def test_exec_timeout_cancels_the_goal_and_gives_aborted(bus, servers, logs):
    server = serve(bus, servers, lambda goal: until_preempted(server)(goal))
    t0 = time.monotonic()
    assert state(bus, exec_timeout=0.1).execute(userdata()) == "aborted"
    assert 0.09 < time.monotonic() - t0 < 0.6
    assert "Action act timed out after 0 seconds." in logs.warn


def test_durations_may_be_objects_with_to_sec(bus, servers):
    server = serve(bus, servers, lambda goal: until_preempted(server)(goal))
    assert state(bus, exec_timeout=SimpleNamespace(to_sec=lambda: 0.05)).execute(userdata()) == "aborted"


def test_server_that_never_comes_up_aborts_after_server_wait_timeout(bus, logs):
    t0 = time.monotonic()
    assert state(bus, server_wait_timeout=0.1).execute(userdata()) == "aborted"
    assert 0.09 < time.monotonic() - t0 < 0.6
    assert "Still waiting for action server 'act' to start... is it running?" in logs.warn
    assert "Action server for act is not running." in logs.error


def test_server_that_comes_up_late_is_used(bus, servers):
    threading.Timer(0.05, doubler, (bus, servers)).start()
    assert state(bus, goal={"n": 1}).execute(userdata()) == "succeeded"


def test_preempt_while_waiting_for_the_server_gives_preempted_at_once(bus, logs):
    s = state(bus, server_wait_timeout=10.0)
    run = Background(lambda: s.execute(userdata()))
    wait_for(lambda: logs.warn)
    t0 = time.monotonic()
    s.request_preempt()
    assert run.join(1.0) == "preempted"
    assert time.monotonic() - t0 < 0.5


def test_goal_that_ignores_its_cancel_is_left_after_preempt_timeout(bus, servers, logs):
    release = threading.Event()
    server = serve(bus, servers, lambda goal: (release.wait(2.0), server.set_succeeded()))
    s = state(bus, preempt_timeout=0.1)
    run = Background(lambda: s.execute(userdata()))
    wait_for(server.is_active)
    s.request_preempt()
    assert run.join(1.0) == "preempted"
    assert any("did not end within 0.1 seconds of its cancellation" in line for line in logs.warn)
    release.set()


def test_feedback_reaches_the_feedback_cb(bus, servers):
    def execute(goal):
        for i in range(3):
            server.publish_feedback({"i": i})
        server.set_succeeded()
    server = serve(bus, servers, execute)
    got = []
    assert state(bus, feedback_cb=lambda ud, fb: got.append(fb)).execute(userdata()) == "succeeded"
    assert got == [{"i": 0}, {"i": 1}, {"i": 2}]


def test_feedback_is_emitted_as_an_event_when_observed(bus, servers):
    def execute(goal):
        server.publish_feedback({"distance": 0.12})
        server.publish_feedback(object())
        server.set_succeeded()
    server = serve(bus, servers, execute)
    sm = machine(["succeeded", "aborted", "preempted"], [("MOVE", state(bus), {})])
    events = []
    rep = smach.attach(sm, events.append)
    try:
        assert sm.execute() == "succeeded"
    finally:
        rep.remove_observer(events.append)
    feedback = [e for e in events if e["kind"] == "feedback"]
    assert [(e["path"], e["action"]) for e in feedback] == [("/SM_ROOT/MOVE", "act")] * 2
    assert feedback[0]["feedback"] == {"distance": 0.12}
    assert "$repr" in feedback[1]["feedback"]


def test_preempting_a_state_machine_cancels_the_running_goal(bus, servers):
    server = serve(bus, servers, lambda goal: until_preempted(server)(goal))
    sm = machine(["succeeded", "aborted", "preempted"], [("MOVE", state(bus), {})])
    run = Background(sm.execute)
    wait_for(server.is_active)
    sm.request_preempt()
    assert run.join(1.0) == "preempted"


def test_in_a_state_machine_goal_and_result_slots_go_through_remapping(bus, servers):
    doubler(bus, servers)
    sm = machine(["succeeded", "aborted", "preempted"],
                 [("DOUBLE", state(bus, goal_slots=["n"], result_key="out"), {}, {"n": "count", "out": "result"})])
    sm.userdata.count = 21
    assert sm.execute() == "succeeded"
    assert sm.userdata.result == {"double": 42}
