"""The browser's fsmscope/static/schema.js, the tables of docs/events.md and the frame tables of docs/api.md are
generated from fsm/observation/schema/ and must not drift from it."""

from __future__ import annotations

from fsm.observation import schema
from fsmscope.server import schema_export


def read(path: str) -> str:
    with open(path, encoding="utf-8") as handle:
        return handle.read()


def test_static_schema_js_is_generated_from_the_python_definition():
    assert read(schema_export.JS_PATH) == schema_export.javascript(), "run: python -m fsmscope.server.schema_export"


def test_the_tables_of_docs_events_md_are_generated_from_the_python_definition():
    doc = read(schema_export.DOC_PATH)
    assert schema_export.events_doc(doc) == doc, "run: python -m fsmscope.server.schema_export"


def test_docs_events_md_has_a_table_for_every_kind_and_every_nested_object():
    assert schema_export.blocks(read(schema_export.DOC_PATH)) == set(schema_export.tables())


def test_each_kind_s_table_in_docs_events_md_lists_that_kind_s_own_fields():
    doc = read(schema_export.DOC_PATH)
    for name, kind in schema.KINDS.items():
        table = doc.split("<!-- schema:%s -->\n" % name, 1)[1].split("<!-- /schema -->", 1)[0]
        assert [row.split("`")[1] for row in table.splitlines()[2:]] == [f.name for f in kind.fields], name


def test_the_frame_tables_of_docs_api_md_are_generated_from_the_python_definition():
    doc = read(schema_export.API_DOC_PATH)
    assert schema_export.api_doc(doc) == doc, "run: python -m fsmscope.server.schema_export"


def test_docs_api_md_has_every_generated_table_and_every_frame_is_in_one():
    assert schema_export.blocks(read(schema_export.API_DOC_PATH)) == set(schema_export.api_tables())
    listed = [name for names in schema_export.SOCKETS.values() for name in names]
    assert sorted(listed) == sorted(schema.MESSAGES)
