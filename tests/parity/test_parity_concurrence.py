"""BEHAVIORS.md section F (and A6), the original SMACH and fsm side by side: Concurrence."""

import pytest

from parity_support import outcome_of

pytestmark = pytest.mark.timeout(20)


def test_a_child_that_raises_logs_its_own_error_then_the_concurrence_error(parity):
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
        return outcome_of(cc.execute)
    theirs, ours = parity.run(scenario)
    assert ours["result"] == theirs["result"] == ("raised", "InvalidStateError",
                                                  "A concurrent state raised an exception during execution.")
    errors = [[message for level, message in side["logs"] if level == "error"] for side in (theirs, ours)]
    assert errors[1] == errors[0] == [
        "InvalidStateError: Could not execute child state 'BOOM': Traceback (most recent call last):\n  …\n"
        "ValueError: boom\n",
        "InvalidStateError: A concurrent state raised an exception during execution."]
