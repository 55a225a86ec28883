"""Controlling a machine of the original smach from the dashboard, against a real uvicorn: preempt,
initial state, start and the debugger, with the roles, the lease, the deadman and the audit of an
fsm machine (docs/debugging.md, "Machines of the original smach"; README's table)."""

import contextlib
import threading
import time

import fsm
import httpx
import pytest
from fsmscope import Publisher
from fsmscope.server.http_server import ServerThread
from fsmscope.server.lease import Deadman
from fsmscope.server.testing.polling import wait_for

from original_core import loaded_original
from server_support import client


@pytest.fixture(scope="module", params=["noetic", "ros2"])
def smach(request):
    """The original of each branch in turn, its log lines kept out of the test's output (they print otherwise)."""
    with loaded_original(request.param) as module:
        module.set_loggers(*[lambda msg: None] * 4)
        yield module


def looping(smach):
    """A <-> B of the original, until ``stop`` is set; each writes its count into userdata ``n``."""
    stop = threading.Event()
    count = {"n": 0}

    def tick(ud):
        time.sleep(0.002)
        count["n"] += 1
        ud.n = count["n"]
        return "stop" if stop.is_set() else "go"

    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", smach.CBState(tick, outcomes=["go", "stop"], output_keys=["n"]),
                               {"go": "B", "stop": "done"})
        smach.StateMachine.add("B", smach.CBState(tick, outcomes=["go", "stop"], output_keys=["n"]),
                               {"go": "A", "stop": "done"})
    return sm, stop


def visiting(smach):
    """FOO -go-> BAR -go-> done of the original; each appends its label to userdata ``visits``."""
    sm = smach.StateMachine(outcomes=["done"])
    sm.userdata.visits = []

    def visit(label):
        def cb(ud):
            ud.visits = ud.visits + [label]
            return "go"
        return smach.CBState(cb, outcomes=["go"], input_keys=["visits"], output_keys=["visits"])

    with sm:
        smach.StateMachine.add("FOO", visit("FOO"), {"go": "BAR"})
        smach.StateMachine.add("BAR", visit("BAR"), {"go": "done"})
    return sm


def waiter(smach):
    """A state of the original that waits until preempted (then 'preempted') or released (then 'done')."""
    entered, release = threading.Event(), threading.Event()

    class Wait(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["done", "preempted"])

        def execute(self, ud):
            entered.set()
            while not release.is_set():
                if self.preempt_requested():
                    self.service_preempt()
                    return "preempted"
                time.sleep(0.005)
            return "done"

    return Wait(), entered, release


def waiting(smach):
    """WAIT (``waiter``) alone in a StateMachine of the original."""
    wait, entered, release = waiter(smach)
    sm = smach.StateMachine(outcomes=["done", "preempted"])
    with sm:
        smach.StateMachine.add("WAIT", wait, {"done": "done", "preempted": "preempted"})
    return sm, entered, release


def run_in_thread(sm):
    result = {}
    thread = threading.Thread(target=lambda: result.update(outcome=sm.execute()), daemon=True)
    thread.start()
    return thread, result


def status(http, name):
    return http.get("/api/machines/%s/status" % name).json()


def holds(http, name="loop"):
    debug = status(http, name)["debug"]  # None until a debugger is attached
    return debug["holds"] if debug is not None else []


def controls(http, name, action=None):
    events = http.get("/api/machines/%s/history" % name, params={"kinds": "control", "limit": 1000}).json()["events"]
    return [e for e in events if action is None or e["action"] == action]


@pytest.fixture
def loop(live_server, smach):
    """The looping original machine served as 'loop', running in a thread; stopped and resumed at the end."""
    sm, stop = looping(smach)
    live_server.hub.add_local(sm, name="loop")
    http = client(live_server)
    thread, result = run_in_thread(sm)
    yield http, stop, result
    stop.set()
    http.put("/api/machines/loop/breakpoints", json={"breakpoints": []})
    http.post("/api/machines/loop/resume")
    thread.join(5)


# Preempt, initial state, start.

def test_the_pages_preempt_ends_a_running_original_machine_preempted(live_server, smach):
    sm, entered, _ = waiting(smach)
    live_server.hub.add_local(sm, name="w")
    thread, result = run_in_thread(sm)
    assert entered.wait(5)
    answer = client(live_server).post("/api/machines/w/preempt", json={"reason": "operator"})
    assert answer.status_code == 202
    thread.join(5)
    assert result["outcome"] == "preempted"
    wait_for(lambda: status(client(live_server), "w")["outcome"] == "preempted")


def test_the_pages_preempt_reaches_an_original_machine_whose_top_is_a_concurrence(live_server, smach):
    """The original's Concurrence has no is_running(): that it runs is what the watch around its execute says."""
    wait, entered, _ = waiter(smach)
    split = smach.Concurrence(outcomes=["done", "preempted"], default_outcome="done")
    with split:
        smach.Concurrence.add("WAIT", wait)
    live_server.hub.add_local(split, name="split")
    thread, result = run_in_thread(split)
    assert entered.wait(5)
    assert client(live_server).post("/api/machines/split/preempt", json={}).status_code == 202
    thread.join(5)
    assert not thread.is_alive() and "outcome" in result


