"""The two SMACH tutorials of examples/ as they are, on a real ROS 1 (a rosmaster of the module's own,
Debian's rospy and actionlib, the original SMACH and smach_ros), run by ``fsmscope run``: the script
runs on what is installed (no counterpart, no notice), its service and action are ROS's, and
fsmscope records its machine, found as it starts."""

import subprocess
import sys

import pytest
from fsm.logfiles.log_reader import read_events

from recording_support import EXAMPLES
from ros1_support import DEBIAN_PACKAGES, rospy_lines

# ``fsmscope ARGS...`` with Debian's packages after this environment's, as a robot's script runs.
FSMSCOPE_WITH_DEBIAN_PACKAGES_LAST = (
    "import runpy, sys; sys.path.append(%r); sys.argv[0] = 'fsmscope'; "
    "runpy.run_module('fsmscope', run_name='__main__', alter_sys=True)" % DEBIAN_PACKAGES)


@pytest.mark.parametrize("tutorial, ended, transitions", [
    ("tutorial_foo_bar", "The state machine ended in outcome4",
     [("FOO", "outcome1", "BAR"), ("BAR", "outcome2", "FOO")] * 3),
    ("tutorial_service_action", "The state machine ended in succeeded with sum=5",
     [("STATE1", "succeeded", "STATE2")]),
])
def test_a_tutorial_runs_on_ros1_as_it_is_and_its_machine_is_recorded(ros, tutorial, ended, transitions):
    log = ros.home / (tutorial + ".jsonl")
    done = subprocess.run([sys.executable, "-c", FSMSCOPE_WITH_DEBIAN_PACKAGES_LAST, "run", "--exit", "--no-serve",
                           "--record", str(log), "%s/%s.py" % (EXAMPLES, tutorial)],
                          env=ros.robot_env(), cwd=ros.home, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "smach is not installed" not in done.stderr
    assert ("info", ended) in rospy_lines(done.stdout)
    events = list(read_events(log))
    assert {e["machine"] for e in events} == {tutorial}
    assert [(e["from"], e["outcome"], e["to"]) for e in events if e["kind"] == "transition"] == transitions
