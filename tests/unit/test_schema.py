"""fsm.observation.schema: every event the runtime emits fits it; what does not fit is refused in words."""

from __future__ import annotations

import glob
import os

import fsm
import pytest
from fsm.observation import schema
from fsm.logfiles.log_reader import read_events

from event_support import deep_root, ev, flat_root, run_of
from server_support import nested_machine, two_state_machine


def test_every_event_of_an_observed_run_fits_the_schema():
    events = []
    for sm in (two_state_machine(), nested_machine()):
        fsm.attach(sm, events.append)
        sm.execute()
    assert events and [schema.validate(e) for e in events] == [None] * len(events)


def test_every_event_of_the_examples_fits_the_schema(tmp_path):
    from fsmscope.server.runner import Runner

    for script in sorted(glob.glob(os.path.join(os.path.dirname(__file__), "..", "..", "examples", "*.py"))):
        log = tmp_path / (os.path.basename(script) + ".jsonl")
        Runner(script, [], str(log)).run()
        problems = []
        events = list(read_events(log, on_problem=problems.append))
        assert events and not problems, (script, problems[:3])


def test_a_snapshot_of_a_recorded_run_fits_the_schema(tmp_path):
    sm = two_state_machine()
    with fsm.Recorder(tmp_path / "run.jsonl", snapshot_every=2) as recorder:
        fsm.attach(sm, recorder, name="two")
        sm.execute()
    snapshots = [e for e in read_events(tmp_path / "run.jsonl") if e["kind"] == "snapshot"]
    assert snapshots and all(schema.validate(e) is None for e in snapshots)


def test_a_terminate_whose_outcome_is_a_number_is_refused_in_words():
    bad = ev(3, "terminate", last=["A"], outcome=5)
    assert schema.validate(bad) == "terminate.outcome must be a string or null, not an integer"


def test_a_time_that_is_not_a_number_is_refused():
    bad = ev(3, "log", level="info", msg="hi")
    bad["t"] = "yesterday"
    assert schema.validate(bad) == "event.t must be a finite number, not a string"


def test_a_transition_without_from_is_refused():
    bad = ev(3, "transition", outcome="go", to="B", active=["B"])
    assert schema.validate(bad) == "transition lacks 'from'"


def test_an_unknown_kind_is_refused():
    assert schema.validate(ev(3, "teleport")) == "unknown kind 'teleport'"


def test_a_structure_whose_child_path_does_not_follow_its_label_is_refused():
    root = flat_root("A")
    root["children"][0]["path"] = "/ELSEWHERE/A"
    problem = schema.validate(ev(1, "structure", root=root))
    assert "should be '/SM_ROOT/A'" in problem


def test_a_structure_deeper_than_the_limit_is_refused():
    problem = schema.validate(ev(1, "structure", root=deep_root(200)))
    assert problem == "structure.root the structure is deeper than %d levels" % schema.MAX_STRUCTURE_DEPTH


def test_a_structure_within_the_depth_limit_fits():
    assert schema.validate(ev(1, "structure", root=deep_root(schema.MAX_STRUCTURE_DEPTH - 1))) is None


def test_a_nested_snapshot_problem_names_where_it_is():
    status = {"containers": {"/SM_ROOT": {"active": [7], "initial": [], "userdata": {}, "running": True,
                                          "outcome": None}}, "running": True, "outcome": None}
    assert schema.validate(ev(4, "snapshot", status=status)) == \
        "snapshot.status.containers['/SM_ROOT'].active[0] must be a string, not an integer"


def test_a_userdata_value_nested_past_the_limit_is_refused():
    value: list = []
    for _ in range(schema.MAX_VALUE_DEPTH + 2):
        value = [value]
    assert "nested deeper" in schema.validate(ev(3, "userdata", changes={"k": value}))


def test_a_sequence_number_beyond_what_a_browser_holds_exactly_is_refused():
    bad = ev(3, "log", level="info", msg="hi")
    bad["seq"] = 2 ** 53
    assert schema.validate(bad).startswith("event.seq must be an integer from 0 to 2^53-1")


@pytest.mark.parametrize("event", run_of(flat_root("A", "B")), ids=lambda e: e["kind"])
def test_the_test_support_run_is_valid(event):
    assert schema.validate(event) is None


