"""The debugger of a machine of the original smach, against a real uvicorn: pause, step, breakpoints
with conditions before and after, forced outcomes, a preempt of a held machine, its Concurrence's
children holding each on its own, and the same of one published from its own process
(docs/debugging.md, "Machines of the original smach")."""

import threading

import pytest
from fsmscope.server.testing.polling import wait_for

from original_control_support import (Bare, holds, loop, published, run_in_thread, smach,  # noqa: F401
                                      split_machine, status, visiting, waiter, waiting)
from server_support import client, looping_machine


def test_pause_holds_an_original_machine_and_resume_lets_it_finish(loop):
    http, stop, result = loop
    assert http.post("/api/machines/loop/pause").status_code == 202
    wait_for(lambda: holds(http))
    [hold] = holds(http)
    assert (hold["at"], hold["reason"]) == ("after", "pause")
    stop.set()
    assert http.post("/api/machines/loop/resume").status_code == 202
    wait_for(lambda: result.get("outcome") == "done")


def test_a_step_lets_one_transition_of_a_paused_original_machine_happen(loop):
    http, _, _ = loop
    http.post("/api/machines/loop/pause")
    wait_for(lambda: holds(http))
    before = holds(http)[0]["state"]
    assert http.post("/api/machines/loop/step").status_code == 202
    wait_for(lambda: holds(http) and holds(http)[0]["reason"] == "step")
    assert holds(http)[0]["state"] == {"A": "B", "B": "A"}[before]


def test_a_step_at_the_roots_level_steps_over_what_runs_inside_a_nested_original_machine(live_server, smach):
    runs = []

    def visit(label):
        return smach.CBState(lambda ud: runs.append(label) or "go", outcomes=["go"])

    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        sub = smach.StateMachine(outcomes=["ok"])
        with sub:
            smach.StateMachine.add("X", visit("X"), {"go": "Y"})
            smach.StateMachine.add("Y", visit("Y"), {"go": "ok"})
        smach.StateMachine.add("SUB", sub, {"ok": "LAST"})
        smach.StateMachine.add("LAST", visit("LAST"), {"go": "done"})
    live_server.hub.add_local(sm, name="nested")
    http = client(live_server)
    http.put("/api/machines/nested/breakpoints", json={"breakpoints": [{"state": "/SM_ROOT/SUB/X", "at": "after"}]})
    thread, result = run_in_thread(sm)
    wait_for(lambda: holds(http, "nested"))
    http.put("/api/machines/nested/breakpoints", json={"breakpoints": []})
    assert http.post("/api/machines/nested/step", json={"level": "/SM_ROOT"}).status_code == 202
    wait_for(lambda: holds(http, "nested") and holds(http, "nested")[0]["reason"] == "step")
    [hold] = holds(http, "nested")
    assert (hold["path"], hold["state"], hold["outcome"]) == ("/SM_ROOT", "SUB", "ok")
    assert runs == ["X", "Y"]
    http.post("/api/machines/nested/resume")
    thread.join(5)
    assert result["outcome"] == "done" and runs == ["X", "Y", "LAST"]


def test_a_conditional_breakpoint_before_a_state_holds_the_original_machine_there(loop):
    http, _, _ = loop
    answer = http.put("/api/machines/loop/breakpoints",
                      json={"breakpoints": [{"state": "/SM_ROOT/A", "at": "before", "when": "n >= 6"}]})
    assert answer.status_code == 200
    wait_for(lambda: holds(http))
    [hold] = holds(http)
    assert (hold["state"], hold["at"], hold["detail"]) == ("A", "before", "hit breakpoint before A when n >= 6")
    assert status(http, "loop")["containers"]["/SM_ROOT"]["userdata"]["n"] >= 6


def test_a_conditional_breakpoint_after_a_state_holds_the_original_machine_with_its_outcome(loop):
    http, _, _ = loop
    http.put("/api/machines/loop/breakpoints",
             json={"breakpoints": [{"state": "/SM_ROOT/B", "at": "after", "outcome": "go", "when": "n >= 4"}]})
    wait_for(lambda: holds(http))
    [hold] = holds(http)
    assert (hold["state"], hold["at"], hold["outcome"]) == ("B", "after", "go")
    assert hold["detail"] == "hit breakpoint after B with outcome 'go' when n >= 4"


def test_a_forced_outcome_replaces_what_the_held_original_state_returned(loop):
    http, _, result = loop
    http.post("/api/machines/loop/pause")
    wait_for(lambda: holds(http))
    state = "/SM_ROOT/" + holds(http)[0]["state"]
    assert http.post("/api/machines/loop/force", json={"state": state, "outcome": "stop"}).status_code == 202
    http.post("/api/machines/loop/resume")
    wait_for(lambda: result.get("outcome") == "done")  # 'stop' ends it: the loop was never told to stop


