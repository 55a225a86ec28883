"""One event per step (docs/events.md): a step that writes its container's userdata is one
``transition`` (or ``terminate``) carrying the keys it wrote in ``changes``, not a ``userdata`` event
before it; and a log written before, with the two events, reads the same to every reader: the
``Status`` and its JavaScript mirror, the transcript, a userdata key's history."""

from __future__ import annotations

import json
import pathlib
import shutil
import subprocess

import fsm
import pytest
from fsm.logfiles.log_reader import seek
from fsm.logfiles.transcript import Transcript
from fsm.observation.status import Status

from smach_support import Out, concurrence, machine

STATIC = pathlib.Path(__file__).resolve().parents[2] / "fsmscope" / "static"
NODE = shutil.which("node")
needs_node = pytest.mark.skipif(NODE is None, reason="Node.js is not installed")


def _count(ud):
    ud.n = ud.n + 1
    return "again" if ud.n < 3 else "enough"


def _final(ud):
    ud.final = "n was %d" % ud.n
    return "finished"


def writing_machine() -> fsm.StateMachine:
    """COUNT writes n three times (looping on itself), then SPLIT (a Concurrence whose two children
    each write a key), ITER (an Iterator over two items, its body writing nothing), QUIET (writes
    nothing), LAST (writes final, ending the machine)."""
    split = concurrence(["done"], "done", [
        ("LEFT", Out(lambda ud: setattr(ud, "left", 1) or "done", output_keys=["left"])),
        ("RIGHT", Out(lambda ud: setattr(ud, "right", 2) or "done", output_keys=["right"]))])
    it = fsm.Iterator(outcomes=["done"], input_keys=[], output_keys=[], it=[10, 20])
    with it:
        fsm.Iterator.set_contained_state("BODY", Out("next", outcomes=["next"]), loop_outcomes=["next"])
    sm = machine(["finished"], [
        ("COUNT", Out(_count, outcomes=["again", "enough"], io_keys=["n"]), {"again": "COUNT", "enough": "SPLIT"}),
        ("SPLIT", split, {"done": "ITER"}),
        ("ITER", it, {"exhausted": "QUIET", "done": "QUIET"}),
        ("QUIET", Out("on"), {"on": "LAST"}),
        ("LAST", Out(_final, outcomes=["finished"], input_keys=["n"], output_keys=["final"]), {"finished": "finished"})])
    sm.userdata.n = 0
    return sm


