"""fsm.observation.status: a start of the root container begins a new run, and the state shows that run only."""

import fsm
import pytest
from fsm.observation.status import Status
from smach_support import two_level_machine

SUB = "/SM_ROOT/SUB"


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
