"""fsm.debugging.Debugger: pause, step, breakpoints and forced outcomes at every container kind."""

import threading
import time

import fsm as smach
import pytest
from fsm.debugging import DebugError, Debugger
from fsm.observation.schema import validate
from fsm.observation.status import rebuild

from smach_support import Background, WaitForPreempt, concurrence, machine


class Gate(smach.State):
    """Counts its runs and returns ``go`` until told to ``stop``; writes the count into userdata ``n``."""

    def __init__(self, outcomes=("go", "stop")):
        smach.State.__init__(self, list(outcomes), output_keys=["n"])
        self.runs = 0
        self.stop = threading.Event()

    def execute(self, ud):
        self.runs += 1
        ud.n = self.runs
        return "stop" if self.stop.is_set() else "go"


def held(debugger, count=1, timeout=5.0):
    """The debugger's holds once there are ``count`` of them."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        holds = debugger.holds()
        if len(holds) >= count:
            return holds
        time.sleep(0.005)
    raise AssertionError("the machine did not hold: %r" % debugger.holds())


def observed(sm):
    events = []
    smach.attach(sm, events.append, name="m")
    return events


def loop_machine():
    """SM_ROOT: A <-> B, each a Gate; 'stop' ends it."""
    a, b = Gate(), Gate()
    sm = machine(["done"], [("A", a, {"go": "B", "stop": "done"}), ("B", b, {"go": "A", "stop": "done"})])
    return sm, a, b


@pytest.fixture
def loop():
    sm, a, b = loop_machine()
    events = observed(sm)
    debugger = Debugger(sm)
    yield sm, a, b, debugger, events
    a.stop.set()
    b.stop.set()
    debugger.detach()


def test_a_paused_machine_holds_the_next_transition_until_resumed(loop):
    sm, a, b, debugger, events = loop
    debugger.pause()
    run = Background(sm.execute)
    [hold] = held(debugger)
    assert (hold["state"], hold["at"], hold["outcome"], hold["reason"]) == ("A", "after", "go", "pause")
    time.sleep(0.05)
    assert (a.runs, b.runs) == (1, 0)  # nothing new while paused
    a.stop.set()
    b.stop.set()
    debugger.resume()
    assert run.join() == "done"


def test_a_pause_hold_says_who_paused_the_machine(loop):
    sm, a, b, debugger, events = loop
    debugger.pause(by="deadman")
    run = Background(sm.execute)
    [hold] = held(debugger)
    assert hold["detail"] == "paused by deadman"
    a.stop.set()
    b.stop.set()
    debugger.resume()
    assert run.join() == "done"


def test_a_step_lets_exactly_one_transition_happen_and_holds_again(loop):
    sm, a, b, debugger, events = loop
    debugger.pause()
    run = Background(sm.execute)
    held(debugger)
    debugger.step()
    time.sleep(0.02)
    [hold] = held(debugger)
    assert (hold["state"], hold["reason"]) == ("B", "step")
    assert (a.runs, b.runs) == (1, 1)
    a.stop.set()
    b.stop.set()
    debugger.resume()
    run.join()


def test_step_is_refused_while_the_machine_runs(loop):
    sm, a, b, debugger, events = loop
    with pytest.raises(DebugError) as info:
        debugger.step()
    assert info.value.problem == "not-paused"


def test_a_breakpoint_before_a_state_holds_before_it_runs(loop):
    sm, a, b, debugger, events = loop
    debugger.set_breakpoints([{"state": "/SM_ROOT/B", "at": "before"}])
    run = Background(sm.execute)
    [hold] = held(debugger)
    assert (hold["state"], hold["at"], hold["detail"]) == ("B", "before", "hit breakpoint before B")
    assert b.runs == 0
    debugger.set_breakpoints([])
    a.stop.set()
    debugger.resume()
    assert run.join() == "done"
    assert b.runs == 1


def test_a_breakpoint_after_a_given_outcome_ignores_the_others(loop):
    sm, a, b, debugger, events = loop
    debugger.set_breakpoints([{"state": "/SM_ROOT/A", "at": "after", "outcome": "stop"}])
    run = Background(sm.execute)
    time.sleep(0.05)
    assert debugger.holds() == []
    a.stop.set()
    [hold] = held(debugger)
    assert (hold["state"], hold["outcome"]) == ("A", "stop")
    debugger.resume()
    assert run.join() == "done"


def test_a_conditional_breakpoint_holds_when_its_condition_on_userdata_holds(loop):
    sm, a, b, debugger, events = loop
    debugger.set_breakpoints([{"state": "/SM_ROOT/B", "at": "after", "when": "n >= 3"}])
    run = Background(sm.execute)
    [hold] = held(debugger)
    assert b.runs == 3
    assert hold["detail"] == "hit breakpoint after B when n >= 3"
    debugger.set_breakpoints([])
    a.stop.set()
    debugger.resume()
    run.join()


def test_a_condition_that_cannot_be_evaluated_holds_and_says_why(loop):
    sm, a, b, debugger, events = loop
    debugger.set_breakpoints([{"state": "/SM_ROOT/A", "at": "before", "when": "missing > 1"}])
    run = Background(sm.execute)
    [hold] = held(debugger)
    assert "there is no userdata key 'missing'" in hold["detail"]
    debugger.set_breakpoints([])
    a.stop.set()
    debugger.resume()
    run.join()


@pytest.mark.parametrize("spec, problem", [
    ({"state": "/SM_ROOT/NOPE"}, "unknown-state"),
    ({"state": "/SM_ROOT/A", "at": "after", "outcome": "nope"}, "unknown-outcome"),
    ({"state": "/SM_ROOT/A", "when": "__import__('os').system('true')"}, "bad-breakpoint"),
    ({"state": "/SM_ROOT/A", "at": "during"}, "bad-breakpoint"),
])
def test_a_breakpoint_that_cannot_be_set_is_refused_and_the_set_is_unchanged(loop, spec, problem):
    sm, a, b, debugger, events = loop
    debugger.set_breakpoints([{"state": "/SM_ROOT/B"}])
    with pytest.raises(DebugError) as info:
        debugger.set_breakpoints([{"state": "/SM_ROOT/A"}, spec])
    assert info.value.problem == problem
    assert "breakpoint 1" in info.value.message
    assert debugger.breakpoints() == [{"state": "/SM_ROOT/B", "at": "before", "outcome": None, "when": None}]


def test_forcing_a_held_outcome_takes_it_at_once(loop):
    sm, a, b, debugger, events = loop
    debugger.pause()
    run = Background(sm.execute)
    held(debugger)
    debugger.force("/SM_ROOT/A", "stop", by="operator")
    debugger.resume()
    assert run.join() == "done"
    assert b.runs == 0
    [forced] = [e for e in events if e["kind"] == "debug" and e["action"] == "forced"]
    assert (forced["state"], forced["outcome"], forced["returned"], forced["by"]) == ("A", "stop", "go", "operator")


def test_forcing_a_running_state_preempts_it_and_its_container_takes_the_forced_outcome():
    waiting = WaitForPreempt(outcomes=("preempted", "succeeded", "aborted"))
    sm = machine(["ok", "failed"], [("WAIT", waiting, {"succeeded": "ok", "aborted": "failed", "preempted": "failed"})])
    events = observed(sm)
    debugger = Debugger(sm)
    run = Background(sm.execute)
    assert waiting.started.wait(5)
    debugger.force("/SM_ROOT/WAIT", "succeeded", by="operator")
    assert run.join() == "ok"
    assert not waiting.preempt_requested()
    [forced] = [e for e in events if e["kind"] == "debug" and e["action"] == "forced"]
    assert (forced["outcome"], forced["returned"]) == ("succeeded", "preempted")
    debugger.detach()


def test_forcing_an_outcome_a_state_does_not_have_is_refused(loop):
    sm, a, b, debugger, events = loop
    with pytest.raises(DebugError) as info:
        debugger.force("/SM_ROOT/A", "nope")
    assert info.value.problem == "unknown-outcome"
    assert "its outcomes: ['go', 'stop']" in info.value.message


def test_forcing_an_inactive_state_is_refused(loop):
    sm, a, b, debugger, events = loop
    with pytest.raises(DebugError) as info:
        debugger.force("/SM_ROOT/B", "stop")
    assert info.value.problem == "not-active"


def test_a_preempt_reaches_a_paused_machine():
    waiting = WaitForPreempt()
    sm = machine(["done", "preempted"], [("A", smach.CBState(lambda ud: "go", outcomes=["go"]), {"go": "W"}),
                                         ("W", waiting, {"preempted": "preempted"})])
    debugger = Debugger(sm)
    debugger.pause()
    run = Background(sm.execute)
    held(debugger)
    sm.request_preempt()
    assert run.join() == "preempted"
    assert debugger.holds() == []
    debugger.detach()


def test_a_step_at_a_container_level_steps_over_what_runs_inside_it():
    inner_a, inner_b = Gate(), Gate()
    inner_b.stop.set()
    sub = machine(["ok"], [("X", inner_a, {"go": "Y", "stop": "ok"}), ("Y", inner_b, {"go": "X", "stop": "ok"})])
    last = Gate()
    last.stop.set()
    sm = machine(["done"], [("SUB", sub, {"ok": "LAST"}), ("LAST", last, {"stop": "done", "go": "done"})])
    debugger = Debugger(sm)
    debugger.pause()
    run = Background(sm.execute)
    [hold] = held(debugger)
    assert (hold["path"], hold["state"]) == ("/SM_ROOT/SUB", "X")
    debugger.step(level="/SM_ROOT")
    time.sleep(0.02)
    [hold] = held(debugger)
    assert (hold["path"], hold["state"], hold["outcome"]) == ("/SM_ROOT", "SUB", "ok")
    assert (inner_a.runs, inner_b.runs, last.runs) == (1, 1, 0)
    debugger.resume()
    assert run.join() == "done"
    debugger.detach()


def test_a_sequence_pauses_and_steps():
    first, second = Gate(), Gate()
    seq = smach.Sequence(outcomes=["done"], connector_outcome="go")
    with seq:
        smach.Sequence.add("FIRST", first, {"stop": "done"})
        smach.Sequence.add("SECOND", second, {"go": "done", "stop": "done"})
    debugger = Debugger(seq)
    debugger.pause()
    run = Background(seq.execute)
    assert held(debugger)[0]["state"] == "FIRST"
    debugger.step()
    time.sleep(0.02)
    assert held(debugger)[0]["state"] == "SECOND"
    debugger.resume()
    assert run.join() == "done"
    debugger.detach()


def test_a_concurrence_holds_each_child_that_returns_while_paused():
    left, right = Gate(("go",)), Gate(("go",))
    cc = concurrence(["done"], "done", [("LEFT", left), ("RIGHT", right)])
    debugger = Debugger(cc)
    debugger.pause()
    run = Background(cc.execute)
    holds = held(debugger, 2)
    assert sorted(h["state"] for h in holds) == ["LEFT", "RIGHT"]
    debugger.step()
    time.sleep(0.02)
    assert len(debugger.holds()) == 1  # one transition, the other child still holds
    debugger.resume()
    assert run.join() == "done"
    debugger.detach()


def test_an_iterator_pauses_between_iterations():
    body = Gate(("go",))
    it = smach.Iterator(outcomes=["done"], input_keys=[], output_keys=[], it=[1, 2, 3], it_label="item",
                        exhausted_outcome="done")
    with it:
        smach.Iterator.set_contained_state("BODY", body, loop_outcomes=["go"])
    debugger = Debugger(it)
    debugger.pause()
    run = Background(it.execute)
    held(debugger)
    assert body.runs == 1
    debugger.step()
    time.sleep(0.02)
    held(debugger)
    assert body.runs == 2
    debugger.resume()
    assert run.join() == "done"
    assert body.runs == 3
    debugger.detach()


def test_every_debug_event_fits_the_schema_and_the_status_follows_them(loop):
    sm, a, b, debugger, events = loop
    debugger.set_breakpoints([{"state": "/SM_ROOT/B", "at": "after", "when": "n >= 2"}], by="me")
    run = Background(sm.execute)
    held(debugger)
    status = rebuild(list(events))["m"].to_dict()
    assert status["debug"]["mode"] == "pause"
    assert [h["state"] for h in status["debug"]["holds"]] == ["B"]
    assert status["debug"]["breakpoints"] == [{"state": "/SM_ROOT/B", "at": "after", "outcome": None, "when": "n >= 2"}]
    debugger.set_breakpoints([])
    a.stop.set()
    debugger.resume()
    run.join()
    assert [validate(e) for e in events if validate(e)] == []
    assert rebuild(events)["m"].to_dict()["debug"]["holds"] == []


def test_an_idle_debugger_leaves_the_containers_unbound(loop):
    sm, a, b, debugger, events = loop
    assert sm._debugger is None
    debugger.pause()
    assert sm._debugger is debugger
    debugger.resume()
    assert sm._debugger is None
