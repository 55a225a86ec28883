"""The browser's fsmscope/static/schema.js, the tables of docs/events.md and the frame tables of docs/api.md are
generated from fsm/observation/schema/ and must not drift from it."""

from __future__ import annotations

from fsm.observation import schema
from fsmscope.server import schema_export


def read(path: str) -> str:
    with open(path, encoding="utf-8") as handle:
        return handle.read()


def test_static_schema_js_is_generated_from_the_python_definition():
    assert read(schema_export.JS_PATH) == schema_export.javascript(), "run: python -m server.schema_export"


def test_the_tables_of_docs_events_md_are_generated_from_the_python_definition():
    doc = read(schema_export.DOC_PATH)
    assert schema_export.events_doc(doc) == doc, "run: python -m server.schema_export"


def test_docs_events_md_has_a_table_for_every_kind_and_every_nested_object():
    assert schema_export.blocks(read(schema_export.DOC_PATH)) == set(schema_export.tables())


def test_the_frame_tables_of_docs_api_md_are_generated_from_the_python_definition():
    doc = read(schema_export.API_DOC_PATH)
    assert schema_export.api_doc(doc) == doc, "run: python -m server.schema_export"


def test_docs_api_md_has_every_generated_table_and_every_frame_is_in_one():
    assert schema_export.blocks(read(schema_export.API_DOC_PATH)) == set(schema_export.api_tables())
    listed = [name for names in schema_export.SOCKETS.values() for name in names]
    assert sorted(listed) == sorted(schema.MESSAGES)