def test_forcing_a_running_original_state_preempts_it_and_its_container_takes_the_forced_outcome(live_server, smach):
    sm, entered, _ = waiting(smach)
    live_server.hub.add_local(sm, name="w")
    thread, result = run_in_thread(sm)
    assert entered.wait(5)
    answer = client(live_server).post("/api/machines/w/force", json={"state": "/SM_ROOT/WAIT", "outcome": "done"})
    assert answer.status_code == 202
    thread.join(5)
    assert result["outcome"] == "done"  # WAIT returned 'preempted'


def test_a_preempt_reaches_a_held_original_machine(live_server, smach):
    sm, entered, release = waiting(smach)
    live_server.hub.add_local(sm, name="w")
    http = client(live_server)
    http.put("/api/machines/w/breakpoints", json={"breakpoints": [{"state": "/SM_ROOT/WAIT", "at": "before"}]})
    thread, result = run_in_thread(sm)
    wait_for(lambda: holds(http, "w"))
    assert http.post("/api/machines/w/preempt", json={}).status_code == 202
    thread.join(5)
    assert result["outcome"] == "preempted"
    assert holds(http, "w") == []


def test_a_held_original_machine_is_let_go_when_its_own_shutdown_check_says_so(loop, smach):
    """As smach_ros sets it: the original's is_shutdown is rospy's, and a held machine must not keep the node up."""
    http, _, result = loop
    http.post("/api/machines/loop/pause")
    wait_for(lambda: holds(http))
    smach.set_shutdown_check(lambda: True)
    try:
        wait_for(lambda: "outcome" in result)
    finally:
        smach.set_shutdown_check(lambda: False)
    assert result["outcome"] is None  # the original's loop ends without an outcome at a shutdown


def test_a_breakpoint_in_a_container_added_to_an_original_machine_after_arming_holds_at_its_next_run(
        live_server, smach):
    sm = visiting(smach)
    live_server.hub.add_local(sm, name="two")
    http = client(live_server)
    never = {"state": "/SM_ROOT/FOO", "at": "after", "when": "visits == ['never']"}
    assert http.put("/api/machines/two/breakpoints", json={"breakpoints": [never]}).status_code == 200
    later = smach.StateMachine(outcomes=["done"])
    with later:
        smach.StateMachine.add("Z", smach.CBState(lambda ud: "done", outcomes=["done"]), {"done": "done"})
    with sm:
        smach.StateMachine.add("LATER", later, {"done": "done"})
    answer = http.put("/api/machines/two/breakpoints",
                      json={"breakpoints": [never, {"state": "/SM_ROOT/LATER/Z", "at": "before"}]})
    assert answer.status_code == 200
    http.post("/api/machines/two/initial-state", json={"states": ["LATER"]})
    assert http.post("/api/machines/two/start", json={}).status_code == 202
    wait_for(lambda: holds(http, "two"))
    assert (holds(http, "two")[0]["path"], holds(http, "two")[0]["state"]) == ("/SM_ROOT/LATER", "Z")
    http.put("/api/machines/two/breakpoints", json={"breakpoints": []})
    http.post("/api/machines/two/resume")
    wait_for(lambda: status(http, "two")["outcome"] == "done")


class Slotted(Bare):
    """SMACH runs any object with a state's interface; this one takes no attribute (``__slots__``)
    and can be asked whether it is preempted."""

    __slots__ = ()

    def preempt_requested(self):
        return False


def slotted(live_server, smach):
    """SLOT (``Slotted``) then LAST, an original machine served as 'slotted'; an operator's client."""
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("SLOT", Slotted(), {"go": "LAST"})
        smach.StateMachine.add("LAST", smach.CBState(lambda ud: "done", outcomes=["done"]), {"done": "done"})
    live_server.hub.add_local(sm, name="slotted")
    return sm, client(live_server)


def test_an_original_machine_with_a_state_that_takes_no_attribute_is_paused_at_the_others(live_server, smach):
    sm, http = slotted(live_server, smach)
    assert http.post("/api/machines/slotted/pause").status_code == 202
    thread, result = run_in_thread(sm)
    wait_for(lambda: holds(http, "slotted"))
    assert [(h["state"], h["at"]) for h in holds(http, "slotted")] == [("LAST", "after")]
    http.post("/api/machines/slotted/resume")
    thread.join(5)
    assert result["outcome"] == "done"


