"""The browser's transcript (fsmscope/static/transcript.js) is the terminal's (fsm.logfiles.transcript), line for line.

Both rebuild SMACH's log lines from the same events; the Python side is checked against the
runtime's own printed lines (tests/unit/test_transcript.py). Here each example is recorded as
``fsmscope run --record`` records it, plus machines for what no example does (an Iterator, a
Concurrence that services a preempt, with and without a 'preempted' outcome, two outcomes of the
last state leading to one container outcome, a debugged run), and the events of each run are fed to both, in
Chromium for the JavaScript.
"""

from __future__ import annotations

import threading
import time
from pathlib import Path

import fsm
import pytest
from fsm.debugging import Debugger
from fsm.logfiles.log_reader import read_events
from fsm.observation import introspection
from fsm.observation.status import Status
from fsm.logfiles.transcript import Transcript

from recording_support import EXAMPLES, FAST, cli, record
from smach_support import Out, WaitForPreempt, concurrence, machine

STATIC = Path(__file__).resolve().parents[2] / "fsmscope" / "static"
ORIGIN = "http://transcript.test"


def iterator_run(path: Path) -> None:
    """SM_ROOT: IT iterates BODY over three items, then the machine ends 'done'."""
    it = fsm.Iterator(outcomes=["done"], input_keys=[], output_keys=[], it=[1, 2, 3], it_label="item")
    with it:
        fsm.Iterator.set_contained_state("BODY", Out("next"), loop_outcomes=["next"])
    record(machine(["done"], [("IT", it, {"exhausted": "done"})]), path)


def serviced_preempt_run(cc_outcomes: list[str]):
    """SM_ROOT: CC (two children that service a preempt) is preempted from outside; with 'preempted'
    among its outcomes it ends so, without it goes on to its default outcome 'done'."""
    def run(path: Path) -> None:
        left, right = WaitForPreempt(), WaitForPreempt()
        cc = concurrence(cc_outcomes, "done", [("LEFT", left), ("RIGHT", right)])
        transitions = {"preempted": "stopped", "done": "done"}
        sm = machine(["stopped", "done"], [("CC", cc, {o: transitions[o] for o in cc_outcomes})])
        preempter = threading.Thread(target=lambda: left.started.wait(5) and right.started.wait(5)
                                     and sm.request_preempt())
        preempter.start()
        outcome, _ = record(sm, path)
        preempter.join(5)
        assert outcome == ("stopped" if "preempted" in cc_outcomes else "done")
    return run


def two_outcomes_to_one_run(path: Path) -> None:
    """A returns 'b'; both its outcomes lead to 'done': the last line names 'b', the outcome A returned."""
    record(machine(["done"], [("A", Out("b", outcomes=["a", "b"]), {"a": "done", "b": "done"})]), path)


def debugged_run(path: Path) -> None:
    """SM_ROOT: WAIT -> A <-> B, A 'stop' -> LAST: a conditional breakpoint after B holds, a step
    holds after A, A's outcome is forced to 'stop', the debugger resumes (every kind of debug event)."""
    ready, finish = threading.Event(), threading.Event()
    count = {"n": 0}

    def tick(ud):
        count["n"] += 1
        ud.n = count["n"]
        return "go"

    def held():
        while not debugger.holds():
            time.sleep(0.005)

    def drive():
        while introspection.reporter_of(sm) is None:
            time.sleep(0.005)
        debugger.set_breakpoints([{"state": "/SM_ROOT/B", "at": "after", "when": "n >= 2"}], by="tester")
        ready.set()
        held()
        debugger.set_breakpoints([])
        debugger.step(by="tester")
        held()
        debugger.force("/SM_ROOT/A", "stop", by="tester")
        debugger.resume(by="tester")
        finish.set()

    ticking = {"outcomes": ["go", "stop"], "output_keys": ["n"]}
    sm = machine(["done"], [("WAIT", fsm.CBState(lambda ud: ready.wait(5) and "go", outcomes=["go"]), {"go": "A"}),
                            ("A", fsm.CBState(tick, **ticking), {"go": "B", "stop": "LAST"}),
                            ("B", fsm.CBState(tick, **ticking), {"go": "A", "stop": "done"}),
                            ("LAST", fsm.CBState(lambda ud: finish.wait(5) and "go", outcomes=["go"]), {"go": "done"})])
    debugger = Debugger(sm)
    driver = threading.Thread(target=drive)
    driver.start()
    record(sm, path)
    driver.join(5)
    debugger.detach()


def example_run(name: str):
    def run(path: Path) -> None:
        done = cli("run", Path(EXAMPLES) / (name + ".py"), "--record", path, env=FAST)
        assert done.returncode == 0, done.stderr
    return run


RUNS = {**{p.stem: example_run(p.stem) for p in sorted(Path(EXAMPLES).glob("*.py"))},
        "iterator": iterator_run, "two_outcomes_to_one": two_outcomes_to_one_run,
        "concurrence_serviced_preempt": serviced_preempt_run(["preempted", "done"]),
        "concurrence_serviced_preempt_without_preempted_outcome": serviced_preempt_run(["done"]),
        "debugged": debugged_run}


@pytest.fixture(scope="module")
def page(browser):
    """A blank page that can import the static modules (served from disk, no server)."""
    def serve(route):
        name = route.request.url[len(ORIGIN) + 1:]
        if name.endswith(".js"):
            route.fulfill(content_type="text/javascript", body=(STATIC / name).read_text())
        else:
            route.fulfill(content_type="text/html", body="")

    page = browser.new_page()
    page.route(ORIGIN + "/**", serve)
    page.goto(ORIGIN + "/")
    yield page
    page.close()


def terminal_lines(events: list[dict]) -> list[tuple]:
    transcript = Transcript()
    return [(e["seq"], e["kind"], line.level, line.msg) for e in events for line in transcript.lines(e)]


def browser_lines(page, events: list[dict]) -> list[tuple]:
    lines = page.evaluate("""async (events) => {
        const { Transcript } = await import('/transcript.js');
        const transcript = new Transcript();
        return events.flatMap((e) => transcript.lines(e).map((line) => [e.seq, e.kind, line.level, line.text]));
    }""", events)
    return [tuple(line) for line in lines]


@pytest.mark.parametrize("name", RUNS)
def test_the_browsers_transcript_of_a_run_is_the_terminals_line_for_line(page, tmp_path, name, logs):
    path = tmp_path / (name + ".jsonl")
    RUNS[name](path)
    events = list(read_events(path))
    want = terminal_lines(events)
    assert want
    assert browser_lines(page, events) == want


def test_the_browsers_reducer_follows_the_debuggers_events_as_the_terminals_does(page, tmp_path, logs):
    path = tmp_path / "debugged.jsonl"
    debugged_run(path)
    events = list(read_events(path))
    status, want = Status("m"), []
    for event in events:
        status.apply(event)
        if event["kind"] == "debug":
            want.append(status.to_dict()["debug"])
    got = page.evaluate("""async (events) => {
        const { Status } = await import('/status.js');
        const status = new Status('m');
        const seen = [];
        for (const e of events) {
            status.apply(e);
            if (e.kind === 'debug') seen.push(status.toDict().debug);
        }
        return seen;
    }""", events)
    assert [d["holds"] for d in want if d["holds"]]  # the run held, and the reducers saw it
    assert got == want
