"""Controlling a machine of the original smach from the dashboard, against a real uvicorn: preempt,
initial state and start, with the roles, the lease, the deadman and the audit of an fsm machine, and
what its structure cannot take refused with a 4xx saying why (docs/debugging.md, "Machines of the
original smach"; README's table). Its debugger: test_original_debug.py."""

import contextlib

import httpx
import pytest
from fsmscope.server.http_server import ServerThread
from fsmscope.server.lease import Deadman
from fsmscope.server.testing.polling import wait_for

from original_control_support import (Bare, holds, loop, run_in_thread, smach, status,  # noqa: F401
                                      visiting, waiter, waiting)
from server_support import client, control_events as controls, looping_machine


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


def test_initial_userdata_is_the_containers_and_reaches_a_state_through_its_remapping(live_server, smach):
    seen = []

    def read(ud):
        seen.append(ud.goal)
        return "done"

    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("READ", smach.CBState(read, outcomes=["done"], input_keys=["goal"]), {"done": "done"},
                               remapping={"goal": "target"})
    live_server.hub.add_local(sm, name="remapped")
    http = client(live_server)
    assert http.post("/api/machines/remapped/initial-state", json={"userdata": {"target": 7}}).status_code == 200
    assert http.post("/api/machines/remapped/start", json={}).status_code == 202
    wait_for(lambda: seen)
    assert seen == [7] and sm.userdata.target == 7


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


def test_start_runs_an_original_machine_holding_a_state_with_nothing_but_execute_and_outcomes(live_server, smach):
    """SMACH runs any object with a state's interface: no preempt methods, no attributes (``__slots__``)."""

    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("BARE", Bare(), {"go": "done"})
    live_server.hub.add_local(sm, name="bare")
    http = client(live_server)
    assert http.post("/api/machines/bare/start", json={}).status_code == 202
    wait_for(lambda: status(http, "bare")["outcome"] == "done")


def test_an_initial_state_set_while_the_original_machine_runs_takes_effect_at_its_next_run(live_server, smach):
    sm, stop = looping_machine(smach)
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
    sm, stop = looping_machine(smach)
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
