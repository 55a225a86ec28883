"""A script's run leaves the process as it found it: the counterparts of smach and rospy are gone
after ``Runner.run`` (a later ``import smach`` fails again) and their node's shutdown is undone."""

import importlib
import os
import sys

import fsm
import pytest

from recording_support import EXAMPLES
from fsmscope.server.runner import Runner


def test_after_a_tutorial_ran_in_this_process_smach_and_rospy_are_not_importable(tmp_path):
    assert Runner(os.path.join(EXAMPLES, "tutorial_service_action.py"), [], str(tmp_path / "r.jsonl")).run() == 0
    for name in ("smach", "smach_ros", "rospy", "actionlib", "std_srvs"):
        assert name not in sys.modules
        with pytest.raises(ModuleNotFoundError):
            importlib.import_module(name)


def test_the_tutorials_shutdown_does_not_stop_machines_run_after_it(tmp_path):
    assert Runner(os.path.join(EXAMPLES, "tutorial_service_action.py"), [], str(tmp_path / "r.jsonl")).run() == 0
    assert not fsm.is_shutdown()