def test_graph_ids_escape_control_characters_and_percent_one_to_one():
    assert schema.state_id("/SM_ROOT/VT\x0bBAD") == "s:/SM_ROOT/VT%0BBAD"
    assert schema.state_id("/SM_ROOT/100%") == "s:/SM_ROOT/100%25"
    assert schema.edge_id("/R", "A\n", "go") == "e:/R:A%0A:go"
    assert schema.state_id("/SM_ROOT/VT%0BBAD") != schema.state_id("/SM_ROOT/VT\x0bBAD")


def _names(fields):
    return {f.name for f in fields}


def test_a_kinds_own_fields_are_its_events_without_the_envelope():
    joints, bodies = {"j1": 0.5}, {"cube": [0.4, 0.1, 0.4, 1.0, 0.0, 0.0, 0.0]}
    event = schema.build.pose(1, 0.0, None, "m", "/SM_ROOT", joints, bodies)
    envelope = {f.name for f in schema.ENVELOPE}
    assert schema.fields_of.pose(joints, bodies) == {k: v for k, v in event.items() if k not in envelope}
    assert schema.fields_of.pose(joints) == {"joints": joints}


@pytest.mark.parametrize("name", list(schema.MESSAGES))
def test_a_frames_field_names_are_in_the_order_its_maker_takes_them(name):
    made = getattr(schema.frame, name)(*schema.field_names(name))
    assert list(made) == ["type", *schema.field_names(name)]
    assert [made[field] for field in schema.field_names(name)] == list(schema.field_names(name))


def test_the_reducers_status_holds_the_fields_of_the_schemas_status_and_no_other():
    from fsm.observation.status import Status

    status = Status("m")
    for event in (ev(1, "structure", root=flat_root("A", "B")),
                  ev(2, "start", initial=["A"], active=["A"], userdata={}),
                  ev(3, "transition", **{"from": "A", "outcome": "go", "to": "B", "active": ["B"]}),
                  ev(4, "preempt", phase="requested"), ev(5, "pose", joints={"j1": 0.5}),
                  ev(6, "debug", action="hold", state="B", at="before", outcome=None, reason="pause", detail="paused"),
                  ev(7, "debug", action="breakpoints", breakpoints=[
                      {"state": "/SM_ROOT/B", "at": "before", "outcome": None, "when": None}])):
        status.apply(event)
    data = status.to_dict()
    debug = data["debug"]
    shapes = {"status": (set(data), _names(schema.STATUS_FIELDS)),
              "container": (set(data["containers"]["/SM_ROOT"]), _names(schema.CONTAINER_STATUS_FIELDS)),
              "last": (set(data["containers"]["/SM_ROOT"]["last"]), _names(schema.LAST_TRANSITION_FIELDS)),
              "preempt": (set(data["preempt"]), _names(schema.PREEMPT_FIELDS)),
              "pose": (set(data["pose"]), _names(schema.POSE_FIELDS)),
              "debug": (set(debug), _names(schema.DEBUG_STATUS_FIELDS)),
              "hold": (set(debug["holds"][0]), _names(schema.HOLD_FIELDS)),
              "breakpoint": (set(debug["breakpoints"][0]), _names(schema.BREAKPOINT_FIELDS))}
    assert {name: made for name, (made, defined) in shapes.items() if made != defined} == {}
    assert schema.STATUS.check(data) is None


def test_a_batch_of_step_records_and_events_is_made_as_the_makers_make_each_stamped_in_order():
    steps = [(1.0, "r1", "m", "/SM_ROOT", "A", "go", "B", ["B"], schema.ABSENT),
             (2.0, "r1", "m", "/SM_ROOT", "B", "go", "A", ["A"], {"count": 2})]
    start = schema.build.start(0, 0.5, "r1", "m", "/SM_ROOT", ["A"], ["A"], {})
    made = schema.build_batch(7, [start, *steps])
    expected = [schema.build.start(7, 0.5, "r1", "m", "/SM_ROOT", ["A"], ["A"], {}),
                schema.build.transition(8, *steps[0]), schema.build.transition(9, *steps[1])]
    assert [list(event.items()) for event in made] == [list(event.items()) for event in expected]
    assert made[0] is start
