"""BEHAVIORS.md section G (and A7), the original SMACH and fsm side by side: Iterator."""

from parity_support import kit, outcome_of


def summing(sm, items, body_outcome=lambda ud: "next", **contained):
    """An Iterator over ``items`` adding each to ``total``; its body's outcome from ``body_outcome``."""
    k = kit(sm)
    outcomes = ["done"]

    def body(ud):
        ud.total = ud.total + ud.item
        return body_outcome(ud)
    it = sm.Iterator(outcomes=outcomes, input_keys=["total"], output_keys=["total"], it=items, it_label="item",
                     exhausted_outcome="done")
    with it:
        sm.Iterator.set_contained_state("BODY", k.Out(body, outcomes=["next", "stop"]), **contained)
    it.userdata.total = 0
    return it, outcomes


def test_an_iterator_runs_its_state_once_per_item_and_returns_the_exhausted_outcome(parity):
    def scenario(side):
        sm = side.sm
        calls = []
        it, outcomes = summing(sm, [1, 2, 3], loop_outcomes=["next"])
        it.register_transition_cb(lambda ud, active: calls.append(("transition", active, ud.item)))
        it.register_termination_cb(lambda ud, states, outcome: calls.append(("termination", states, outcome)))
        return outcome_of(it.execute), it.userdata.total, calls, outcomes, it.get_active_states()
    same = parity.same(scenario)
    assert same["result"] == (("returned", "done"), 6, [("transition", ["BODY"], 1), ("transition", ["BODY"], 2),
                                                        ("transition", ["BODY"], 3), ("termination", "BODY", "done")],
                              ["done"], [])
    assert [message for level, message in same["logs"] if level == "info"] == [
        "Iterating %d of [1, 2, 3]" % n for n in (1, 2, 3)]


def test_a_break_outcome_ends_the_loop_with_its_mapped_outcome(parity):
    def scenario(side):
        it, outcomes = summing(side.sm, [1, 2, 3, 4], lambda ud: "stop" if ud.item == 3 else "next",
                               break_outcomes=["stop"], final_outcome_map={"stop": "stopped"})
        return outcome_of(it.execute), it.userdata.total
    assert parity.same(scenario)["result"] == (("returned", "stopped"), 6)


def test_a_callable_iterable_is_called_and_its_repr_logged(parity):
    def items():
        return iter([5])

    def scenario(side):
        it, outcomes = summing(side.sm, items, loop_outcomes=["next"])
        return outcome_of(it.execute), it.userdata.total
    same = parity.same(scenario)
    assert same["result"] == (("returned", "done"), 5)
    assert same["logs"][-1][1].startswith("Iterating 5 of <function test_a_callable_iterable_is_called_and_its_repr")


def test_an_iterable_that_raises_counts_as_exhausted(parity):
    def items():
        yield 1
        raise RuntimeError("broken iterable")

    def scenario(side):
        it, outcomes = summing(side.sm, items(), loop_outcomes=["next"])
        return outcome_of(it.execute), it.userdata.total
    assert parity.same(scenario)["result"] == (("returned", "done"), 1)


