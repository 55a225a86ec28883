"""fsm.observation.status: a start of the root container begins a new run, and the state shows that run only."""

import fsm
import pytest
from fsm.observation.status import Status

SUB = "/SM_ROOT/SUB"


def two_level_machine():
    """SM_ROOT: SUB(A -> B) -> done; B writes SUB's `x`."""
    def write(ud):
        ud.x = ud.x + 1
        return "go"

    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        sub = fsm.StateMachine(outcomes=["ok"])
        sub.userdata.x = 0
        with sub:
            fsm.StateMachine.add("A", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "B"})
            fsm.StateMachine.add("B", fsm.CBState(write, outcomes=["go"], input_keys=["x"], output_keys=["x"]),
                                 {"go": "ok"})
        fsm.StateMachine.add("SUB", sub, {"ok": "done"})
    return sm


@pytest.fixture
def second_run_started():
    """The status after a whole first run and the root's start of a second one."""
    sm = two_level_machine()
    events = []
    reporter = fsm.attach(sm, events.append, name="m")
    try:
        sm.execute()
        first_run = len(events)
        sm.execute()
    finally:
        reporter.remove_observer(events.append)
    root_start = next(i for i, e in enumerate(events) if i >= first_run and e["kind"] == "start")
    status = Status("m")
    for event in events[:root_start + 1]:
        status.apply(event)
    return status


def test_a_root_start_clears_what_containers_reached_in_the_previous_run(second_run_started):
    sub = second_run_started.containers[SUB]
    assert (sub["active"], sub["running"], sub["outcome"]) == ([], False, None)


def test_a_root_start_keeps_the_userdata_and_initial_states_of_other_containers(second_run_started):
    sub = second_run_started.containers[SUB]
    assert sub["userdata"] == {"x": 1} and sub["initial"] == ["A"]
