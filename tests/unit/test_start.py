"""Start (MachineHandle.start, the dashboard's Start button) begins a fresh run of the machine."""

from __future__ import annotations

import fsm
from fsm.control.handle import MachineHandle


class Polite(fsm.State):
    """Services a preempt it finds asked, as SMACH's states are written to."""

    def __init__(self) -> None:
        fsm.State.__init__(self, ["ok", "preempted"])

    def execute(self, ud) -> str:
        if self.preempt_requested():
            self.service_preempt()
            return "preempted"
        return "ok"


def nested_machine() -> fsm.StateMachine:
    """SM_ROOT: INNER (A -> B) -> done."""
    inner = fsm.StateMachine(outcomes=["ok", "preempted"])
    with inner:
        fsm.StateMachine.add("A", Polite(), {"ok": "B"})
        fsm.StateMachine.add("B", Polite(), {"ok": "ok"})
    sm = fsm.StateMachine(outcomes=["done", "preempted"])
    with sm:
        fsm.StateMachine.add("INNER", inner, {"ok": "done", "preempted": "preempted"})
    return sm


def test_a_run_started_after_a_preempt_asked_as_a_state_returned_runs_to_its_end():
    sm = nested_machine()
    handle = MachineHandle(sm, fsm.attach(sm, name="m"), can_start=True)
    events: list[dict] = []
    fsm.attach(sm, events.append)
    sm.execute()
    # A preempt asked of a state just as it returned is never serviced: SMACH keeps the request.
    sm.get_children()["INNER"].get_children()["A"].request_preempt()
    handle.start("me")
    handle.join(10)
    assert [e["outcome"] for e in events if e["kind"] == "terminate" and e["path"] == "/SM_ROOT"] == ["done", "done"]