def test_preempt_of_a_finished_original_machine_is_409(live_server, smach):
    sm = visiting(smach)
    live_server.hub.add_local(sm, name="two")
    sm.execute()
    answer = client(live_server).post("/api/machines/two/preempt", json={})
    assert answer.status_code == 409 and answer.json()["detail"] == "machine is not running"


def test_initial_state_with_userdata_then_start_runs_the_original_machine_from_there(live_server, smach):
    sm = visiting(smach)
    live_server.hub.add_local(sm, name="two")
    http = client(live_server)
    answer = http.post("/api/machines/two/initial-state", json={"states": ["BAR"], "userdata": {"visits": ["X"]}})
    assert answer.status_code == 200
    assert http.post("/api/machines/two/start", json={}).status_code == 202
    wait_for(lambda: status(http, "two")["outcome"] == "done")
    assert sm.userdata.visits == ["X", "BAR"]
    assert status(http, "two")["containers"]["/SM_ROOT"]["userdata"] == {"visits": ["X", "BAR"]}


def test_start_runs_a_finished_original_machine_again(live_server, smach):
    sm = visiting(smach)
    live_server.hub.add_local(sm, name="two")
    sm.execute()
    http = client(live_server)
    first_run = status(http, "two")["run"]
    assert http.post("/api/machines/two/start", json={}).status_code == 202
    wait_for(lambda: status(http, "two")["run"] != first_run and status(http, "two")["outcome"] == "done")
    assert sm.userdata.visits == ["FOO", "BAR", "FOO", "BAR"]


def test_start_runs_an_original_machine_again_after_a_run_that_raised(live_server, smach):
    """The ros2 branch's StateMachine says it still runs after a run that raised (its execute has no finally)."""
    fail = {"now": True}

    def maybe_raise(ud):
        if fail["now"]:
            raise ValueError("boom")
        return "go"

    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("RISKY", smach.CBState(maybe_raise, outcomes=["go"]), {"go": "done"})
    live_server.hub.add_local(sm, name="risky")
    with pytest.raises(smach.InvalidUserCodeError):
        sm.execute()
    fail["now"] = False
    http = client(live_server)
    assert http.post("/api/machines/risky/start", json={}).status_code == 202
    wait_for(lambda: status(http, "risky")["outcome"] == "done")


def test_an_initial_state_set_while_the_original_machine_runs_takes_effect_at_its_next_run(live_server, smach):
    sm, stop = looping(smach)
    live_server.hub.add_local(sm, name="loop")
    http = client(live_server)
    thread, _ = run_in_thread(sm)
    wait_for(lambda: sm.is_running())
    answer = http.post("/api/machines/loop/initial-state", json={"states": ["B"], "userdata": {"n": 100}})
    assert answer.status_code == 200
    assert controls(http, "loop", "initial-state")[-1]["params"]["deferred"] is True
    assert sm.get_initial_states() == ["A"]  # the run goes on as it began
    stop.set()
    thread.join(5)
    assert sm.get_initial_states() == ["B"] and sm.userdata.n == 100


def test_start_while_the_original_machine_runs_is_409(live_server, smach):
    sm, entered, release = waiting(smach)
    live_server.hub.add_local(sm, name="w")
    thread, _ = run_in_thread(sm)
    assert entered.wait(5)
    try:
        answer = client(live_server).post("/api/machines/w/start", json={})
        assert answer.status_code == 409 and answer.json()["detail"] == "machine is running"
    finally:
        release.set()
        thread.join(5)


# The debugger.

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


@contextlib.contextmanager
def published(live_server, sm):
    """``sm`` published to the server by a Publisher (in this process, over a real websocket): the
    controls reach it as control frames, applied by the same handle; yields its run's thread and result."""
    publisher = Publisher(live_server.base_url, live_server.token)
    try:
        fsm.attach(sm, publisher, name="remote")
        assert publisher.connected.wait(5)
        thread, result = run_in_thread(sm)
        wait_for(lambda: any(m["name"] == "remote" and m["running"]
                             for m in client(live_server).get("/api/machines").json()))
        yield thread, result
    finally:
        publisher.close()


def split_machine(smach, left):
    """SPLIT, an original Concurrence of ``left`` and RIGHT (returns 'done' at once), in a StateMachine;
    'done' when both are done."""
    sm = smach.StateMachine(outcomes=["done", "other", "preempted"])
    with sm:
        split = smach.Concurrence(outcomes=["done", "other", "preempted"], default_outcome="other",
                                  outcome_map={"done": {"LEFT": "done", "RIGHT": "done"}})
        with split:
            smach.Concurrence.add("LEFT", left)
            smach.Concurrence.add("RIGHT", smach.CBState(lambda ud: "done", outcomes=["done"]))
        smach.StateMachine.add("SPLIT", split, {"done": "done", "other": "other", "preempted": "preempted"})
    return sm


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
    sm, _ = looping(smach)
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


