"""Any state name draws: control characters, percent signs and markup in names never break the SVG."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import fsm
from fsm.observation.schema import state_id

from server_support import client

SVG = "{http://www.w3.org/2000/svg}"
NAMES = ["VT\x0bBAD", "NUL\x00", "100%", "<b>bold</b>", "quote\"back\\slash", "line\nbreak"]


def machine_named(*labels: str) -> fsm.StateMachine:
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        for a, b in zip(labels, labels[1:] + ("done",)):
            fsm.StateMachine.add(a, fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": b})
    return sm


def test_states_with_control_characters_in_their_names_draw(live_server):
    live_server.hub.add_local(machine_named(*NAMES), name="odd")
    answer = client(live_server).get("/api/machines/odd/graph.svg")
    assert answer.status_code == 200, answer.text
    svg = ET.fromstring(answer.content)
    ids = {g.get("id") for g in svg.iter(SVG + "g")}
    assert {state_id("/SM_ROOT/" + name) for name in NAMES} <= ids


def test_a_control_character_is_shown_as_its_control_picture():
    from fsmscope.server import graph

    root = machine_named("VT\x0bBAD")
    rep = fsm.attach(root, name="pictures")
    svg = ET.fromstring(graph.render(rep.structure(), "pictures-test"))
    texts = {t.text for t in svg.iter(SVG + "text")}
    assert "VT\u240bBAD" in texts
