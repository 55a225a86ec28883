"""fsm.observation.structure: walking the running tree and the structure event's tree of one small
machine, ROOT(PREP, PAR: Concurrence(LEFT, SUB(X)))."""

from __future__ import annotations

import pytest

import fsm
from fsm.observation import schema, structure


def leaf() -> fsm.CBState:
    return fsm.CBState(lambda ud: "ok", outcomes=["ok"])


class Parallel(fsm.Concurrence):
    """A user's own Concurrence: its structure node carries its own type name."""


@pytest.fixture
def machine() -> fsm.StateMachine:
    sub = fsm.StateMachine(outcomes=["ok"])
    with sub:
        fsm.StateMachine.add("X", leaf())
    par = fsm.Concurrence(outcomes=["ok"], default_outcome="ok")
    with par:
        fsm.Concurrence.add("LEFT", leaf())
        fsm.Concurrence.add("SUB", sub)
    root = fsm.StateMachine(outcomes=["ok"])
    with root:
        fsm.StateMachine.add("PREP", leaf(), transitions={"ok": "PAR"})
        fsm.StateMachine.add("PAR", par)
    return root


@pytest.fixture
def tree(machine: fsm.StateMachine) -> dict:
    return fsm.attach(machine).structure()


# The running tree.

def test_containers_are_the_states_with_children(machine):
    assert structure.is_container(machine)
    assert structure.is_container(machine["PAR"])
    assert not structure.is_container(machine["PREP"])


def test_children_are_a_containers_states_by_label_and_none_for_a_leaf(machine):
    assert list(structure.children(machine)) == ["PREP", "PAR"]
    assert list(structure.children(machine["PAR"])) == ["LEFT", "SUB"]
    assert structure.children(machine["PREP"]) == {}


def test_state_at_follows_labels_down_through_a_concurrence(machine):
    assert structure.state_at(machine, ["PAR", "SUB", "X"]) is machine["PAR"]["SUB"]["X"]
    assert structure.state_at(machine, []) is machine


def test_state_at_is_none_for_an_unknown_label_or_a_label_below_a_leaf(machine):
    assert structure.state_at(machine, ["PAR", "NOPE"]) is None
    assert structure.state_at(machine, ["PREP", "X"]) is None


def test_is_concurrence_by_class_subclasses_included(machine):
    assert structure.is_concurrence(machine["PAR"])
    assert structure.is_concurrence(Parallel(outcomes=["ok"], default_outcome="ok"))
    assert not structure.is_concurrence(machine)
    assert not structure.is_concurrence(machine["PAR"]["SUB"])
    assert not structure.is_concurrence(machine["PREP"])


# The structure event's tree.

def test_walk_gives_every_node_parents_first_in_child_order_with_its_depth(tree):
    assert [(node["path"], depth) for node, depth in structure.walk(tree)] == [
        ("/SM_ROOT", 0), ("/SM_ROOT/PREP", 1), ("/SM_ROOT/PAR", 1), ("/SM_ROOT/PAR/LEFT", 2),
        ("/SM_ROOT/PAR/SUB", 2), ("/SM_ROOT/PAR/SUB/X", 3)]


def test_walk_skips_the_children_of_containers_descend_refuses(tree):
    paths = [node["path"] for node, _ in structure.walk(tree, lambda node: node["path"] != "/SM_ROOT/PAR")]
    assert paths == ["/SM_ROOT", "/SM_ROOT/PREP", "/SM_ROOT/PAR"]


def test_walk_never_visits_children_of_a_node_that_is_no_container():
    odd = {"path": "/R", "container": True, "children": [
        {"path": "/R/A", "container": False, "children": [{"path": "/R/A/B", "container": False}]}]}
    assert [node["path"] for node, _ in structure.walk(odd)] == ["/R", "/R/A"]


def test_containers_are_the_container_nodes_in_walk_order(tree):
    assert [node["path"] for node in structure.containers(tree)] == ["/SM_ROOT", "/SM_ROOT/PAR", "/SM_ROOT/PAR/SUB"]


def test_count_counts_every_state_containers_included(tree):
    assert structure.count(tree) == 6
    assert structure.count(None) == 0


def test_node_at_finds_a_node_by_its_path(tree):
    assert structure.node_at(tree, "/SM_ROOT/PAR/SUB/X")["label"] == "X"
    assert structure.node_at(tree, "/SM_ROOT") is tree


def test_node_at_is_none_for_a_path_not_in_the_tree(tree):
    assert structure.node_at(tree, "/SM_ROOT/PAR/NOPE") is None
    assert structure.node_at(tree, "/ELSEWHERE") is None
    assert structure.node_at(None, "/SM_ROOT") is None


def test_container_kind_is_the_type_of_smachs_own_containers(tree):
    assert schema.container_kind(tree) == "StateMachine"
    assert schema.container_kind(structure.node_at(tree, "/SM_ROOT/PAR")) == "Concurrence"


def test_container_kind_of_a_concurrence_subclass_comes_from_its_outcome_map():
    par = Parallel(outcomes=["ok"], default_outcome="ok")
    with par:
        Parallel.add("A", leaf())
    node = fsm.attach(par).structure()
    assert node["type"] == "Parallel"
    assert schema.container_kind(node) == "Concurrence"


def test_container_kind_of_an_iterator_subclass_comes_from_its_exhausted_outcome():
    class Loop(fsm.Iterator):
        pass

    loop = Loop(outcomes=["ok"], input_keys=[], output_keys=[], it=[])
    with loop:
        Loop.set_contained_state("BODY", leaf(), loop_outcomes=["ok"])
    assert schema.container_kind(fsm.attach(loop).structure()) == "Iterator"


def test_container_kind_of_any_other_container_is_statemachine():
    class Plan(fsm.StateMachine):
        pass

    plan = Plan(outcomes=["ok"])
    with plan:
        Plan.add("STEP", leaf())
    assert schema.container_kind(fsm.attach(plan).structure()) == "StateMachine"
