"""The timeline of a machine (fsmscope/server/timeline.py, GET /api/machines/{name}/timeline): bands per
container, ticks, zoom and its bounds, against a real uvicorn and real machines."""

import random
import threading

import fsm
import pytest
from fsm.observation.schema import event

import fsmscope.server.timeline
from fsmscope.server.testing.polling import wait_for
from fsmscope.server.timeline import MANY, TimelineIndex
from server_support import client, sleeper, waiting_machine
from smach_support import Out, concurrence, failing_machine, machine, run_to_failure


def served(srv, sm, name):
    """``sm`` served by ``srv``'s hub as ``name``; returns the list its events are also appended to."""
    events = []
    fsm.attach(sm, events.append, name=name)
    srv.hub.add_local(sm, name)
    return events


def timeline(srv, name, **params):
    answer = client(srv).get("/api/machines/%s/timeline" % name, params=params)
    assert answer.status_code == 200, answer.text
    return answer.json()


def find(events, kind, path):
    return [e for e in events if e["kind"] == kind and e["path"] == path]


def test_the_bands_of_a_nested_machine_are_its_states_in_turn_at_every_level(live_server):
    sub = machine(["done"], [("A", sleeper(0.01), {"go": "B"}), ("B", sleeper(0.01), {"go": "done"})])
    sm = machine(["done"], [("SUB", sub, {"done": "C"}), ("C", sleeper(0.01), {"go": "done"})])
    events = served(live_server, sm, "nested")
    sm.execute()
    got = timeline(live_server, "nested")

    (root_start,), (to_c,), (root_end,) = (find(events, k, "/SM_ROOT") for k in ("start", "transition", "terminate"))
    (sub_start,), (to_b,), (sub_end,) = (find(events, k, "/SM_ROOT/SUB") for k in ("start", "transition", "terminate"))
    end = events[-1]["t"]
    assert got["bands"] == {
        "/SM_ROOT": [[root_start["t"], to_c["t"], root_start["seq"], "SUB"],
                     [to_c["t"], root_end["t"], to_c["seq"], "C"],
                     [root_end["t"], end, root_end["seq"], None]],
        "/SM_ROOT/SUB": [[sub_start["t"], to_b["t"], sub_start["seq"], "A"],
                         [to_b["t"], sub_end["t"], to_b["seq"], "B"],
                         [sub_end["t"], end, sub_end["seq"], None]],
    }
    assert got["first"] == {"seq": events[0]["seq"], "t": events[0]["t"]}
    assert got["last"] == {"seq": events[-1]["seq"], "t": end}
    assert got["transitions"] == [[e["seq"], e["t"]] for e in events if e["kind"] in ("start", "transition",
                                                                                       "terminate")]
    assert got["runs"] == [{"run": root_start["run"], "seq": events[0]["seq"], "t": events[0]["t"]}]
    assert got["coarse"] is False


def test_a_concurrence_shows_plus_while_several_children_run(live_server):
    slow_began, fast_ended = threading.Event(), threading.Event()

    def fast(ud):
        slow_began.wait(10)  # both run at once, however the threads are scheduled
        return "go"

    def slow(ud):
        slow_began.set()
        fast_ended.wait(10)  # FAST ends first, however loaded the machine
        return "go"

    def reported(outcomes):
        if outcomes["FAST"] is not None:
            fast_ended.set()  # FAST's transition has been reported
        return False

    cc = concurrence(["done"], "done", [("FAST", Out(fast, outcomes=["go"])), ("SLOW", Out(slow, outcomes=["go"]))],
                     outcome_map={"done": {"FAST": "go", "SLOW": "go"}}, child_termination_cb=reported)
    sm = machine(["done"], [("CC", cc, {"done": "done"})])
    served(live_server, sm, "together")
    sm.execute()
    assert [band[3] for band in timeline(live_server, "together")["bands"]["/SM_ROOT/CC"]] == ["+", "SLOW", None]


def test_an_error_is_a_tick_saying_what_was_raised(live_server):
    sm = failing_machine()
    events = served(live_server, sm, "failing")
    run_to_failure(sm)
    (error,) = find(events, "error", "/SM_ROOT/SUB")
    ticks = [tick for tick in timeline(live_server, "failing")["ticks"] if tick["kind"] == "error"]
    assert ticks[0] == {"seq": error["seq"], "t": error["t"], "kind": "error", "text": "BAD: ValueError: boom"}


def test_a_preempt_asked_from_the_page_is_a_control_tick_and_a_preempt_tick(live_server):
    sm, wait = waiting_machine()
    served(live_server, sm, "waiting")
    assert client(live_server).post("/api/machines/waiting/start", json={}).status_code == 202
    assert wait.entered.wait(5)
    answer = client(live_server).post("/api/machines/waiting/preempt", json={"reason": "enough"})
    assert answer.status_code == 202
    wait_for(lambda: not live_server.hub.get("waiting").running(), 5, what="the preempted machine to end")
    ticks = [(tick["kind"], tick["text"]) for tick in timeline(live_server, "waiting")["ticks"]]
    assert ("control", "preempt: enough") in ticks
    assert ("preempt", "preempt requested of /SM_ROOT") in ticks


