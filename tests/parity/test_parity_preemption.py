"""BEHAVIORS.md section E, the original SMACH and fsm side by side: preemption.

Not compared: a Concurrence preempted while idle (fsm starts its children preempted; the original
runs them unpreempted and answers 'preempted' after they finish, so a child that waits for its
preempt hangs it): one test below shows the difference with children that do not wait."""

import threading

import pytest

from parity_support import kit, outcome_of

pytestmark = pytest.mark.timeout(20)


def outcome_of_in_thread(fn):
    """Starts ``fn`` in a thread; the returned function joins it and gives what ``outcome_of`` would."""
    box = []
    thread = threading.Thread(target=lambda: box.append(outcome_of(fn)), daemon=True)
    thread.start()

    def join():
        thread.join(10)
        assert box, "the run did not end"
        return box[0]
    return join


def test_a_preempt_requested_while_idle_preempts_the_first_state_of_the_next_run(parity):
    def scenario(side):
        k = kit(side.sm)
        first, second = k.Out("go", outcomes=["go", "preempted"]), k.Out("done")
        built = k.machine(["done", "preempted"], [("A", first, {"go": "B"}), ("B", second, {})])
        built.request_preempt()
        return outcome_of(built.execute), first.saw_preempt, second.saw_preempt, built.preempt_requested()
    same = parity.same(scenario)
    assert same["result"] == (("returned", "done"), [True], [True], True)
    assert ("info", "Preempt requested on state machine before executing the next state.") in same["logs"]
    assert ("info", "Last state 'A' did not service preempt. Preempting next state 'B' before executing...") in same["logs"]


def test_a_serviced_preempt_is_consumed_and_the_next_state_runs_normally(parity):
    def scenario(side):
        k = kit(side.sm)
        w1, w2 = k.WaitForPreempt(outcomes=["preempted", "timeout"]), k.Out("done")
        built = k.machine(["done", "timeout"], [("W1", w1, {"preempted": "W2"}), ("W2", w2, {})])
        run = outcome_of_in_thread(built.execute)
        assert w1.started.wait(5)
        built.request_preempt()
        return run(), w2.saw_preempt, built.preempt_requested()
    assert parity.same(scenario)["result"] == (("returned", "done"), [False], False)


def test_an_unserviced_preempt_is_forwarded_to_the_next_state_and_the_flag_stays(parity):
    def scenario(side):
        k = kit(side.sm)
        w1 = k.WaitForPreempt(outcomes=["preempted", "timeout"], service=False)
        w2 = k.Out("done")
        built = k.machine(["done", "timeout"], [("W1", w1, {"preempted": "W2"}), ("W2", w2, {})])
        run = outcome_of_in_thread(built.execute)
        assert w1.started.wait(5)
        built.request_preempt()
        return run(), w2.saw_preempt, built.preempt_requested()
    same = parity.same(scenario)
    assert same["result"] == (("returned", "done"), [True], True)
    assert ("info", "Last state 'W1' did not service preempt. Preempting next state 'W2' before executing...") in same["logs"]


def test_a_concurrence_whose_children_all_service_a_preempt_returns_preempted_when_registered(parity):
    def scenario(side):
        k = kit(side.sm)
        a, b = k.WaitForPreempt(), k.WaitForPreempt()
        cc = k.concurrence(["done", "preempted"], "done", [("A", a), ("B", b)])
        run = outcome_of_in_thread(cc.execute)
        assert a.started.wait(5) and b.started.wait(5)
        cc.request_preempt()
        return run(), cc.preempt_requested()
    theirs, ours = parity.run(scenario)
    assert ours["result"] == theirs["result"] == (("returned", "preempted"), False)
    assert sorted(ours["logs"]) == sorted(theirs["logs"])  # the children's lines in either order
    assert ("info", "Concurrence serviced preempt.") in ours["logs"]


