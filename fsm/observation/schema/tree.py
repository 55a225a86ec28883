"""The structure tree: the shape of a ``structure`` event's root (and a snapshot's structure), its
check (fields, paths, depth, size), and which of SMACH's containers a node is."""

from __future__ import annotations

from typing import Any

from .fields import (BOOL, LIST_STR, MAP_STR, MAX_DOC, MAX_STRUCTURE_DEPTH, MAX_STRUCTURE_NODES, OPT_STR, PATH, STR,
                     Field, Type, fields_problem, list_of, maker, object_of, shape, simple)

# Which of SMACH's containers a structure node is: its ``type`` when it is one of these, else (a
# user's subclass) the kind whose own field it carries, else a state machine.
CONTAINER_TYPES = ("StateMachine", "Sequence", "Concurrence", "Iterator")
KIND_FIELDS = (("outcome_map", "Concurrence"), ("exhausted_outcome", "Iterator"))


def container_kind(node: dict) -> str:
    """The SMACH container a structure node is, for readers that treat each kind differently."""
    kind = node.get("type", "StateMachine")
    if kind in CONTAINER_TYPES:
        return kind
    return next((kind for field, kind in KIND_FIELDS if field in node), "StateMachine")


TRANSITION_FIELDS = (Field("from", STR, doc="a child's label"), Field("outcome", STR, doc="one of its outcomes"),
                     Field("to", OPT_STR, doc="a child's label, a container outcome, or null (the container "
                                              "outcome of the same name)"))
NODE_FIELDS = (
    Field("label", STR, doc="the name its parent knows it by"),
    Field("path", PATH, doc="its parent's path, '/', its label"),
    Field("type", STR, doc="the class name (StateMachine, Concurrence, CBState, ...)"),
    Field("container", BOOL, doc="whether it holds children"),
    Field("outcomes", LIST_STR, doc="registered outcomes, sorted"),
    Field("input_keys", LIST_STR, doc="sorted"), Field("output_keys", LIST_STR, doc="sorted"),
    Field("remapping", MAP_STR, doc="its parent's remapping for it: {its key: the parent's key}"),
    Field("doc", STR, required=False, doc="the first paragraph of its class's docstring (at most %d characters); "
                                          "absent when the class has none or is one of fsm's own" % MAX_DOC),
)
CONTAINER_FIELDS = (
    Field("initial", LIST_STR, doc="initial states"),
    Field("transitions", list_of(shape("a transition", "Transition", TRANSITION_FIELDS), "a list of transitions"),
          doc="its edges (below)"),
    Field("children", Type("a list", simple("a list", (list,)).check, (list,), js="Array<StructureNode>"),
          doc="nodes, in add order"),
    Field("default_outcome", OPT_STR, required=False, doc="a Concurrence's"),
    Field("outcome_map", object_of(MAP_STR, "an object of objects of strings"), required=False,
          doc="a Concurrence's {container outcome: {child: outcome}}"),
)


def node_problem(node: Any, path: str | None = None) -> str | None:
    """What is wrong with a structure tree (None when nothing): fields, paths, depth and size."""
    count = [0]

    def walk(n: Any, expected: str | None, depth: int) -> str | None:
        where = expected or "root"
        if depth > MAX_STRUCTURE_DEPTH:
            return "the structure is deeper than %d levels" % MAX_STRUCTURE_DEPTH
        count[0] += 1
        if count[0] > MAX_STRUCTURE_NODES:
            return "the structure has more than %d states" % MAX_STRUCTURE_NODES
        problem = fields_problem(n, NODE_FIELDS, "node %s" % where)
        if problem:
            return problem
        if expected is not None and n["path"] != expected:
            return "node path %r should be %r (its parent's path, '/', its label)" % (n["path"], expected)
        if not n["container"]:
            return None
        problem = fields_problem(n, CONTAINER_FIELDS, "container %s" % n["path"])
        if problem:
            return problem
        for child in n["children"]:
            label = child.get("label") if type(child) is dict else None
            problem = walk(child, n["path"] + "/" + label if type(label) is str else n["path"] + "/?", depth + 1)
            if problem:
                return problem
        return None

    return walk(node, path, 0)


NODE = shape("a structure node (below)", "StructureNode",
             NODE_FIELDS + tuple(Field(f.name, f.type, False, "a container's: " + f.doc) for f in CONTAINER_FIELDS),
             lambda v: node_problem(v))


# The makers of a structure tree's parts, the fields in their order (optional ones by keyword, left out when
# not given): a node, a container's own fields (added to its node), one of its edges.
node = maker("node", (), NODE_FIELDS, "A structure node: every state's fields.")
container_fields = maker("container_fields", (), CONTAINER_FIELDS, "A container node's own fields.")
edge = maker("edge", (), TRANSITION_FIELDS, "One of a container's edges.")