# Who may control it: the roles, the lease, the deadman, the audit.

def test_a_viewers_control_of_an_original_machine_is_403_and_in_its_audit(loop, live_server):
    http, _, _ = loop
    viewer = httpx.Client(base_url=live_server.base_url, timeout=10,
                          headers={"Authorization": "Bearer " + live_server.viewer_token})
    answer = viewer.post("/api/machines/loop/pause")
    assert answer.status_code == 403
    [refused] = controls(http, "loop", "pause")
    assert (refused["client"], refused["result"]) == ("127.0.0.1 (viewer)", answer.json()["detail"])
    assert holds(http) == []


def page(srv, page_id):
    http = client(srv)
    http.headers["X-Fsmscope-Page"] = page_id
    return http


def test_a_control_without_the_lease_of_an_original_machine_is_409_and_in_its_audit(loop, live_server):
    one, two = page(live_server, "one"), page(live_server, "two")
    assert one.post("/api/machines/loop/lease").status_code == 200
    answer = two.post("/api/machines/loop/pause")
    assert answer.status_code == 409
    assert "127.0.0.1 (operator, page one) controls machine 'loop' since" in answer.json()["detail"]
    [refused] = controls(one, "loop", "pause")
    assert (refused["client"], refused["result"]) == ("127.0.0.1 (operator, page two)", answer.json()["detail"])
    assert holds(one) == []
    one.delete("/api/machines/loop/lease")


@contextlib.contextmanager
def serving_with_deadman(smach, after):
    srv = ServerThread(deadman=Deadman(after, "pause")).start()
    sm, stop = looping(smach)
    srv.hub.add_local(sm, name="loop")
    thread, _ = run_in_thread(sm)
    try:
        yield srv
    finally:
        stop.set()
        client(srv).post("/api/machines/loop/resume")
        thread.join(5)
        srv.stop()


def test_a_silent_holder_of_an_original_machines_lease_gets_it_paused_by_the_deadman(smach):
    with serving_with_deadman(smach, 1.5) as srv:
        page(srv, "one").post("/api/machines/loop/lease")
        http = client(srv)
        wait_for(lambda: controls(http, "loop", "deadman"), timeout=5)
        assert controls(http, "loop", "pause")[-1]["client"] == "deadman"
        wait_for(lambda: holds(http))
        assert holds(http)[0]["reason"] == "pause"


# What the original cannot take: a clear 4xx, never a 500.

def concurrent(smach):
    """SPLIT, an original Concurrence of A and B, inside a StateMachine."""
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        split = smach.Concurrence(outcomes=["done"], default_outcome="done", input_keys=["goal"])
        with split:
            smach.Concurrence.add("A", smach.CBState(lambda ud: "go", outcomes=["go"]))
            smach.Concurrence.add("B", smach.CBState(lambda ud: "go", outcomes=["go"]))
        smach.StateMachine.add("SPLIT", split, {"done": "done"})
    return sm, split


def test_initial_states_of_an_original_concurrence_are_422_saying_it_starts_all_its_children(live_server, smach):
    sm, _ = concurrent(smach)
    live_server.hub.add_local(sm, name="cc")
    answer = client(live_server).post("/api/machines/cc/initial-state",
                                      json={"path": "/SM_ROOT/SPLIT", "states": ["A"]})
    assert answer.status_code == 422
    assert answer.json()["detail"] == "a Concurrence starts all its children; it takes no initial states"


def test_userdata_alone_is_set_on_an_original_concurrence(live_server, smach):
    """Its own set_initial_state fails on Python 3 whatever it is given: the userdata is merged as it means to."""
    sm, split = concurrent(smach)
    live_server.hub.add_local(sm, name="cc")
    answer = client(live_server).post("/api/machines/cc/initial-state",
                                      json={"path": "/SM_ROOT/SPLIT", "userdata": {"goal": 3}})
    assert answer.status_code == 200
    assert split.userdata.goal == 3


def test_initial_state_of_a_users_container_without_set_initial_state_is_422(live_server, smach):
    class Pair(smach.Container):
        """A user's own container of the original: children, but no initial state to set."""

        def __init__(self):
            smach.Container.__init__(self, outcomes=["done"])
            self._children = {"ONE": smach.CBState(lambda ud: "done", outcomes=["done"])}

        def get_children(self):
            return self._children

        def get_initial_states(self):
            return ["ONE"]

        def get_active_states(self):
            return []

        def get_internal_edges(self):
            return []

        def execute(self, parent_ud=None):
            return self._children["ONE"].execute(self.userdata)

    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("PAIR", Pair(), {"done": "done"})
    live_server.hub.add_local(sm, name="pair")
    answer = client(live_server).post("/api/machines/pair/initial-state",
                                      json={"path": "/SM_ROOT/PAIR", "states": ["ONE"]})
    assert answer.status_code == 422
    assert answer.json()["detail"] == "a Pair takes no initial state: its class does not implement set_initial_state"
