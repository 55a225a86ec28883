"""BEHAVIORS.md section F (and A6), the original SMACH and fsm side by side: Concurrence.

The children of a Concurrence run at once, so where the order of their lines is not set by the
scenario (a child waiting for another's line), the lines are compared in any order.

Not compared: a child returning None (F46, [bug], documented): the original hangs forever (its
child thread raises before notifying), so it cannot be run; fsm raises InvalidStateError, which
tests/unit/test_concurrence.py checks."""

import pytest

from parity_support import kit, outcome_of

pytestmark = pytest.mark.timeout(20)


def two(side, a, b, **kwargs):
    """A Concurrence of A (returns ``a`` at once) and B (returns ``b`` once A's line is logged)."""
    k = kit(side.sm)
    a_done = side.when_logged("Concurrent state 'A' returned")
    b_state = k.Out(lambda ud: a_done.wait(5) and b, outcomes=[b])
    return k.concurrence(kwargs.pop("outcomes", ["x", "y", "d"]), kwargs.pop("default_outcome", "d"),
                         [("A", k.Out(a)), ("B", b_state)], **kwargs)


def test_a_run_logs_its_start_each_child_as_it_finishes_and_the_outcomes_in_add_order(parity):
    def scenario(side):
        cc = two(side, "fail", "done", input_keys=["k"])
        cc.userdata.k = 1
        return outcome_of(cc.execute), cc.get_active_states()
    same = parity.same(scenario)
    assert same["result"] == (("returned", "d"), [])
    assert [message for level, message in same["logs"] if level == "info"] == [
        "Concurrence starting with userdata: \n\t['k']",
        "Concurrent state 'A' returned outcome 'fail' on termination.",
        "Concurrent state 'B' returned outcome 'done' on termination.",
        "Concurrent Outcomes: {'A': 'fail', 'B': 'done'}"]


@pytest.mark.parametrize("outcome_map, expected", [
    ({"x": {"A": "done", "B": "fail"}}, "d"),
    ({"x": {"A": "done"}, "y": {"A": "done", "B": "done"}}, "y"),
    ({"x": {"A": "done"}, "y": {"B": "done"}}, "x"),
    ({"x": {"A": "done", "B": "done"}, "y": {"A": "done"}}, "x"),
], ids=["none-satisfied-default", "more-constraints-win", "tie-first-wins", "fewer-constraints-skipped"])
def test_the_outcome_map_entry_with_the_most_satisfied_constraints_wins(parity, outcome_map, expected):
    same = parity.same(lambda side: outcome_of(two(side, "done", "done", outcome_map=outcome_map).execute))
    assert same["result"] == ("returned", expected)


def test_outcome_cb_gets_a_copy_of_the_outcomes_and_a_string_overrides(parity):
    def scenario(side):
        received = []

        def cb(outcomes):
            received.append(dict(outcomes))
            outcomes["A"] = "tampered"
            return "y"
        cc = two(side, "done", "fail", outcome_cb=cb)
        return outcome_of(cc.execute), received
    assert parity.same(scenario)["result"] == (("returned", "y"), [{"A": "done", "B": "fail"}])


def test_outcome_cb_returning_none_keeps_the_map_result_and_warns(parity):
    same = parity.same(lambda side: outcome_of(two(side, "done", "done", outcome_map={"x": {"A": "done"}},
                                                   outcome_cb=lambda outcomes: None).execute))
    assert same["result"] == ("returned", "x")
    assert ("warn", "Outcome callback returned None, using outcome 'x'") in same["logs"]


def test_outcome_cb_returning_a_non_string_documented_fix_uses_the_default(parity):
    """[bug] F45, documented: both log that the default outcome is used; the original uses the map's."""
    theirs, ours = parity.run(lambda side: outcome_of(two(side, "done", "done", outcome_map={"x": {"A": "done"}},
                                                          outcome_cb=lambda outcomes: 5).execute))
    assert theirs["result"] == ("returned", "x")
    assert ours["result"] == ("returned", "d")
    assert ours["logs"] == theirs["logs"]
    assert ("error", "Outcome callback returned a non-string '5', using default outcome 'd'") in ours["logs"]


