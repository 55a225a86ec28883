"""BEHAVIORS.md section C (and A3-A5), the original SMACH and fsm side by side: running a StateMachine."""

from parity_support import kit, outcome_of


def nested(sm):
    """SM_ROOT: FOO -outcome1-> BAR -outcome1-> SUB(L1 -> L3 ...), as in BEHAVIORS.md's examples."""
    k = kit(sm)
    sub = k.machine(["out2"], [("L1", k.Out("out1"), {"out1": "L3"}), ("L3", k.Out("out3"), {"out3": "out2"})])
    return k.machine(["outcome4", "outcome5"], [("FOO", k.Out("outcome1", outcomes=["outcome1", "outcome2"]),
                                                 {"outcome1": "BAR", "outcome2": "outcome4"}),
                                                ("BAR", k.Out("outcome1"), {"outcome1": "SUB"}),
                                                ("SUB", sub, {"out2": "outcome5"})])


def test_a_nested_run_logs_start_transition_and_termination_lines(parity):
    def scenario(side):
        root = nested(side.sm)
        root.userdata.a = 1
        return outcome_of(root.execute)
    same = parity.same(scenario)
    assert same["result"] == ("returned", "outcome5")
    assert [message for level, message in same["logs"] if level == "info"] == [
        "State machine starting in initial state 'FOO' with userdata: \n\t['a']",
        "State machine transitioning 'FOO':'outcome1'-->'BAR'",
        "State machine transitioning 'BAR':'outcome1'-->'SUB'",
        "State machine starting in initial state 'L1' with userdata: \n\t[]",
        "State machine transitioning 'L1':'out1'-->'L3'",
        "State machine terminating 'L3':'out3':'out2'",
        "State machine terminating 'SUB':'out2':'outcome5'"]