def test_a_preempted_concurrence_without_a_preempted_outcome_documented_fix(parity):
    """[bug] E41, documented: the original returns 'preempted' although it is not an outcome, so its
    parent StateMachine raises; fsm gives what its outcome policy gives."""
    def scenario(side):
        k = kit(side.sm)
        a = k.WaitForPreempt()
        cc = k.concurrence(["done"], "done", [("A", a)])
        root = k.machine(["done"], [("CC", cc, {})])
        run = outcome_of_in_thread(root.execute)
        assert a.started.wait(5)
        root.request_preempt()
        return run()
    theirs, ours = parity.run(scenario)
    assert theirs["result"][:2] == ("raised", "InvalidTransitionError")
    assert theirs["result"][2].startswith("Attempted to return outcome 'preempted' from state 'CC' of type ")
    assert ours["result"] == ("returned", "done")


def test_concurrence_children_that_do_not_service_a_preempt_are_recalled_and_the_policy_decides(parity):
    def scenario(side):
        k = kit(side.sm)
        a = k.WaitForPreempt(outcomes=["preempted", "stubborn"], service=False, result="stubborn")
        cc = k.concurrence(["done", "preempted", "kept"], "done", [("A", a)], outcome_map={"kept": {"A": "stubborn"}})
        run = outcome_of_in_thread(cc.execute)
        assert a.started.wait(5)
        cc.request_preempt()
        return run(), a.preempt_requested(), cc.preempt_requested()
    same = parity.same(scenario)
    assert same["result"] == (("returned", "kept"), False, True)
    assert ("warn", "State 'A' in concurrence did not service preempt.") in same["logs"]


def test_child_termination_cb_sees_the_live_outcomes_and_a_true_return_preempts_the_others(parity):
    def scenario(side):
        k = kit(side.sm)
        calls = []
        slow = k.WaitForPreempt()
        fast = k.Out()
        cc = k.concurrence(["done", "other"], "other", [("FAST", fast), ("SLOW", slow)],
                           outcome_map={"done": {"FAST": "done"}},
                           child_termination_cb=lambda outcomes: calls.append(dict(outcomes)) or True)
        return outcome_of(cc.execute), calls, cc.preempt_requested()
    theirs, ours = parity.run(scenario)
    assert ours["result"] == theirs["result"] == (
        ("returned", "done"), [{"FAST": "done", "SLOW": None}, {"FAST": "done", "SLOW": "preempted"}], False)
    assert sorted(ours["logs"]) == sorted(theirs["logs"])


def test_an_iterator_stops_after_the_current_item_on_preempt_and_returns_its_mapped_outcome(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        seen = []
        it = None

        def body(ud):
            seen.append(ud.item)
            if ud.item == 2:
                it.request_preempt()
            return "next"
        it = sm.Iterator(outcomes=["done", "stopped"], input_keys=[], output_keys=[], it=[1, 2, 3], it_label="item",
                         exhausted_outcome="done")
        with it:
            sm.Iterator.set_contained_state("BODY", k.Out(body, outcomes=["next"]), loop_outcomes=["next"],
                                            final_outcome_map={"next": "stopped"})
        return outcome_of(it.execute), seen, it.preempt_requested()
    assert parity.same(scenario)["result"] == (("returned", "stopped"), [1, 2], False)


def test_a_concurrence_preempted_while_idle_undocumented_difference(parity):
    """Not in README's table of fixes (listed in the parity report): the original runs the children of
    a Concurrence preempted while idle unpreempted and answers 'preempted' once they finish; fsm
    starts them preempted (so a child that waits for its preempt does not hang it, and one that does
    not service it is recalled and the outcome policy decides)."""
    def scenario(side):
        k = kit(side.sm)
        a = k.Out("done", outcomes=["done", "preempted"])
        cc = k.concurrence(["done", "preempted"], "done", [("A", a)])
        cc.request_preempt()
        return outcome_of(cc.execute), a.saw_preempt
    theirs, ours = parity.run(scenario)
    assert theirs["result"] == (("returned", "preempted"), [False])
    assert ("info", "Concurrence serviced preempt.") in theirs["logs"]
    assert ours["result"] == (("returned", "done"), [True])
    assert ("warn", "State 'A' in concurrence did not service preempt.") in ours["logs"]
