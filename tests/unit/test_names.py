"""One rule for a machine's name wherever it travels (fsm/observation/names.py): the event schema,
the hub, the fleet's key space and the page all take the same names, and every namer makes a
second machine's name the same way."""

from __future__ import annotations

import fsm
import pytest

from fsmscope.fleet import keys
from fsm.observation import names, schema
from fsmscope.interop.channels import EVENTS
from node_support import map_in_schema_js, needs_node
from fsmscope.server.hub import Hub

NAMES = ["picker", "pick and place", "robot:arm", "ünïcødé", "x" * 200, "", " lead", "trail ", "task#2",
         "a/b", "*", "$x", "what?", "tab\there", "bell\x07", "del\x7f", "x" * 201, "\u00a0nbsp", "😀" * 200]


def _machine() -> fsm.StateMachine:
    sm = fsm.StateMachine(["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(lambda ud: "done", outcomes=["done"]))
    return sm


@pytest.mark.parametrize("name", NAMES)
def test_the_schema_and_the_fleet_keys_take_the_same_names(name):
    event = schema.event(1, 0.0, None, name, "log", "/SM_ROOT", {"level": "info", "msg": ""})
    fits_events = schema.validate(event) is None
    try:
        keys.machine_key("r1", name)
        fits_keys = True
    except ValueError:
        fits_keys = False
    assert fits_events == fits_keys == names.is_valid(name)


@pytest.mark.parametrize("text", NAMES + ["/smach_server/arm", "###", "   "])
def test_a_name_made_of_any_text_is_valid_and_one_topic_level(text):
    name = names.valid(text)
    assert names.is_valid(name)
    assert (EVENTS % name).count("/") == 3


def test_a_name_made_unique_is_cut_to_leave_room_for_its_number():
    taken = {names.valid("y" * 300)}
    name = names.unique("y" * 300, taken)
    assert name == "y" * 198 + "-2" and names.is_valid(name)


def test_the_hub_names_a_second_machine_of_a_name_as_the_runner_does():
    hub = Hub()
    first, second = hub.add_local(_machine(), "task"), hub.add_local(_machine(), "task")
    assert (first.name, second.name) == ("task", names.unique("task", {"task"})) == ("task", "task-2")


def test_the_hub_makes_a_valid_name_of_an_unusable_one():
    assert Hub().add_local(_machine(), "pick/place").name == "pick_place"


@needs_node
def test_the_page_takes_the_same_names_as_python():
    """fsmscope/static/schema.js isMachineName, generated from fsm/observation/names.py, mirrors names.is_valid."""
    assert map_in_schema_js("n => m.isMachineName(n)", NAMES) == [names.is_valid(n) for n in NAMES]


def test_a_robot_named_with_the_fleets_separator_is_refused_before_it_joins():
    from fsmscope.fleet.robot import ZenohRobot

    with pytest.raises(ValueError, match="a robot's name must not hold ':'"):
        ZenohRobot("lab:1")
