"""BEHAVIORS.md section E: preemption, across every container type."""

import fsm as smach
import pytest

from smach_support import Out, WaitForPreempt, concurrence, machine, preempt_while_running

pytestmark = pytest.mark.timeout(10)


def test_preempt_requested_while_idle_persists_and_preempts_the_first_state_of_the_next_run(logs):
    first = Out("done")
    sm = machine(["done"], [("W1", first, {})])
    sm.request_preempt()
    assert sm.preempt_requested()
    assert sm.execute() == "done"
    assert first.saw_preempt == [True]
    assert logs.info[:2] == ["State machine starting in initial state 'W1' with userdata: \n\t[]",
                             "Preempt requested on state machine before executing the next state."]


def test_serviced_preempt_is_consumed_and_the_next_state_runs_normally(logs):
    first = WaitForPreempt(outcomes=["preempted"])
    second = Out("done")
    sm = machine(["done"], [("W1", first, {"preempted": "W2"}), ("W2", second, {})])
    assert preempt_while_running(sm, first) == "done"
    assert second.saw_preempt == [False]
    assert not sm.preempt_requested()


def test_unserviced_preempt_is_forwarded_to_the_next_state_and_stays_requested(logs):
    first = WaitForPreempt(outcomes=["done"], service=False, result="done")
    second = Out("done")
    sm = machine(["done"], [("W1", first, {"done": "W2"}), ("W2", second, {})])
    assert preempt_while_running(sm, first) == "done"
    assert second.saw_preempt == [True]
    assert ("Last state 'W1' did not service preempt. Preempting next state 'W2' before executing..."
            in logs.info)
    assert sm.preempt_requested()


def test_serviced_preempt_of_the_last_state_is_serviced_by_the_machine(logs):
    leaf = WaitForPreempt(outcomes=["preempted"])
    sm = machine(["preempted"], [("W", leaf, {})])
    assert preempt_while_running(sm, leaf) == "preempted"
    assert not sm.preempt_requested()


def test_concurrence_registering_preempted_returns_it_when_every_child_services_the_preempt(logs):
    a, b = WaitForPreempt(), WaitForPreempt()
    cc = concurrence(["done", "preempted"], "done", [("A", a), ("B", b)])
    assert preempt_while_running(cc, a, b) == "preempted"
    assert "Concurrence serviced preempt." in logs.info
    assert not cc.preempt_requested()


def test_concurrence_without_preempted_maps_its_serviced_children_through_its_outcome_policy(logs):
    a, b = WaitForPreempt(), WaitForPreempt()
    cc = concurrence(["done", "stopped"], "done", [("A", a), ("B", b)],
                     outcome_map={"stopped": {"A": "preempted", "B": "preempted"}})
    assert preempt_while_running(cc, a, b) == "stopped"
    assert "Concurrence serviced preempt." in logs.info
    assert not cc.preempt_requested()


def test_parent_machine_follows_the_registered_outcome_of_a_serviced_concurrence_without_preempted(logs):
    a = WaitForPreempt()
    cc = concurrence(["done"], "done", [("A", a)])
    sm = machine(["done"], [("CC", cc, {})])
    assert preempt_while_running(sm, a) == "done"
    assert not sm.preempt_requested()


def test_concurrence_recalls_unserviced_preempts_and_uses_its_outcome_policy(logs):
    a = WaitForPreempt()
    b = WaitForPreempt(outcomes=["done"], service=False, result="done")
    cc = concurrence(["mapped", "other"], "other", [("A", a), ("B", b)], outcome_map={"mapped": {"B": "done"}})
    assert preempt_while_running(cc, a, b) == "mapped"
    assert logs.warn == ["State 'B' in concurrence did not service preempt."]
    assert not b.preempt_requested()
    assert cc.preempt_requested()


def test_concurrence_preempted_while_idle_starts_its_children_preempted(logs):
    a, b = WaitForPreempt(), WaitForPreempt()
    cc = concurrence(["done", "preempted"], "done", [("A", a), ("B", b)])
    cc.request_preempt()
    assert cc.execute() == "preempted"


def test_child_termination_cb_gets_the_live_outcomes_and_can_preempt_the_others(logs):
    calls = []

    def on_child_done(outcomes):
        calls.append((outcomes, dict(outcomes), cc.get_active_states()))
        return True
    slow = WaitForPreempt()
    cc = concurrence(["done", "other"], "other", [("FAST", Out("done")), ("SLOW", slow)],
                     outcome_map={"done": {"FAST": "done"}}, child_termination_cb=on_child_done)
    assert cc.execute() == "done"
    assert [c[1:] for c in calls] == [({"FAST": "done", "SLOW": None}, ["SLOW"]),
                                      ({"FAST": "done", "SLOW": "preempted"}, [])]
    assert calls[0][0] is calls[1][0]
    assert not cc.preempt_requested()


def test_iterator_stops_after_the_current_item_on_preempt_and_returns_the_mapped_outcome(logs):
    seen = []

    def body(ud):
        seen.append(ud.it_data)
        if ud.it_data == 2:
            it.request_preempt()
        return "next"
    it = smach.Iterator(outcomes=["stopped"], input_keys=[], output_keys=[], it=[1, 2, 3])
    with it:
        smach.Iterator.set_contained_state("BODY", Out(body, outcomes=["next"]), loop_outcomes=["next"],
                                           final_outcome_map={"next": "stopped"})
    assert it.execute() == "stopped"
    assert seen == [1, 2]
    assert not it.preempt_requested()


def test_preempt_propagates_through_state_machine_concurrence_state_machine_to_leaf(logs):
    leaf, sibling = WaitForPreempt(), WaitForPreempt()
    inner = machine(["preempted"], [("LEAF", leaf, {})])
    cc = concurrence(["done", "preempted"], "done", [("SUB", inner), ("SIBLING", sibling)])
    outer = machine(["done", "preempted"], [("CC", cc, {})])
    assert preempt_while_running(outer, leaf, sibling) == "preempted"
    assert [c.preempt_requested() for c in (outer, cc, inner, leaf, sibling)] == [False] * 5


def test_preempt_propagates_through_state_machine_to_iterator_contents(logs):
    body = WaitForPreempt(outcomes=["next"], result="next")
    it = smach.Iterator(outcomes=["preempted"], input_keys=[], output_keys=[], it=[1, 2, 3])
    with it:
        smach.Iterator.set_contained_state("BODY", body, loop_outcomes=["next"], final_outcome_map={"next": "preempted"})
    sm = machine(["preempted", "exhausted"], [("IT", it, {})])
    assert preempt_while_running(sm, body) == "preempted"
    assert logs.info.count("Iterating 1 of [1, 2, 3]") == 1
    assert not any(line.startswith("Iterating 2") for line in logs.info)
    assert not it.preempt_requested()