@pytest.mark.parametrize("method, path, body", [
    ("PUT", "breakpoints", {"breakpoints": [{"state": "/SM_ROOT/SLOT"}]}),
    ("POST", "force", {"state": "/SM_ROOT/SLOT", "outcome": "go"}),
])
def test_a_breakpoint_or_force_on_a_state_the_original_cannot_let_be_wrapped_is_422_saying_why(
        live_server, smach, method, path, body):
    _, http = slotted(live_server, smach)
    answer = http.request(method, "/api/machines/slotted/" + path, json=body)
    assert answer.status_code == 422
    assert "/SM_ROOT/SLOT takes no attribute (__slots__): its execute cannot be wrapped" in answer.json()["detail"]


def test_a_force_of_a_state_without_preempt_methods_is_taken_when_it_returns(live_server, smach):
    entered, release = threading.Event(), threading.Event()

    class Duck:
        """SMACH runs any object with a state's interface: this one has no preempt methods."""

        def get_registered_outcomes(self):
            return ("go", "other")

        def get_registered_input_keys(self):
            return ()

        def get_registered_output_keys(self):
            return ()

        def execute(self, ud):
            entered.set()
            release.wait(5)
            return "go"

    sm = smach.StateMachine(outcomes=["went", "forced"])
    with sm:
        smach.StateMachine.add("DUCK", Duck(), {"go": "went", "other": "forced"})
    live_server.hub.add_local(sm, name="duck")
    thread, result = run_in_thread(sm)
    assert entered.wait(5)
    answer = client(live_server).post("/api/machines/duck/force", json={"state": "/SM_ROOT/DUCK", "outcome": "other"})
    assert answer.status_code == 202
    release.set()
    thread.join(5)
    assert result["outcome"] == "forced"


def test_a_child_of_an_original_concurrence_held_before_it_runs_blocks_no_other(live_server, smach):
    """The original's Concurrence runs a child with no lock held: while RIGHT holds, LEFT runs on to
    its end, and holds there in turn (a held machine is paused) until resumed."""
    left, _, release = waiter(smach)
    sm = split_machine(smach, left)
    live_server.hub.add_local(sm, name="split")
    http = client(live_server)
    http.put("/api/machines/split/breakpoints", json={"breakpoints": [{"state": "/SM_ROOT/SPLIT/RIGHT"}]})
    thread, result = run_in_thread(sm)
    wait_for(lambda: holds(http, "split"))
    release.set()
    wait_for(lambda: len(holds(http, "split")) == 2)
    assert sorted((h["state"], h["at"], h["reason"]) for h in holds(http, "split")) == [
        ("LEFT", "after", "pause"), ("RIGHT", "before", "breakpoint")]
    http.put("/api/machines/split/breakpoints", json={"breakpoints": []})
    http.post("/api/machines/split/resume")
    thread.join(5)
    assert result["outcome"] == "done"


def test_a_preempt_reaches_an_original_machine_held_inside_its_concurrence(live_server, smach):
    left, entered, _ = waiter(smach)
    sm = split_machine(smach, left)
    live_server.hub.add_local(sm, name="split")
    http = client(live_server)
    http.put("/api/machines/split/breakpoints", json={"breakpoints": [{"state": "/SM_ROOT/SPLIT/RIGHT"}]})
    thread, result = run_in_thread(sm)
    wait_for(lambda: holds(http, "split"))
    assert entered.wait(5)
    assert http.post("/api/machines/split/preempt", json={}).status_code == 202
    thread.join(5)
    assert not thread.is_alive() and holds(http, "split") == []


def test_a_published_original_machine_is_paused_and_forced_from_the_page(live_server, smach):
    sm, _ = looping_machine(smach)
    with published(live_server, sm) as (thread, result):
        http = client(live_server)
        assert http.post("/api/machines/remote/pause").status_code == 202
        wait_for(lambda: holds(http, "remote"))
        state = "/SM_ROOT/" + holds(http, "remote")[0]["state"]
        assert http.post("/api/machines/remote/force", json={"state": state, "outcome": "stop"}).status_code == 202
        assert http.post("/api/machines/remote/resume").status_code == 202
        thread.join(5)
        assert result["outcome"] == "done"


def test_a_published_original_machine_is_preempted_from_the_page(live_server, smach):
    sm, entered, _ = waiting(smach)
    with published(live_server, sm) as (thread, result):
        assert entered.wait(5)
        assert client(live_server).post("/api/machines/remote/preempt", json={}).status_code == 202
        thread.join(5)
        assert result["outcome"] == "preempted"