@pytest.fixture(scope="module")
def events() -> list[dict]:
    """A run of ``writing_machine``'s events, as a log holds them (JSON)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    seen: list[dict] = []
    reporter = fsm.attach(writing_machine(), seen.append, name="m")
    try:
        assert reporter.root.execute() == "finished"
    finally:
        reporter.remove_observer(seen.append)
    return json.loads(json.dumps(seen))


def _steps(events, path, kinds=("transition", "terminate")):
    return [(e["kind"], e.get("from", (e.get("last") or [None])[0]), e.get("changes"))
            for e in events if e["path"] == path and e["kind"] in kinds]


def test_a_run_whose_steps_write_userdata_sends_no_userdata_event(events):
    assert [e for e in events if e["kind"] == "userdata"] == []


def test_a_step_that_writes_is_one_transition_carrying_the_keys_it_wrote(events):
    assert _steps(events, "/SM_ROOT")[:4] == [
        ("transition", "COUNT", {"n": 1}), ("transition", "COUNT", {"n": 2}), ("transition", "COUNT", {"n": 3}),
        ("transition", "SPLIT", None)]


def test_the_last_step_s_writes_ride_on_its_container_s_terminate(events):
    assert _steps(events, "/SM_ROOT")[-2:] == [("transition", "QUIET", None),
                                              ("terminate", "LAST", {"final": "n was 3"})]


def test_a_concurrence_child_s_writes_ride_on_the_transition_of_its_return(events):
    assert sorted(_steps(events, "/SM_ROOT/SPLIT", ("transition",)), key=repr) == [
        ("transition", "LEFT", {"left": 1}), ("transition", "RIGHT", {"right": 2})]


def test_an_iterator_s_item_rides_on_the_transition_of_the_iteration_it_ran(events):
    assert _steps(events, "/SM_ROOT/ITER") == [
        ("transition", "BODY", {"it_data": 10}), ("transition", "BODY", {"it_data": 20}), ("terminate", "BODY", None)]


# A log written before transitions carried their step's writes: the same run, with a userdata event
# before each transition or terminate that carries some. Every event keeps its place: event i of the
# run is seq 2i + 1 in both logs, a userdata event before it 2i.

def _renumbered(event: dict, seq: int) -> dict:
    return dict(event, seq=seq)


def as_written_now(events: list[dict]) -> list[dict]:
    return [_renumbered(e, 2 * i + 1) for i, e in enumerate(events)]


def as_written_before(events: list[dict]) -> list[dict]:
    older = []
    for i, event in enumerate(events):
        if "changes" in event and event["kind"] != "userdata":
            older.append(fsm.observation.schema.event(2 * i, event["t"], event["run"], event["machine"], "userdata",
                                                      event["path"], {"changes": event["changes"]}))
            event = {k: v for k, v in event.items() if k != "changes"}
        older.append(_renumbered(event, 2 * i + 1))
    return older


def _statuses(events: list[dict]) -> dict[int, dict]:
    """The Status after each odd seq (an event of the run), as a dict."""
    status, after = Status("m"), {}
    for event in events:
        status.apply(event)
        if event["seq"] % 2:
            after[event["seq"]] = status.to_dict()
    return after


def test_the_older_log_is_one_of_userdata_events_before_transitions(events):
    older = as_written_before(events)
    assert all(fsm.observation.schema.validate(e) is None for e in older)
    kinds = [e["kind"] for e in older]
    assert kinds.count("userdata") == 8 and "changes" not in {k for e in older if e["kind"] != "userdata" for k in e}


def test_an_older_log_rebuilds_the_same_status_after_every_event(events):
    assert _statuses(as_written_before(events)) == _statuses(as_written_now(events))


def test_an_older_log_file_seeks_to_the_same_status(events, tmp_path):
    now, before = tmp_path / "now.jsonl", tmp_path / "before.jsonl"
    for path, log in ((now, as_written_now(events)), (before, as_written_before(events))):
        path.write_text("".join(json.dumps(e) + "\n" for e in log), encoding="utf-8")
    for seq in range(1, 2 * len(events), 2):
        assert seek(before, "m", seq).status.to_dict() == seek(now, "m", seq).status.to_dict()


def test_an_older_log_replays_to_the_same_transcript(events):
    def lines(log):
        transcript = Transcript()
        return [(line.level, line.path, line.msg) for e in log for line in transcript.lines(e)]
    assert lines(as_written_before(events)) == lines(as_written_now(events))


def _in_node(script: str, logs: dict) -> object:
    """What ``script`` (an ES module body with ``Status``, ``keyHistory`` and ``logs`` in scope) prints as JSON."""
    prelude = (f'import {{ Status }} from "{(STATIC / "status.js").as_uri()}";\n'
               f'import {{ keyHistory }} from "{(STATIC / "userdata.js").as_uri()}";\n'
               'import { readFileSync } from "node:fs";\n'
               "const logs = JSON.parse(readFileSync(0, 'utf8'));\n")
    out = subprocess.run([NODE, "--input-type=module", "-e", prelude + script], input=json.dumps(logs),
                         capture_output=True, text=True, timeout=30, check=True)
    return json.loads(out.stdout)


FOLD = """
const folded = {};
for (const [name, log] of Object.entries(logs)) {
  const status = new Status("m");
  const after = {};
  for (const ev of log) {
    status.apply(ev);
    if (ev.seq % 2) after[ev.seq] = JSON.parse(JSON.stringify(status.containers));
  }
  folded[name] = after;
}
console.log(JSON.stringify(folded));
"""


@needs_node
def test_the_page_s_status_folds_an_older_log_as_the_new_one_and_as_python_does(events):
    folded = _in_node(FOLD, {"before": as_written_before(events), "now": as_written_now(events)})
    python = {str(seq): status["containers"] for seq, status in _statuses(as_written_now(events)).items()}
    assert folded["before"] == folded["now"] == python


HISTORY = """
const root = (log) => log.filter((ev) => ev.path === "/SM_ROOT");
const strip = (items) => items.map(({ state, value }) => ({ state, value }));
console.log(JSON.stringify(Object.fromEntries(Object.entries(logs).map(([name, log]) =>
  [name, { n: strip(keyHistory(root(log), "n")), final: strip(keyHistory(root(log), "final")) }]))));
"""


@needs_node
def test_a_key_s_history_beside_the_userdata_is_the_same_from_an_older_log(events):
    history = _in_node(HISTORY, {"before": as_written_before(events), "now": as_written_now(events)})
    assert history["before"] == history["now"] == {
        "n": [{"state": "(start)", "value": 0}] + [{"state": "COUNT", "value": n} for n in (1, 2, 3)],
        "final": [{"state": "LAST", "value": "n was 3"}]}