def test_the_start_line_lists_the_keys_after_the_input_keys_are_copied(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        sub = k.machine(["done"], [("IN", k.Out(), {})], input_keys=["x"])
        root = k.machine(["done"], [("SUB", sub, {})])
        root.userdata.x = 1
        return outcome_of(root.execute)
    assert ("info", "State machine starting in initial state 'IN' with userdata: \n\t['x']") in parity.same(scenario)["logs"]


def test_an_unmapped_outcome_falls_through_to_the_container_outcome_of_its_name(parity):
    def scenario(side):
        k = kit(side.sm)
        return outcome_of(k.machine(["outcome1"], [("BAR", k.Out("outcome1"), {})]).execute)
    assert parity.same(scenario)["result"] == ("returned", "outcome1")


def test_a_target_that_is_both_a_state_and_an_outcome_goes_to_the_state(parity):
    def scenario(side):
        k = kit(side.sm)
        return outcome_of(k.machine(["B", "end"], [("A", k.Out("go"), {"go": "B"}), ("B", k.Out("x"), {"x": "end"})]).execute)
    assert parity.same(scenario)["result"] == ("returned", "end")


def test_an_undeclared_outcome_or_none_raises_invalid_transition_error(parity):
    def scenario(side):
        k = kit(side.sm)
        weird = k.machine(["done"], [("BAD", k.Out(lambda ud: "weird"), {})])
        silent = k.machine(["done"], [("BAD", k.Out(lambda ud: None), {})])
        return outcome_of(weird.execute), outcome_of(silent.execute), silent.is_running()
    weird, silent, running = parity.same(scenario)["result"]
    assert weird == ("raised", "InvalidTransitionError",
                     "Attempted to return outcome 'weird' from state 'BAD' of type '<parity_support.kit.<locals>.Out "
                     "object at 0x…>' which only has registered outcomes: ('done',)")
    assert silent[2].startswith("Attempted to return outcome 'None' from state 'BAD'")
    assert running is False


def test_a_raising_state_is_wrapped_in_invalid_user_code_error_and_output_keys_are_not_copied(parity):
    """C22. [bug] C23/C22, documented: after the error the original still reports the failed state
    active, fsm reports ['None']."""
    def scenario(side):
        sm = side.sm
        k = kit(sm)

        def boom(ud):
            ud.out = "written"
            raise ValueError("boom")
        sub = k.machine(["done"], [("BAD", k.Out(boom, output_keys=["out"]), {})], output_keys=["out"])
        root = k.machine(["done"], [("SUB", sub, {})])
        raised = outcome_of(root.execute)
        return raised, root.is_running(), sub.is_running(), "out" in root.userdata, root.get_active_states(), \
            sub.get_active_states()
    theirs, ours = parity.run(scenario)
    assert ours["logs"] == theirs["logs"]
    assert ours["result"][:4] == theirs["result"][:4]
    raised, root_running, sub_running, copied = ours["result"][:4]
    assert raised[:2] == ("raised", "InvalidUserCodeError")
    assert raised[2].startswith("Could not execute state 'BAD' of type '<parity_support.kit.<locals>.Out object at "
                                "0x…>': Traceback (most recent call last):\n  …\nValueError: boom")
    assert (root_running, sub_running, copied) == (False, False, False)
    assert theirs["result"][4:] == (["SUB"], ["BAD"])
    assert ours["result"][4:] == (["None"], ["None"])
    assert [message for level, message in ours["logs"] if level == "error"][-1] == "State 'SUB' failed to execute."


def test_active_and_initial_states_are_reported_as_strings_nested_too(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        seen = []
        root = None

        def look(ud):
            seen.append((root.get_active_states(), sub.get_active_states()))
            return "done"
        sub = k.machine(["done"], [("INNER_STATE", k.Out(look), {})])
        root = k.machine(["done"], [("INNER", sub, {})])
        before = root.get_active_states(), root.get_initial_states(), sub.get_initial_states()
        outcome_of(root.execute)
        return before, seen, root.get_active_states()
    assert parity.same(scenario)["result"] == ((["None"], ["INNER"], ["INNER_STATE"]), [(["INNER"], ["INNER_STATE"])],
                                               ["None"])


def callbacks_scenario(side):
    """A -go-> B -stop-> done with a start, a transition and a termination callback (each with an
    extra argument) that record what they get, the active states then, and the parent's key."""
    sm = side.sm
    k = kit(sm)
    calls = []
    sub = None

    def record(kind):
        def cb(ud, *args):
            sm.loginfo("%s callback" % kind)  # so that the log shows when each ran
            calls.append((kind, args, sub.get_active_states(), sorted(ud.keys()), "x" in parent.userdata))
        return cb
    sub = k.machine(["done"], [("A", k.Out("go"), {"go": "B"}), ("B", k.Out(lambda ud: setattr(ud, "x", 1) or "stop",
                                                                            outcomes=["stop"], output_keys=["x"]),
                                                                  {"stop": "done"})], output_keys=["x"])
    sub.register_start_cb(record("start"), ["extra"])
    sub.register_transition_cb(record("transition"), ["extra"])
    sub.register_termination_cb(record("termination"), ["extra"])
    parent = k.machine(["done"], [("SUB", sub, {})])
    return outcome_of(parent.execute), calls


def test_callbacks_get_their_arguments_in_order_at_the_documented_moments(parity):
    same = parity.same(callbacks_scenario)
    assert [message for level, message in same["logs"] if level == "info"] == [
        "State machine starting in initial state 'SUB' with userdata: \n\t[]",
        "State machine starting in initial state 'A' with userdata: \n\t[]", "start callback",
        "State machine transitioning 'A':'go'-->'B'", "transition callback",
        "State machine terminating 'B':'stop':'done'", "termination callback",
        "State machine terminating 'SUB':'done':'done'"]
    assert same["result"] == (("returned", "done"), [
        ("start", (["A"], "extra"), ["A"], [], False),
        ("transition", (["B"], "extra"), ["B"], [], False),
        ("termination", (["B"], "done", "extra"), ["None"], ["x"], False)])


def test_a_failing_callback_skips_the_rest_of_its_kind_and_logs_it(parity):
    def scenario(side):
        k = kit(side.sm)
        calls = []
        built = k.machine(["done"], [("A", k.Out("go"), {"go": "B"}), ("B", k.Out(), {})])
        for kind in ("start", "transition", "termination"):
            register = getattr(built, "register_%s_cb" % kind)
            register(lambda ud, *a, kind=kind: 1 / 0)
            register(lambda ud, *a, kind=kind: calls.append(kind))
        return outcome_of(built.execute), calls
    same = parity.same(scenario)
    assert same["result"] == (("returned", "done"), [])
    assert [message.split(":")[0] for level, message in same["logs"] if level == "error"] == [
        "Could not execute start callback", "Could not execute transition callback",
        "Could not execute termination callback"]


def test_userdata_persists_across_runs_of_the_same_machine(parity):
    def scenario(side):
        k = kit(side.sm)

        def count(ud):
            ud.n = ud.n + 1 if "n" in ud else 1
            return "done"
        built = k.machine(["done"], [("COUNT", k.Out(count, input_keys=["n"], output_keys=["n"]), {})])
        return [outcome_of(built.execute) for _ in range(3)], built.userdata.n
    assert parity.same(scenario)["result"] == ([("returned", "done")] * 3, 3)


def test_at_shutdown_execute_logs_the_start_runs_the_start_callbacks_and_returns_none(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        calls = []
        a = k.Out()
        built = k.machine(["done"], [("A", a, {})])
        built.register_start_cb(lambda ud, initial: calls.append(initial))
        sm.set_shutdown_check(lambda: True)
        return outcome_of(built.execute), calls, a.saw_preempt
    assert parity.same(scenario)["result"] == (("returned", None), [["A"]], [])


def test_constants_are_written_before_every_execution_of_their_state(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        seen = []

        def read(ud):
            seen.append(ud.k)
            return "again" if len(seen) < 2 else "done"
        built = sm.StateMachine(outcomes=["done"])
        with built:
            sm.StateMachine.add("A", k.Out(read, outcomes=["again", "done"], input_keys=["k"]),
                                {"again": "A"}, constants={"k": 7})
        built.userdata.k = 0
        return outcome_of(built.execute), seen, built.userdata.k
    assert parity.same(scenario)["result"] == (("returned", "done"), [7, 7], 7)


def test_a_state_machine_can_be_executed_again_after_an_error(parity):
    def scenario(side):
        k = kit(side.sm)
        fail = [True]
        built = k.machine(["done"], [("A", k.Out(lambda ud: 1 / 0 if fail[0] else "done"), {})])
        first = outcome_of(built.execute)
        fail[0] = False
        return first[:2], outcome_of(built.execute)
    assert parity.same(scenario)["result"] == (("raised", "InvalidUserCodeError"), ("returned", "done"))


def test_an_outcome_bound_to_nothing_raises_and_one_bound_to_an_unknown_target_fails_the_check(parity):
    def scenario(side):
        k = kit(side.sm)
        unbound = k.machine(["done"], [("A", k.Out("go"), {"go": "done"})])
        del unbound._transitions["A"]["go"]
        nowhere = k.machine(["done"], [("A", k.Out("go"), {"go": "done"})])
        nowhere._transitions["A"]["go"] = "elsewhere"
        return outcome_of(unbound.execute), outcome_of(nowhere.execute)
    assert parity.same(scenario)["result"] == (
        ("raised", "InvalidTransitionError", "Outcome 'go' of state 'A' is not bound to any transition target. Bound "
                                             "transitions include: {}"),
        ("returned", None))  # the consistency check at execute catches the unknown target first


def test_an_empty_target_is_a_terminal_transition_like_none(parity):
    def scenario(side):
        k = kit(side.sm)
        return outcome_of(k.machine(["go"], [("A", k.Out("go"), {"go": ""})]).execute)
    assert parity.same(scenario)["result"] == ("returned", "go")


def test_a_state_whose_request_preempt_raises_is_logged_and_runs(parity):
    def scenario(side):
        sm = side.sm

        class Stubborn(sm.State):
            def __init__(self):
                sm.State.__init__(self, ["done"])

            def request_preempt(self):
                raise RuntimeError("will not")

            def execute(self, ud):
                return "done"
        built = kit(sm).machine(["done"], [("A", Stubborn(), {})])
        built.request_preempt()
        return outcome_of(built.execute)
    same = parity.same(scenario)
    assert same["result"] == ("returned", "done")
    assert [message.split("\n")[0] for level, message in same["logs"] if level == "error"] == [
        "Failed to preempt contained state 'A': Traceback (most recent call last):"]
