"""The graph's cache: a drawing composed from cached containers is the very document a fresh renderer
lays out, and opening one container lays out only it and its ancestors."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import fsm
from fsmscope.server import graph
from fsmscope.server.testing.big_machine import big_machine

SVG = "{http://www.w3.org/2000/svg}"


def structure() -> dict:
    fsm.set_loggers(*(lambda msg: None,) * 4)
    sm, _ = big_machine(branching=2, depth=3, leaves=3)
    return fsm.attach(sm, name="cached").structure()


def containers(node: dict) -> list[str]:
    found = [node["path"]] if node.get("container") else []
    for child in node.get("children") or ():
        found += containers(child)
    return found


def test_a_drawing_from_cached_containers_is_the_document_a_fresh_renderer_draws():
    root = structure()
    paths = containers(root)
    warm = graph.Renderer()
    for expand in ([root["path"]], paths[:3], paths[:5], paths):  # each drawing reuses the ones before
        warm.render(root, "k", expand)
    assert warm.render(root, "k", paths[:4]) == graph.Renderer().render(root, "k", paths[:4])


def test_opening_a_container_lays_out_only_it_and_its_ancestors():
    root = structure()
    renderer = graph.Renderer()
    deep = max(containers(root), key=lambda p: p.count("/"))
    ancestors = [deep.rsplit("/", i)[0] for i in range(1, deep.count("/")) if deep.rsplit("/", i)[0]]
    renderer.render(root, "k", ancestors)
    before = renderer.layouts
    renderer.render(root, "k", ancestors + [deep])
    assert renderer.layouts - before == len(ancestors) + 1


def test_an_open_container_is_drawn_inside_its_parent():
    root = structure()
    paths = containers(root)
    drawn = ET.fromstring(graph.Renderer().render(root, "k", paths))
    parent_of = {child: parent for parent in drawn.iter(SVG + "g") for child in parent}
    for path in paths[1:]:
        g = drawn.find(".//%sg[@id='c:%s']" % (SVG, path))
        up = parent_of[g]
        while up.get("id") is None:
            up = parent_of[up]
        assert up.get("id") == "c:" + path.rsplit("/", 1)[0]


def test_no_id_carries_the_page_prefix_dot_gives_later_graphs_of_a_process():
    root = structure()
    drawn = graph.Renderer().render(root, "k", containers(root))  # several graphs a depth, one process
    assert b'id="page' not in drawn and b'id="c:/SM_ROOT/TASK_0/TASK_0_1"' in drawn
