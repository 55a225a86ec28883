"""The browser's static/schema.js and the tables of docs/events.md are generated from fsm/observation/schema/
and must not drift from it."""

from __future__ import annotations

from server import schema_export


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
