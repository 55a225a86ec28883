"""BEHAVIORS.md section B, the original SMACH and fsm side by side: building a StateMachine and a
Sequence (every construction line is logged at DEBUG by both, and compared too)."""

from parity_support import kit, outcome_of


def test_the_first_added_state_is_the_initial_state_unless_set(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        built = k.machine(["done"], [("A", k.Out(), {}), ("B", k.Out(), {})])
        first = built.get_initial_states()
        built.set_initial_state(["B"])
        return first, built.get_initial_states(), built.get_active_states()
    assert parity.same(scenario)["result"] == (["A"], ["B"], ["None"])


def test_add_completes_and_keeps_the_callers_transitions_dict(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        transitions = {"a": "done"}
        built = sm.StateMachine(outcomes=["done", "b"])
        with built:
            sm.StateMachine.add("X", k.Out("a", outcomes=["a", "b"]), transitions)
        return sorted(transitions.items(), key=str), built._transitions["X"] is transitions
    assert parity.same(scenario)["result"] == ([("a", "done"), ("b", None)], True)


def test_a_transition_from_an_unregistered_outcome_is_refused_at_add(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        built = sm.StateMachine(outcomes=["done"])
        with built:
            refused = outcome_of(lambda: sm.StateMachine.add("BAR", k.Out("outcome1"), {"nope": "done"}))
            sm.StateMachine.add("OK", k.Out(), {})
        return refused
    assert parity.same(scenario)["result"] == (
        "raised", "InvalidTransitionError",
        "Specified outcome 'nope' on state 'BAR', which only has available registered outcomes: ('outcome1',)")


def test_a_duplicate_label_is_refused(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        built = sm.StateMachine(outcomes=["done"])
        with built:
            sm.StateMachine.add("BAR", k.Out(), {})
            return outcome_of(lambda: sm.StateMachine.add("BAR", k.Out(), {}))
    assert parity.same(scenario)["result"] == (
        "raised", "InvalidStateError",
        'Attempting to add state with label "BAR" to state machine, but this label is already being used.')


def test_add_outside_any_open_container_is_refused(parity):
    def scenario(side):
        return outcome_of(lambda: side.sm.StateMachine.add("A", kit(side.sm).Out(), {}))
    assert parity.same(scenario)["result"] == (
        "raised", "InvalidStateError", "Attempting to access the currently opened container, but no container is opened.")


def test_consistency_errors_are_gathered_logged_at_close_and_execute_returns_none(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        built = sm.StateMachine(outcomes=["done"])
        with built:
            sm.StateMachine.add("A", k.Out("go"), {"go": "GHOST"})
            sm.StateMachine.add("B", k.Out("away"), {})
        built.set_initial_state(["NOPE"])
        return outcome_of(built.execute), built.is_running()
    same = parity.same(scenario)
    assert same["result"] == (("returned", None), False)
    errors = [message for level, message in same["logs"] if level == "error"]
    assert errors[-1] == "Container consistency check failed."
    assert errors[-2].startswith("InvalidTransitionError: State machine failed consistency check: \n\tInitial state "
                                 "label: 'NOPE' is not in the state machine.\n\tState 'A' references unknown states: "
                                 "['GHOST']\n\tState 'B' references unregistered outcomes: ['away']\n\n\tAvailable states: ")


def test_a_state_machine_with_no_state_fails_its_check(parity):
    def scenario(side):
        built = side.sm.StateMachine(outcomes=["done"])
        with built:
            pass
        return outcome_of(built.execute)
    assert parity.same(scenario)["result"] == ("returned", None)


def test_an_exception_inside_with_propagates_and_the_documented_fix_closes_the_container(parity):
    """[bug] B15: the original leaves the container open (and its global lock held); fsm closes it.
    Both log the error (other than InvalidStateError/InvalidTransitionError) with its traceback."""
    def scenario(side):
        sm = side.sm
        built = sm.StateMachine(outcomes=["done"])
        try:
            with built:
                raise RuntimeError("in the with block")
        except RuntimeError as err:
            raised = str(err)
        still_open = list(sm.Container._construction_stack)
        for container in still_open:  # put the original back as it was before the scenario
            sm.Container._construction_stack.remove(container)
            sm.Container._construction_lock.release()
        return raised, [c is built for c in still_open]
    theirs, ours = parity.run(scenario)
    assert theirs["result"] == ("in the with block", [True])
    assert ours["result"] == ("in the with block", [])
    assert ours["logs"] == theirs["logs"]


def test_with_binds_none(parity):
    def scenario(side):
        built = side.sm.StateMachine(outcomes=["done"])
        with built as bound:
            side.sm.StateMachine.add("A", kit(side.sm).Out(), {})
        return bound
    assert parity.same(scenario)["result"] is None


def test_add_auto_wires_its_connector_outcomes_to_the_next_added_state(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        built = sm.StateMachine(outcomes=["done"])
        with built:
            sm.StateMachine.add_auto("A", k.Out("go", outcomes=["go", "other"]), ["go"], {"go": "done", "other": "done"})
            sm.StateMachine.add("B", k.Out(), {})
            refused = outcome_of(lambda: sm.StateMachine.add_auto("C", k.Out(), ["nope"]))
        return sorted(built._transitions["A"].items()), refused, outcome_of(built.execute)
    same = parity.same(scenario)
    assert same["result"] == ([("go", "B"), ("other", "done")], (
        "raised", "InvalidStateError",
        "Attempting to auto-connect states with outcomes ['nope'], but state 'C' only has registerd outcomes: ('done',)"),
        ("returned", "done"))


def test_a_sequence_links_each_state_to_the_next_unless_given_explicitly(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        seq = sm.Sequence(outcomes=["succeeded", "aborted"], connector_outcome="succeeded")
        with seq:
            sm.Sequence.add("S1", k.Out("succeeded", outcomes=["succeeded", "aborted"]), {"succeeded": "S3"})
            sm.Sequence.add("S2", k.Out("succeeded", outcomes=["succeeded", "aborted"]))
            sm.Sequence.add("S3", k.Out("succeeded", outcomes=["succeeded", "aborted"]))
        return {label: sorted(t.items()) for label, t in seq._transitions.items()}, outcome_of(seq.execute)
    same = parity.same(scenario)
    assert same["result"][0] == {"S1": [("aborted", None), ("succeeded", "S3")],
                                 "S2": [("aborted", None), ("succeeded", "S3")],
                                 "S3": [("aborted", None), ("succeeded", None)]}
    assert same["result"][1] == ("returned", "succeeded")


def test_a_sequence_whose_state_lacks_the_connector_outcome_logs_that_construction_failed(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        seq = sm.Sequence(outcomes=["done", "next"], connector_outcome="next")
        with seq:
            sm.Sequence.add("S1", k.Out("done"))
            sm.Sequence.add("S2", k.Out("done"))
        return outcome_of(seq.execute)
    same = parity.same(scenario)
    assert same["result"] == ("returned", "done")


def test_opened_yields_the_container(parity):
    def scenario(side):
        sm = side.sm
        built = sm.StateMachine(outcomes=["done"])
        with built.opened() as bound:
            sm.StateMachine.add("A", kit(sm).Out(), {})
        return bound is built, built.is_opened(), outcome_of(built.execute)
    assert parity.same(scenario)["result"] == (True, False, ("returned", "done"))
