"""A machine of the original SMACH (each branch's core) watched over its life: run again, built
further, attached while it runs, its log functions replaced, observed by an observer that fails."""

import threading

import fsm
import pytest
from fsm.debugging.debugger import Debugger
from fsm.observation import schema
from fsmscope.server.testing.polling import wait_for

from original_support import SCENARIOS, run
from parity_support import Side, kit

pytestmark = pytest.mark.timeout(30)


def quiet(smach):
    smach.set_loggers(*[lambda msg: None] * 4)


def two_states(smach):
    k = kit(smach)
    return k.machine(["done"], [("FOO", k.Out("go"), {"go": "BAR"}), ("BAR", k.Out("done"), {})])


def test_each_execute_of_the_root_is_a_run_of_its_own_described_once(core):
    quiet(core)
    sm, events = two_states(core), []
    fsm.attach(sm, events.append)
    sm.execute()
    sm.execute()
    starts = [e for e in events if e["kind"] == "start"]
    assert len(starts) == 2 and starts[0]["run"] != starts[1]["run"]
    assert [e["kind"] for e in events].count("structure") == 1


def test_a_container_added_after_attach_is_described_and_watched_at_the_next_run(core):
    quiet(core)
    k = kit(core)
    sm, events = two_states(core), []
    fsm.attach(sm, events.append)
    sm.execute()
    with sm:
        core.StateMachine.add("MORE", k.machine(["go"], [("INNER", k.Out("go"), {})]), {"go": "FOO"})
    sm.set_initial_state(["MORE"])
    events.clear()
    assert sm.execute() == "done"
    assert events[0]["kind"] == "structure"
    assert events[0]["root"]["initial"] == ["MORE"]
    assert [c["label"] for c in events[0]["root"]["children"]] == ["FOO", "BAR", "MORE"]
    assert [(e["kind"], e["path"]) for e in events if e["path"] == "/SM_ROOT/MORE"] == [
        ("start", "/SM_ROOT/MORE"), ("terminate", "/SM_ROOT/MORE")]


def test_a_machine_attached_while_it_runs_reports_the_rest_of_the_run_and_the_next_whole(core):
    quiet(core)
    k = kit(core)
    block = k.WaitForPreempt(outcomes=["preempted", "timeout"], service=False, result="timeout")
    sm = k.machine(["done", "preempted"], [("FOO", k.Out("go"), {"go": "BLOCK"}), ("BLOCK", block, {"timeout": "BAR"}),
                              ("BAR", k.Out("done"), {})])
    thread = threading.Thread(target=sm.execute, daemon=True)
    thread.start()
    assert block.started.wait(5)
    events = []
    fsm.attach(sm, events.append)
    block.preempted.set()  # BLOCK returns 'timeout', without a preempt requested
    thread.join(5)
    # BLOCK's execute began before the watch: the outcome that led to BAR is read from the edges.
    assert [(e["kind"], e.get("from"), e.get("outcome"), e.get("to")) for e in events] == [
        ("transition", "BLOCK", "timeout", "BAR"), ("terminate", None, "done", None)]
    events.clear()
    block.preempted.set()
    sm.execute()
    assert [e["kind"] for e in events] == ["structure", "start", "transition", "transition", "terminate"]
    assert all(schema.validate(e) is None for e in events)


def test_log_functions_set_after_attach_are_watched_from_the_next_run_and_still_print(core):
    sm, events, printed = two_states(core), [], []
    fsm.attach(sm, events.append)
    core.set_loggers(*[printed.append] * 4)
    k = kit(core)
    with sm:
        core.StateMachine.add("SAY", k.Out(lambda ud: core.logwarn("low battery") or "done"), {})
    sm.set_initial_state(["SAY"])
    sm.execute()
    assert "low battery" in printed
    assert [(e["level"], e["msg"]) for e in events if e["kind"] == "log"] == [("warn", "low battery")]


def test_an_observer_that_raises_changes_nothing_of_the_run(core, tmp_path, capsys):
    class Broken:
        def __call__(self, event):
            raise RuntimeError("observer broken")

    unwatched = run(core, SCENARIOS["nested"])
    side = Side(core)
    machine = SCENARIOS["nested"](side)
    side.logs.clear()
    fsm.attach(machine, Broken())
    assert machine.execute() == "succeeded"
    assert side.logs == unwatched["logs"]
    assert capsys.readouterr().err.count("RuntimeError: observer broken") == 1  # said once, not per event


def test_fsms_debugger_holds_an_original_machine_through_the_execute_wrappers_gates(core):
    """The seam fsm's containers offer the debugger (fsm/debugging/debugger.py) is the wrapper's: a
    breakpoint before a state of an original machine holds it there, with its condition over the
    userdata, and an outcome forced while holding is taken."""
    quiet(core)
    k = kit(core)
    bar = k.Out("done", outcomes=["done", "failed"])
    sm = k.machine(["done", "failed"], [("FOO", k.Out("go"), {"go": "BAR"}), ("BAR", bar, {})])
    sm.userdata.tries = 2
    events = []
    fsm.attach(sm, events.append)
    debugger = Debugger(sm)
    debugger.set_breakpoints([{"state": "/SM_ROOT/BAR", "at": "before", "outcome": None, "when": "tries > 1"}])
    box = []
    thread = threading.Thread(target=lambda: box.append(sm.execute()), daemon=True)
    thread.start()
    wait_for(debugger.holds)
    assert debugger.holds()[0]["state"] == "BAR"
    debugger.force("/SM_ROOT/BAR", "failed")
    debugger.resume()  # a hold paused the machine (as on fsm): it runs on
    thread.join(5)
    assert box == ["failed"] and bar.saw_preempt == []  # forced before it ran: BAR never ran
    forced = [e for e in events if e["kind"] == "debug" and e["action"] == "forced"]
    assert [(e["state"], e["outcome"], e["returned"]) for e in forced] == [("BAR", "failed", None)]
    debugger.detach()


def test_a_state_that_takes_no_attribute_is_described_and_its_machine_watched(core):
    """SMACH runs any object with its interface; one with ``__slots__`` cannot be hooked: it is in the
    structure, and its container's events still tell the run (the outcome read from the edges)."""
    quiet(core)

    class Slotted:
        __slots__ = ()

        def get_registered_outcomes(self):
            return ("done",)

        def get_registered_input_keys(self):
            return ()

        def get_registered_output_keys(self):
            return ()

        def execute(self, ud):
            return "done"

        def preempt_requested(self):
            return False

    k = kit(core)
    sm = k.machine(["end"], [("SLOT", Slotted(), {"done": "LAST"}), ("LAST", k.Out("end"), {})])
    events = []
    fsm.attach(sm, events.append)
    assert sm.execute() == "end"
    assert [c["label"] for c in events[0]["root"]["children"]] == ["SLOT", "LAST"]
    assert [(e["kind"], e.get("from"), e.get("outcome")) for e in events[1:]] == [
        ("start", None, None), ("transition", "SLOT", "done"), ("terminate", None, "end")]
