"""The page's one store (fsmscope/static/store.js) and what the notice says of the runs (fsmscope/static/notice.js's
RunNotices), run in Node on the events of a real run: subscribers hear which part of the state
changed, the structure's nodes are indexed again only when it changes, and the notice is the store's
state (what it says is never read back from the page)."""

from __future__ import annotations

import json
import pathlib
import shutil
import subprocess

import fsm
import pytest
from server_support import nested_machine

STATIC = pathlib.Path(__file__).resolve().parents[2] / "fsmscope" / "static"
NODE = shutil.which("node")
pytestmark = pytest.mark.skipif(NODE is None, reason="Node.js is not installed")


def run_in_node(script: str, events: list[dict]) -> object:
    """What `script` (an ES module body with `Store`, `RunNotices` and `events` in scope) prints as JSON."""
    prelude = (f'import {{ Store }} from "{(STATIC / "store.js").as_uri()}";\n'
               f'import {{ RunNotices }} from "{(STATIC / "notice.js").as_uri()}";\n'
               'import { readFileSync } from "node:fs";\n'
               "const events = JSON.parse(readFileSync(0, 'utf8'));\n")
    # The page's modules are ES modules in files named .js with no package.json to say so: Node (20.19,
    # 22.7 and later) tells them by their syntax.
    out = subprocess.run([NODE, "--input-type=module", "-e", prelude + script],
                         input=json.dumps(events), capture_output=True, text=True, timeout=30, check=True)
    return json.loads(out.stdout)


def events_of(sm, runs=1) -> list[dict]:
    """The events of `runs` runs of `sm`, as the stream sends them (JSON)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    events: list[dict] = []
    reporter = fsm.attach(sm, events.append, name="m")
    try:
        for _ in range(runs):
            sm.execute()
    finally:
        reporter.remove_observer(events.append)
    return json.loads(json.dumps(events))


@pytest.fixture(scope="module")
def two_runs() -> list[dict]:
    return events_of(nested_machine(), runs=2)


def second_start(events: list[dict]) -> int:
    """The index of the event that starts the second run."""
    return [i for i, e in enumerate(events) if e["kind"] == "start" and e["path"] == "/SM_ROOT"][1]


def test_a_subscriber_hears_which_part_of_the_state_changed(two_runs):
    parts = run_in_node("""
        const store = new Store();
        const heard = [];
        store.subscribe((state, part) => heard.push(part));
        store.open("m");
        store.apply(events.slice(0, 3));
        store.apply(events.slice(3, 6));
        store.select("/SM_ROOT/C");
        store.setInstant({ playing: true });
        console.log(JSON.stringify(heard));
    """, two_runs)
    assert parts == ["machine", "structure", "live", "live", "selection", "instant"]


def test_the_nodes_are_indexed_from_the_structure_and_the_selection_is_the_stores(two_runs):
    state = run_in_node("""
        const store = new Store();
        store.open("m");
        store.apply(events);
        store.select("/SM_ROOT/SUB/A");
        const { name, nodes, selected, live } = store.state;
        console.log(JSON.stringify({ name, paths: [...nodes.keys()].sort(), selected, outcome: live.outcome }));
    """, two_runs)
    assert state == {
        "name": "m", "selected": "/SM_ROOT/SUB/A", "outcome": "done",
        "paths": ["/SM_ROOT", "/SM_ROOT/C", "/SM_ROOT/SUB", "/SM_ROOT/SUB/A", "/SM_ROOT/SUB/B"],
    }


def test_another_machine_shown_starts_from_nothing(two_runs):
    state = run_in_node("""
        const store = new Store();
        store.open("m");
        store.apply(events);
        store.select("/SM_ROOT/C");
        store.setInstant({ past: true, status: store.state.live });
        store.open("other");
        const { name, nodes, selected, instant, live } = store.state;
        console.log(JSON.stringify({ name, nodes: nodes.size, selected, past: instant.past, seq: live.last_seq }));
    """, two_runs)
    assert state == {"name": "other", "nodes": 0, "selected": None, "past": False, "seq": 0}


def test_the_notice_says_the_outcome_of_the_run_and_takes_it_back_when_the_next_starts(two_runs):
    start = second_start(two_runs)
    said = run_in_node(f"""
        const store = new Store();
        store.open("m");
        const notices = new RunNotices(store);
        const said = [];
        store.apply(events.slice(0, {start}));
        notices.events(events.slice(0, {start}));
        said.push(store.state.notice);
        store.apply(events.slice({start}));
        notices.events(events.slice({start}, {start + 1}));
        said.push(store.state.notice);
        console.log(JSON.stringify(said));
    """, two_runs)
    assert said == [{"text": "m finished: outcome 'done'", "level": "ok"}, {"text": "", "level": ""}]


def test_a_notice_said_after_the_outcome_stays_when_the_next_run_starts(two_runs):
    start = second_start(two_runs)
    said = run_in_node(f"""
        const store = new Store();
        store.open("m");
        const notices = new RunNotices(store);
        store.apply(events.slice(0, {start}));
        notices.events(events.slice(0, {start}));
        store.say("Start accepted (event 99)", "ok", true);
        store.apply(events.slice({start}));
        notices.events(events.slice({start}, {start + 1}));
        console.log(JSON.stringify(store.state.notice));
    """, two_runs)
    assert said == {"text": "Start accepted (event 99)", "level": "ok"}
