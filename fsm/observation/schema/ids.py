"""Graph element ids (docs/api.md), part of the contract between the server's SVG and the page.

A path can hold any character; XML cannot hold control characters, so those (and '%', to keep the
mapping one to one) are percent-escaped."""

from __future__ import annotations

ID_PREFIXES = {"state": "s:", "container": "c:", "outcome": "o:", "edge": "e:"}
ID_ESCAPES = {c: "%%%02X" % c for c in [*range(0x20), 0x25, 0x7F]}
ID_ESCAPES.update({c: "%%u%04X" % c for c in (0xFFFE, 0xFFFF)})


def id_text(text: str) -> str:
    """``text`` safe for an XML attribute: control characters and '%' percent-escaped."""
    return text.translate(ID_ESCAPES)


def state_id(path: str) -> str:
    return "s:" + id_text(path)


def container_id(path: str) -> str:
    return "c:" + id_text(path)


def outcome_id(path: str, outcome: str) -> str:
    return "o:%s:%s" % (id_text(path), id_text(outcome))


def edge_id(path: str, frm: str, outcome: str) -> str:
    return "e:%s:%s:%s" % (id_text(path), id_text(frm), id_text(outcome))
