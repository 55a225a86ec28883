"""A structure node carries the first paragraph of its class's docstring (``doc``), for the page's details."""

from __future__ import annotations

import fsm
from fsm.observation.introspection import class_doc
from fsm.observation.schema import MAX_DOC


class Documented(fsm.State):
    """Picks the cube
    from the table.

    Retries three times; this paragraph is not shown."""


class Verbose(fsm.State):
    __doc__ = "word " * 200


class Plain(Documented):
    pass


def test_the_first_paragraph_on_one_line():
    assert class_doc(Documented) == "Picks the cube from the table."


def test_a_long_docstring_is_cut_at_the_limit():
    doc = class_doc(Verbose)
    assert len(doc) == MAX_DOC and doc.endswith("…")


def test_a_docstring_is_not_inherited():
    assert class_doc(Plain) is None


def test_fsm_own_classes_have_none():
    assert class_doc(fsm.StateMachine) is None


def test_the_structure_node_carries_it():
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("PICK", Documented(outcomes=["done"]), {"done": "done"})
    root = fsm.attach(sm, name="documented").structure()
    assert root["children"][0]["doc"] == "Picks the cube from the table." and "doc" not in root
