"""Every drawn state, container, outcome and edge is titled (its tooltip) by what it stands for, never by
the Graphviz node names ("n12") dot would write."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import fsm
from fsmscope.server import graph
from fsmscope.server.testing.big_machine import big_machine

SVG = "{http://www.w3.org/2000/svg}"
GRAPHVIZ_NAME = re.compile(r"[no]\d+(->[no]\d+)?")


def drawn_titles(svg: bytes) -> dict[str, str]:
    """The title of each element with an id: {id: title}."""
    root = ET.fromstring(svg)
    return {g.get("id"): g.find(SVG + "title").text for g in root.iter(SVG + "g") if g.get("id")}


def big_structure() -> dict:
    fsm.set_loggers(*(lambda msg: None,) * 4)
    sm, _ = big_machine(branching=2, depth=3, leaves=3)
    return fsm.attach(sm, name="titled").structure()


def test_a_state_is_titled_by_its_path_and_class():
    titles = drawn_titles(graph.render(big_structure(), "titles-state"))
    assert titles["s:/SM_ROOT/TASK_0/W_0_1"] == "/SM_ROOT/TASK_0/W_0_1 (Work)"


def test_an_open_container_is_titled_by_its_path_and_class():
    titles = drawn_titles(graph.render(big_structure(), "titles-container"))
    assert titles["c:/SM_ROOT/TASK_0/TASK_0_1"] == "/SM_ROOT/TASK_0/TASK_0_1 (Concurrence)"


def test_no_title_is_a_graphviz_node_name():
    titles = drawn_titles(graph.render(big_structure(), "titles-none"))
    named = {eid: t for eid, t in titles.items() if GRAPHVIZ_NAME.fullmatch(t)}
    assert not named


def test_an_edge_is_titled_by_its_transition():
    titles = drawn_titles(graph.render(big_structure(), "titles-edge"))
    assert titles["e:/SM_ROOT:W_0:done"] == "/SM_ROOT: W_0 --done--> W_1"
