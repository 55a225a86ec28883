"""The differential test: the same machines of the original SMACH (each branch's core) run unwatched
and watched (``fsm.attach`` with a Recorder and a list), and a user sees the same of both: the
outcome (or the exception), the root's final userdata, every line SMACH logged, and the exceptions
that ended a thread.

Compared normalised (parity_support.normalised): the traceback inside a raising state's
InvalidUserCodeError has one frame more when watched (the watcher's call of the state's execute,
original_container.Watched), which the normalisation folds with the other frames."""

import pytest

from original_support import SCENARIOS, lines, run

pytestmark = pytest.mark.timeout(30)


@pytest.mark.parametrize("scenario", sorted(SCENARIOS))
def test_a_watched_machine_of_the_original_ends_logs_and_leaves_its_userdata_as_an_unwatched_one(core, scenario, tmp_path):
    unwatched = run(core, SCENARIOS[scenario])
    watched = run(core, SCENARIOS[scenario], tmp_path / "run.jsonl")
    assert watched["events"], "the watched run sent no event"
    assert watched["outcome"] == unwatched["outcome"]
    assert watched["userdata"] == unwatched["userdata"]
    assert lines(watched, scenario) == lines(unwatched, scenario)
    assert watched["thread_errors"] == unwatched["thread_errors"]


def test_the_runs_compared_are_the_runs_the_scenarios_describe(core, tmp_path):
    """What the differential test compares is not nothing: each scenario ends as it says."""
    outcomes = {name: run(core, scenario)["outcome"] for name, scenario in SCENARIOS.items()}
    assert outcomes["loop"] == ("returned", "outcome4")
    assert outcomes["nested"] == ("returned", "succeeded")
    assert outcomes["raising"][:2] == ("raised", "InvalidUserCodeError")
    assert outcomes["raising_child"][:2] == ("raised", "InvalidUserCodeError")
    assert outcomes["preempted"] == ("returned", "preempted")
    assert outcomes["iterated"] == ("returned", "big")
    # The ros2 branch's Concurrence, once its children serviced the preempt, goes on to its outcome map.
    ros2 = "/ros2/" in core.__file__
    assert outcomes["preempted_concurrence"] == ("returned", "done" if ros2 else "preempted")
