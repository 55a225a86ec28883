"""A leaf of an original StateMachine whose outcome its container's edges tell (each place it leads to
is led to by one of its outcomes) is called with no more than an exception's and an armed
debugger's watch (fsm/observation/original_container.py, ``Watched.leaf``): its events still name
the outcome it returned, a leaf whose edges do not tell it is watched whole, and a debugger armed
while such a leaf runs still holds or forces it as it returns."""

import threading

import fsm
import pytest
from fsm.debugging.debugger import Debugger
from fsmscope.server.testing.polling import wait_for

from parity_support import kit

pytestmark = pytest.mark.timeout(30)


def _steps(events):
    return [(e["kind"], e.get("from"), e.get("outcome"), e.get("to"), e.get("state_outcome"))
            for e in events if e["kind"] in ("transition", "terminate")]


def _watched_run(core, sm):
    core.set_loggers(*[lambda msg: None] * 4)
    events = []
    fsm.attach(sm, events.append)
    outcome = sm.execute()
    return outcome, _steps(events)


def test_the_outcome_a_leaf_returned_is_read_from_the_edges_into_the_next_state_and_out_of_the_machine(core):
    k = kit(core)
    rounds = iter(["again", "on"])
    sm = k.machine(["finished", "stopped"], [
        ("FOO", k.Out(lambda ud: next(rounds), outcomes=["again", "on"]), {"again": "FOO", "on": "BAR"}),
        ("BAR", k.Out("end", outcomes=["end", "stop"]), {"end": "finished", "stop": "stopped"})])
    assert _watched_run(core, sm) == ("finished", [
        ("transition", "FOO", "again", "FOO", None), ("transition", "FOO", "on", "BAR", None),
        ("terminate", None, "finished", None, "end")])


def test_an_outcome_falling_through_to_the_machines_outcome_of_its_name_is_told_too(core):
    k = kit(core)
    sm = k.machine(["done", "aborted"], [("FOO", k.Out("aborted", outcomes=["done", "aborted"]), {})])
    assert _watched_run(core, sm) == ("aborted", [("terminate", None, "aborted", None, "aborted")])


def test_a_leaf_with_two_outcomes_to_one_state_is_told_by_what_it_returned(core):
    k = kit(core)
    sm = k.machine(["done"], [("FOO", k.Out("second", outcomes=["first", "second"]), {"first": "BAR", "second": "BAR"}),
                              ("BAR", k.Out("done"), {})])
    assert _watched_run(core, sm) == ("done", [
        ("transition", "FOO", "second", "BAR", None), ("terminate", None, "done", None, "done")])


def test_a_leaf_with_two_outcomes_ending_the_machine_alike_is_told_by_what_it_returned(core):
    k = kit(core)
    sm = k.machine(["done"], [("FOO", k.Out("second", outcomes=["first", "second"]), {"first": "done", "second": "done"})])
    assert _watched_run(core, sm) == ("done", [("terminate", None, "done", None, "second")])


def _waiting_then_next(core):
    """WAIT (blocks until ``release``) -go-> NEXT -done-> done: both leaves whose outcome the edges tell."""
    k = kit(core)
    entered, release, ran = threading.Event(), threading.Event(), []

    def wait(ud):
        entered.set()
        release.wait(5)
        return "go"

    def record(ud):
        ran.append("NEXT")
        return "done"

    sm = k.machine(["done", "other"], [("WAIT", k.Out(wait, outcomes=["go", "other"]), {"go": "NEXT"}),
                                       ("NEXT", k.Out(record), {})])
    return sm, entered, release, ran


def test_a_pause_armed_while_a_leaf_told_by_the_edges_runs_holds_the_machine_as_that_leaf_returns(core):
    core.set_loggers(*[lambda msg: None] * 4)
    sm, entered, release, ran = _waiting_then_next(core)
    fsm.attach(sm, lambda event: None)
    box = []
    thread = threading.Thread(target=lambda: box.append(sm.execute()), daemon=True)
    thread.start()
    assert entered.wait(5)
    debugger = Debugger(sm)
    debugger.pause()
    release.set()
    wait_for(debugger.holds)
    assert [(h["state"], h["at"], h["outcome"]) for h in debugger.holds()] == [("WAIT", "after", "go")]
    assert ran == []  # held before its container took the transition
    debugger.resume()
    thread.join(5)
    assert box == ["done"] and ran == ["NEXT"]
    debugger.detach()


def test_an_outcome_forced_while_a_leaf_told_by_the_edges_runs_is_taken_and_named_by_its_transition(core):
    core.set_loggers(*[lambda msg: None] * 4)
    sm, entered, release, ran = _waiting_then_next(core)
    events = []
    fsm.attach(sm, events.append)
    box = []
    thread = threading.Thread(target=lambda: box.append(sm.execute()), daemon=True)
    thread.start()
    assert entered.wait(5)
    debugger = Debugger(sm)
    debugger.force("/SM_ROOT/WAIT", "other")
    release.set()
    thread.join(5)
    assert box == ["other"] and ran == []
    assert _steps(events) == [("terminate", None, "other", None, "other")]
    debugger.detach()