def test_a_breakpoint_hit_and_a_forced_outcome_are_debug_ticks_in_the_transcripts_words(live_server):
    from fsm.debugging import debugger_of

    sm = machine(["done"], [("A", sleeper(0.01), {"go": "B"}), ("B", sleeper(0.01), {"go": "done"})])
    served(live_server, sm, "debugged")
    debugger = debugger_of(sm)
    debugger.set_breakpoints([{"state": "/SM_ROOT/B", "at": "before"}], by="tester")
    runner = threading.Thread(target=sm.execute)
    runner.start()
    try:
        wait_for(lambda: debugger.holds(), 5, what="the breakpoint to hold")
        debugger.force("/SM_ROOT/B", "go", by="tester")
    finally:
        debugger.detach()
        runner.join(5)
    texts = [tick["text"] for tick in timeline(live_server, "debugged")["ticks"] if tick["kind"] == "debug"]
    hold = texts.index("Holding before 'B': hit breakpoint before B")
    assert texts.index("Forced outcome 'go' of 'B' (it did not run) by tester") > hold


def test_a_machine_with_no_events_has_an_empty_timeline(live_server):
    live_server.hub.ingest(event(1, 1000.0, None, "quiet", "log", "/SM_ROOT", {"level": "info", "msg": "hi"}))
    got = timeline(live_server, "quiet")
    assert got["bands"] == {} and got["ticks"] == [] and got["first"] == got["last"] == {"seq": 1, "t": 1000.0}


@pytest.mark.parametrize("params, words", [
    ({"since_t": "nan"}, "since_t must be a finite number"),
    ({"until_t": "inf"}, "until_t must be a finite number"),
    ({"since_t": "5", "until_t": "4"}, "since_t (5.0) is after until_t (4.0)"),
    ({"buckets": "0"}, "buckets"),
    ({"buckets": "10001"}, "buckets"),
    ({"buckets": "many"}, "buckets"),
], ids=["nan", "inf", "reversed", "no-buckets", "too-many-buckets", "buckets-not-a-number"])
def test_a_bad_zoom_is_422_with_a_message(live_server, params, words):
    served(live_server, machine(["done"], [("A", sleeper(), {"go": "done"})]), "m")
    answer = client(live_server).get("/api/machines/m/timeline", params=params)
    assert answer.status_code == 422 and words in answer.json()["detail"]


def test_the_timeline_of_an_unknown_machine_is_404(live_server):
    answer = client(live_server).get("/api/machines/nobody/timeline")
    assert answer.status_code == 404 and "nobody" in answer.json()["detail"]


# The index alone, over long synthetic runs (one mark a second of machine time each).

def long_run(transitions: int, seed: int = 9) -> TimelineIndex:
    """/SM_ROOT always in SUB; /SM_ROOT/SUB hopping among A..E, each state lasting 1 ms to 1 s."""
    rng = random.Random(seed)
    index = TimelineIndex()
    t = 1000.0
    index.add(event(1, t, "r1", "m", "start", "/SM_ROOT", {"initial": ["SUB"], "active": ["SUB"], "userdata": {}}))
    index.add(event(2, t, "r1", "m", "start", "/SM_ROOT/SUB", {"initial": ["A"], "active": ["A"], "userdata": {}}))
    for seq in range(3, transitions + 3):
        t += rng.choice((0.001, 0.01, 1.0))
        to = "ABCDE"[seq % 5]
        index.add(event(seq, t, "r1", "m", "transition", "/SM_ROOT/SUB",
                        {"from": "?", "outcome": "go", "to": to, "active": [to]}))
    return index


def contiguous(bands: list) -> bool:
    return all(a[1] == b[0] for a, b in zip(bands, bands[1:]))


@pytest.mark.parametrize("buckets", [10, 300, 1000])
def test_zooming_out_on_100000_transitions_keeps_about_buckets_bands(buckets):
    got = long_run(100_000).answer(buckets=buckets)
    bands = got["bands"]["/SM_ROOT/SUB"]
    assert len(bands) <= buckets + 2
    assert MANY in [band[3] for band in bands] and contiguous(bands)
    assert (bands[0][0], bands[-1][1]) == (got["first"]["t"], got["last"]["t"])
    assert len(got["transitions"]) == 5000 and got["coarse"] is True


def test_zooming_in_shows_every_state_of_the_range():
    index = long_run(100_000)
    since, until = 1500.0, 1503.0
    got = index.answer(since, until, buckets=10_000)
    bands = got["bands"]["/SM_ROOT/SUB"]
    assert MANY not in [band[3] for band in bands] and contiguous(bands)
    assert (bands[0][0], bands[-1][1]) == (since, until)
    seqs = [seq for seq, t in got["transitions"]]
    assert [band[2] for band in bands[1:]] == seqs and got["coarse"] is False


def test_past_its_cap_the_index_coalesces_its_older_half_and_says_so(monkeypatch):
    monkeypatch.setattr(fsmscope.server.timeline, "MAX_MARKS", 10_000)
    monkeypatch.setattr(fsmscope.server.timeline, "COARSE_BUCKETS", 100)
    index = long_run(50_000)
    whole = index.answer()
    bands = whole["bands"]["/SM_ROOT/SUB"]
    assert whole["kept_from"] > whole["first"]["seq"] and whole["coarse"] is True
    assert contiguous(bands) and bands[0][0] == whole["first"]["t"]
    recent = index.answer(since_t=whole["last"]["t"] - 5.0, buckets=10_000)
    assert recent["coarse"] is False and MANY not in [band[3] for band in recent["bands"]["/SM_ROOT/SUB"]]
    assert len(index._steps[0]) <= 10_000
