"""fsm is grouped in subpackages (core, ros, observation, logfiles), but what users import stays
where it was: every public name on ``fsm`` and every module by its flat path."""

from __future__ import annotations

import importlib

import pytest

import fsm

FLAT_MODULES = {
    "core": ["state", "container", "state_machine", "concurrence", "sequence", "iterator", "user_data",
             "exceptions", "util", "log", "worker_pool"],
    "ros": ["bus", "actionlib", "service_state", "simple_action_state", "monitor_state", "condition_state",
            "preemptible", "slots", "user_callback"],
    "observation": ["introspection", "schema", "status", "encoding"],
    "logfiles": ["recorder", "log_reader", "summary", "transcript", "structure_index"],
}


@pytest.mark.parametrize("group,name", [(g, n) for g, names in FLAT_MODULES.items() for n in names])
def test_a_module_imports_by_its_flat_path_as_the_same_module(group, name):
    assert importlib.import_module("fsm." + name) is importlib.import_module("fsm.%s.%s" % (group, name))


def test_every_public_name_is_on_fsm():
    assert [name for name in fsm.__all__ if not hasattr(fsm, name)] == []


def test_a_user_script_imports_the_ros_states_by_their_flat_paths():
    from fsm.bus import get_bus
    from fsm.simple_action_state import SimpleActionState

    assert get_bus is fsm.get_bus and SimpleActionState is fsm.SimpleActionState
