"""The REST models of fsmscope/server/models.py say what the schema says (fsm/observation/schema/): the same
fields, each allowing null exactly when the schema does, of the same kind of value. A field added to
or changed in one and not the other fails here."""

from __future__ import annotations

import typing

import pytest
from pydantic import BaseModel

from fsm.observation import schema
from fsmscope.server import control_models, models

NONE = type(None)

# (model, the schema's fields, the schema's fields the model leaves out, the model's own additions)
PAIRS = [
    (models.MachineStatus, schema.STATUS_FIELDS, {"structure"}, {"preempt_waiting_on"}),
    (models.ContainerStatus, schema.CONTAINER_STATUS_FIELDS, set(), set()),
    (models.LastTransition, schema.LAST_TRANSITION_FIELDS, set(), set()),
    (models.PendingPreempt, schema.PREEMPT_FIELDS, set(), set()),
    (models.Pose, schema.POSE_FIELDS, set(), set()),
    (models.DebugState, schema.DEBUG_STATUS_FIELDS, set(), set()),
    (models.Hold, schema.HOLD_FIELDS, set(), set()),
    (models.BreakpointSpec, schema.BREAKPOINT_FIELDS, set(), set()),
    (models.StructureNode, schema.NODE.shape, set(), set()),
    (models.Transition, schema.TRANSITION_FIELDS, set(), set()),
    (models.Tile, schema.TILE_FIELDS, set(), set()),
]


def _schema_kind(t: schema.Type) -> str:
    if t.shape is not None:
        return "object"
    kinds = {str: "string", bool: "boolean", int: "number", float: "number", list: "array", dict: "object"}
    found = {kinds[p] for p in (t.types or ()) if p is not NONE}
    return found.pop() if len(found) == 1 else "any"


def _model_kind(annotation: typing.Any) -> str:
    args = [a for a in typing.get_args(annotation) if a is not NONE]
    if typing.get_origin(annotation) is typing.Union:
        annotation = args[0] if len(args) == 1 else typing.Any
    origin = typing.get_origin(annotation) or annotation
    if origin is typing.Literal:
        return "string"
    if isinstance(origin, type) and issubclass(origin, BaseModel):
        return "object"
    return {str: "string", bool: "boolean", int: "number", float: "number", list: "array", tuple: "array",
            dict: "object"}.get(origin, "any")


def _allows_null(annotation: typing.Any) -> bool:
    return annotation is typing.Any or NONE in typing.get_args(annotation)


def _model_fields(model: type[BaseModel]) -> dict[str, typing.Any]:
    return {info.alias or name: info.annotation for name, info in model.model_fields.items()}


@pytest.mark.parametrize("model,fields,left_out,added", PAIRS, ids=[p[0].__name__ for p in PAIRS])
def test_a_rest_model_has_the_fields_of_its_shape_in_the_schema(model, fields, left_out, added):
    assert set(_model_fields(model)) == {f.name for f in fields} - left_out | added


@pytest.mark.parametrize("model,fields,left_out,added", PAIRS, ids=[p[0].__name__ for p in PAIRS])
def test_a_rest_model_allows_null_where_the_schema_does_and_holds_the_same_kind_of_value(model, fields, left_out,
                                                                                        added):
    own = _model_fields(model)
    wrong = []
    for f in fields:
        if f.name not in own:
            continue
        if (f.type.null or f.required) and f.type.null != _allows_null(own[f.name]):
            said = "allowed" if f.type.null else "refused"
            wrong.append("%s.%s: null %s in the schema" % (model.__name__, f.name, said))
        kinds = {_schema_kind(f.type), _model_kind(own[f.name])}
        if len(kinds - {"any"}) > 1:
            wrong.append("%s.%s: %s" % (model.__name__, f.name, " vs ".join(sorted(kinds))))
    assert wrong == []


def test_the_models_vocabularies_are_the_schemas():
    assert typing.get_args(models.MachineInfo.model_fields["source"].annotation) == schema.SOURCES
    assert typing.get_args(control_models.Deadman.model_fields["action"].annotation) == schema.DEADMAN_ACTIONS
    assert typing.get_args(models.Tile.model_fields["source"].annotation) == schema.SOURCES
    assert typing.get_args(models.Tile.model_fields["state"].annotation) == schema.TILE_STATES