def test_a_raising_outcome_cb_raises_invalid_user_code_error(parity):
    def scenario(side):
        def cb(outcomes):
            raise RuntimeError("bad cb")
        return outcome_of(two(side, "done", "done", outcome_cb=cb).execute)
    same = parity.same(scenario)
    assert same["result"][:2] == ("raised", "InvalidUserCodeError")
    assert same["result"][2].startswith("Could not execute outcome callback '<function ")


def test_a_child_that_raises_logs_its_own_error_then_the_concurrence_error(parity):
    """F46. Documented fixes: the original's child thread also ends with that InvalidStateError
    (Python prints it to stderr), fsm's children run on long-lived workers and end no thread; after
    the error the original still reports the child active, fsm reports none."""
    def scenario(side):
        sm = side.sm

        class Boom(sm.State):
            def __init__(self):
                sm.State.__init__(self, ["done"])

            def execute(self, ud):
                raise ValueError("boom")
        cc = sm.Concurrence(["d"], "d")
        with cc:
            sm.Concurrence.add("BOOM", Boom())
        return outcome_of(cc.execute), cc.get_active_states()
    theirs, ours = parity.run(scenario)
    raised = ("raised", "InvalidStateError", "A concurrent state raised an exception during execution.")
    assert theirs["result"] == (raised, ["BOOM"])
    assert ours["result"] == (raised, [])
    errors = [[message for level, message in side["logs"] if level == "error"] for side in (theirs, ours)]
    assert errors[1] == errors[0] == [
        "InvalidStateError: Could not execute child state 'BOOM': Traceback (most recent call last):\n  …\n"
        "ValueError: boom\n",
        "InvalidStateError: A concurrent state raised an exception during execution."]
    assert sorted(ours["logs"]) == sorted(theirs["logs"])  # the original's debug line races its child's error
    assert [name for name, message in theirs["thread_errors"]] == ["InvalidStateError"]
    assert ours["thread_errors"] == []


def test_a_child_outcome_is_not_checked_against_its_registered_outcomes(parity):
    same = parity.same(lambda side: outcome_of(two(side, "weird", "done", outcome_map={"x": {"A": "weird"}}).execute))
    assert same["result"] == ("returned", "x")


def test_construction_errors_of_the_outcome_policy(parity):
    def scenario(side):
        sm = side.sm
        return (outcome_of(lambda: sm.Concurrence(["a"], None)),
                outcome_of(lambda: sm.Concurrence(["a"], "zz")),
                outcome_of(lambda: sm.Concurrence(["a"], "a", outcome_map={"b": {}}, outcome_cb=5)))
    assert parity.same(scenario)["result"] == (
        ("raised", "InvalidStateError", "Concurrence requires an outcome policy"),
        ("raised", "InvalidStateError", "Errors specifying outcome policy of concurrence: \n\tDefault outcome 'zz' is unregistered."),
        ("raised", "InvalidStateError", "Errors specifying outcome policy of concurrence: \n\tUnregistered outcome 'b' in "
                                        "and_outcome_map.\n\tOutcome callback '5' is not callable."))


