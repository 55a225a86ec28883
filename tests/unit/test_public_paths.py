"""What users import: every public name on ``fsm``, and every module by one path only, its subpackage's."""

from __future__ import annotations

import importlib

import pytest

import fsm

MODULES = {
    "core": ["state", "container", "state_machine", "concurrence", "sequence", "iterator", "user_data",
             "exceptions", "util", "log", "worker_pool"],
    "ros": ["bus", "actionlib", "service_state", "simple_action_state", "monitor_state", "condition_state",
            "preemptible", "slots", "user_callback"],
    "observation": ["introspection", "schema", "status", "encoding"],
    "logfiles": ["recorder", "log_reader", "summary", "transcript", "structure_index"],
}


@pytest.mark.parametrize("group,name", [(g, n) for g, names in MODULES.items() for n in names])
def test_a_module_imports_by_its_subpackage_path(group, name):
    assert importlib.import_module("fsm.%s.%s" % (group, name)).__name__ == "fsm.%s.%s" % (group, name)


@pytest.mark.parametrize("group,name", [(g, n) for g, names in MODULES.items() for n in names])
def test_a_module_has_no_second_flat_path(group, name):
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("fsm." + name)


def test_every_public_name_is_on_fsm():
    assert [name for name in fsm.__all__ if not hasattr(fsm, name)] == []


def test_a_user_script_finds_the_ros_states_on_fsm_and_in_their_subpackage():
    from fsm.ros.bus import get_bus
    from fsm.ros.simple_action_state import SimpleActionState

    assert get_bus is fsm.get_bus and SimpleActionState is fsm.SimpleActionState