def test_the_contained_state_gets_the_raw_userdata_without_key_checks(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        seen = []
        it = sm.Iterator(outcomes=["done"], input_keys=[], output_keys=[], it=[1], exhausted_outcome="done")
        with it:
            sm.Iterator.set_contained_state("BODY", k.Out(lambda ud: seen.append((type(ud).__name__, ud.it_data,
                                                                                  ud.undeclared)) or "done"))
        it.userdata.undeclared = "visible"
        return outcome_of(it.execute), seen
    assert parity.same(scenario)["result"] == (("returned", "done"), [("UserData", 1, "visible")])


def test_a_raising_contained_state_is_wrapped_in_invalid_user_code_error(parity):
    """[bug] documented (after an error no state is reported active): the original's Iterator
    still reports its state active, and running, after the error; fsm reports neither."""
    def scenario(side):
        it, outcomes = summing(side.sm, [1], lambda ud: 1 / 0, loop_outcomes=["next"])
        return outcome_of(it.execute), it.get_active_states()
    theirs, ours = parity.run(scenario)
    assert ours["logs"] == theirs["logs"]
    assert ours["result"][0] == theirs["result"][0]
    assert ours["result"][0][:2] == ("raised", "InvalidUserCodeError")
    assert ours["result"][0][2].startswith("Could not execute iterator state 'BODY' of type '<parity_support.kit.")
    assert theirs["result"][1] == ["BODY"]
    assert ours["result"][1] == []


def test_an_invalid_user_code_error_from_inside_is_logged_and_passed_on(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        it = sm.Iterator(outcomes=["done"], input_keys=[], output_keys=[], it=[1], exhausted_outcome="done")
        with it:
            sm.Iterator.set_contained_state("BODY", k.machine(["done"], [("READ", k.Out(lambda ud: ud.never_declared), {})]))
        wrapper = k.machine(["done"], [("IT", it, {})])
        return outcome_of(wrapper.execute)[:2]
    same = parity.same(scenario)
    assert same["result"] == ("raised", "InvalidUserCodeError")
    assert ("error", "Could not execute Iterator state 'BODY'") in same["logs"]


def test_iterator_set_initial_state(parity):
    """G51. [bug], documented: with more than one state the original raises TypeError (its warning's
    format fails), fsm warns and takes the first. A wrong label warns and raises a bare KeyError on both."""
    def scenario(side):
        sm = side.sm
        it, outcomes = summing(sm, [1])
        ud = sm.UserData()
        ud.total = 10
        return (outcome_of(lambda: it.set_initial_state(["BODY", "BODY"], ud)),
                outcome_of(lambda: it.set_initial_state(["OTHER"], ud)),
                outcome_of(lambda: it.set_initial_state(["BODY"], ud)), it.userdata.total)
    theirs, ours = parity.run(scenario)
    assert theirs["result"][0] == ("raised", "TypeError", "not all arguments converted during string formatting")
    assert ours["result"][0] == ("returned", None)
    assert ours["result"][1:] == theirs["result"][1:] == (("raised", "KeyError", ""), ("returned", None), 10)
    assert ours["logs"] == [("warn", "Attempting to set initial state to include more than one state, but the Iterator "
                                     "container can only have one initial state. Taking the first one.")] + theirs["logs"]
    assert theirs["logs"] == [("warn", "Attempting to set state 'OTHER' as initial state in Iterator container. The "
                                       "only available state is 'BODY'.")]


def test_an_iterators_internal_edges(parity):
    """A break outcome mapped to itself, like one not mapped, falls through: its edge leads to None."""
    def scenario(side):
        sm = side.sm
        it = sm.Iterator(outcomes=["done", "stop"], input_keys=[], output_keys=[], it=[1], exhausted_outcome="done")
        with it:
            sm.Iterator.set_contained_state("B", kit(sm).Out("next", outcomes=["next", "stop", "halt", "odd"]),
                                            loop_outcomes=["next"], final_outcome_map={"stop": "stop", "halt": "done"})
        return sorted(map(str, it.get_internal_edges()))
    assert parity.same(scenario)["result"] == ["('halt', 'B', 'done')", "('odd', 'B', None)", "('stop', 'B', None)",
                                               "['next', 'B', 'B']"]


def test_the_exhausted_outcome_is_appended_to_the_callers_outcomes_and_start_callbacks_get_the_state(parity):
    def scenario(side):
        sm = side.sm
        outcomes = ["done"]
        it = sm.Iterator(outcomes, [], [], it=[1])
        with it:
            sm.Iterator.set_contained_state("BODY", kit(sm).Out())
        calls = []
        it.register_start_cb(lambda ud, initial: calls.append(initial))
        return outcomes, sorted(it.get_registered_outcomes()), outcome_of(it.execute), calls
    assert parity.same(scenario)["result"] == (["done", "exhausted"], ["done", "exhausted"], ("returned", "done"),
                                               [["BODY"]])


def test_a_preempt_requested_while_idle_stops_the_iterator_after_its_first_item(parity):
    def scenario(side):
        sm = side.sm
        body = kit(sm).Out("next", outcomes=["next"])
        it = sm.Iterator(["done"], [], [], it=[1, 2, 3], exhausted_outcome="done")
        with it:
            sm.Iterator.set_contained_state("BODY", body, loop_outcomes=["next"])
        it.request_preempt()
        return outcome_of(it.execute), body.saw_preempt, it.preempt_requested()
    assert parity.same(scenario)["result"] == (("returned", "next"), [False], False)


def test_with_both_loop_and_break_outcomes_the_break_outcomes_decide(parity):
    """Both given: a warning, and every outcome of the state that does not break loops; an outcome
    the state does not register (not checked by an Iterator) then breaks."""
    def scenario(side):
        sm = side.sm
        it = sm.Iterator(["done", "b"], [], [], it=[1, 2], exhausted_outcome="done")
        with it:
            sm.Iterator.set_contained_state("B", kit(sm).Out("x", outcomes=["a", "b"]), loop_outcomes=["x"],
                                            break_outcomes=["b"])
        return sorted(map(str, it.get_internal_edges())), outcome_of(it.execute)
    same = parity.same(scenario)
    assert same["result"] == (["('b', 'B', None)", "['a', 'B', 'B']"], ("returned", "x"))
    assert same["logs"][0] == ("warn", "Both loop_outcomes and break_outcomes were specified when constructing SMACH "
                                       "iterator container.")