def test_an_empty_concurrence_raises_and_a_map_naming_a_missing_child_outcome_logs_at_close(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        empty = sm.Concurrence(["d"], "d")
        cc = sm.Concurrence(["d", "x"], "d", outcome_map={"x": {"A": "nope"}})
        with cc:
            sm.Concurrence.add("A", k.Out())
        return outcome_of(empty.execute)
    same = parity.same(scenario)
    assert same["result"] == ("raised", "InvalidStateError", "No states was added to concurrence")
    assert [message for level, message in same["logs"] if level == "error"][:2] == [
        "InvalidTransitionError: Outcome map in SMACH Concurrence references a state outcome that does not exist. "
        "Requested state outcome: 'nope', but state 'A' only has outcomes ('done',)",
        "Container consistency check failed."]


def test_children_share_the_concurrence_userdata_through_their_remappings(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        calls = []

        def write(value):
            def body(ud):
                ud.out = value
                return "done"
            return k.Out(body, output_keys=["out"])
        a_done = side.when_logged("Concurrent state 'A' returned")
        second = write(12)
        second.execute = lambda ud, first=second.execute: a_done.wait(5) and first(ud)
        cc = k.concurrence(["d"], "d", [("A", write(11), {"out": "r1"}), ("B", second, {"out": "r2"})],
                           output_keys=["r1", "r2"])
        cc.register_termination_cb(lambda ud, states, outcome: calls.append((sorted(states), outcome, "r1" in parent.userdata)))
        parent = k.machine(["d"], [("CC", cc, {})])
        return outcome_of(parent.execute), calls, parent.userdata.r1, parent.userdata.r2
    assert parity.same(scenario)["result"] == (("returned", "d"), [(["A", "B"], "d", False)], 11, 12)


def test_initial_and_active_states_of_a_concurrence(parity):
    """F49. [bug], documented: set_initial_state raises TypeError in the original; fsm merges the userdata."""
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        seen = []
        cc = None
        a_done = side.when_logged("Concurrent state 'A' returned")
        cc = k.concurrence(["d"], "d", [("A", k.Out()), ("B", k.Out(lambda ud: a_done.wait(5) and seen.append(
            cc.get_active_states()) or "done"))])
        before = cc.get_initial_states(), cc.get_active_states()
        outcome_of(cc.execute)
        ud = sm.UserData()
        ud.x = 1
        return before, seen, cc.get_active_states(), outcome_of(lambda: cc.set_initial_state(["A"], ud))
    theirs, ours = parity.run(scenario)
    assert ours["result"][:3] == theirs["result"][:3] == ((["A", "B"], []), [["B"]], [])
    assert theirs["result"][3] == ("raised", "TypeError", "'>' not supported between instances of 'list' and 'int'")
    assert ours["result"][3] == ("returned", None)
    assert ours["logs"] == theirs["logs"]


def test_callbacks_of_a_concurrence_get_the_active_children(parity):
    def scenario(side):
        k = kit(side.sm)
        calls = []
        cc = k.concurrence(["d"], "d", [("A", k.Out())])
        cc.register_start_cb(lambda ud, initial: calls.append(("start", initial)))
        cc.register_transition_cb(lambda ud, active: calls.append(("transition", active)))
        cc.register_termination_cb(lambda ud, states, outcome: calls.append(("termination", states, outcome)))
        return outcome_of(cc.execute), calls
    assert parity.same(scenario)["result"] == (("returned", "d"), [
        ("start", ["A"]), ("transition", ["A"]), ("transition", []), ("termination", ["A"], "d")])


def test_getting_an_unknown_child_of_a_concurrence_raises_a_key_error_naming_it(parity):
    def scenario(side):
        k = kit(side.sm)
        cc = k.concurrence(["d"], "d", [("A", k.Out())])
        return outcome_of(lambda: cc["NOPE"]), type(cc["A"]).__name__
    same = parity.same(scenario)
    assert same["result"] == (("raised", "KeyError", "'NOPE'"), "Out")
    assert same["logs"] == []


def test_a_raising_child_termination_cb_documented_fix(parity):
    """[bug] documented (README's table): in the original the callback's InvalidUserCodeError ends
    the child's thread and the run goes on (here to the default outcome, once the other child ends);
    fsm preempts the unfinished children and the Concurrence raises that error."""
    def scenario(side):
        k = kit(side.sm)
        calls = []

        def cb(outcomes):
            calls.append(dict(outcomes))
            if len(calls) == 1:
                raise RuntimeError("cb exploded")
            return False
        return outcome_of(two(side, "done", "done", child_termination_cb=cb).execute)[:2], calls[:1]
    theirs, ours = parity.run(scenario)
    assert theirs["result"] == (("returned", "d"), [{"A": "done", "B": None}])
    assert [name for name, message in theirs["thread_errors"]] == ["InvalidUserCodeError"]
    assert ours["result"] == (("raised", "InvalidUserCodeError"), [{"A": "done", "B": None}])
    assert ours["thread_errors"] == []
    first_error = [[message for level, message in side["logs"] if level == "error"][0] for side in (theirs, ours)]
    assert first_error[1] == first_error[0]
    assert first_error[0].startswith("InvalidUserCodeError: Could not execute child termination callback: Traceback")


def test_an_outcome_map_naming_an_unknown_child_raises_key_error_at_close_and_at_execute(parity):
    def scenario(side):
        sm = side.sm
        cc = sm.Concurrence(["d", "x"], "d", outcome_map={"x": {"GHOST": "done"}})

        def build():
            with cc:
                sm.Concurrence.add("A", kit(sm).Out())
        closing = outcome_of(build)
        return closing, outcome_of(cc.execute)
    assert parity.same(scenario)["result"] == (("raised", "KeyError", "'GHOST'"), ("raised", "KeyError", "'GHOST'"))
