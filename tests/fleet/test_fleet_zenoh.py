"""The fleet over real Zenoh sessions on the loopback (explicit tcp endpoints, multicast scouting
off): a robot's machine reaches a dashboard's watcher from its first event (or, once the robot let
that go, as a snapshot) and then every event, whenever the dashboard joins; a robot that leaves is seen gone and seen back; a connection cut and restored
while the machine runs leaves no gap."""

from __future__ import annotations

import contextlib
import threading
import time
from typing import Callable

import fsm
import pytest
from fleet_support import TOKEN, Delivered, Proxy, free_endpoint, run_published, slow_loop

import fsmscope.fleet.robot
from fsmscope.fleet.robot import ZenohRobot
from fsm.control.handle import MachineHandle
from fsm.observation.encoding import dumps
from fsm.observation.status import Status
from fsmscope.server.testing.polling import wait_for


@pytest.fixture
def quiet():
    fsm.set_loggers(*(lambda msg: None,) * 4)


def run_on(robot: ZenohRobot, sm, name: str = "loop") -> list[dict]:
    """Run ``sm`` published by ``robot``; the events it emitted, as the robot's own log has them."""
    own = []
    fsm.attach(sm, robot, name=name)
    fsm.attach(sm, own.append)
    sm.execute()
    robot.flush()
    return own


def own_status(events: list[dict]) -> dict:
    status = Status("loop")
    for event in events:
        status.apply(event)
    return status.to_dict()


def test_a_dashboard_there_first_gets_every_event_in_order(quiet):
    endpoint = free_endpoint()
    dash = Delivered(listen=[endpoint])
    robot = ZenohRobot("r1", connect=[endpoint], token=TOKEN)
    try:
        own = run_on(robot, slow_loop(60))
        wait_for(lambda: dash.events and dash.events[-1]["seq"] == own[-1]["seq"], 10,
                 what=lambda: "the last event (%d) delivered: %r, alive %r" % (
                     own[-1]["seq"], [(e["kind"], e["seq"]) for e in dash.events[-3:]], dash.alive))
        assert [e["seq"] for e in dash.events] == [e["seq"] for e in own]
        assert {e["machine"] for e in dash.events} == {"r1:loop"}
        assert dash.status("r1:loop").to_dict() == dict(own_status(own), machine="r1:loop")
    finally:
        robot.close()
        dash.watcher.close()


def run_then_join() -> tuple[list[dict], Delivered]:
    """A robot runs its machine to the end, then a dashboard joins: the robot's own events, and the
    dashboard with what it was given first."""
    endpoint = free_endpoint()
    robot = ZenohRobot("r1", listen=[endpoint], token=TOKEN)
    try:
        own = run_on(robot, slow_loop(40, 0.0))  # more events than a batch of the test below: one event per step
        dash = Delivered(connect=[endpoint])
        try:
            wait_for(lambda: dash.events, 10, what="the machine")
        finally:
            dash.watcher.close()
    finally:
        robot.close()
    return own, dash


def test_a_dashboard_that_joins_after_the_run_gets_the_whole_run_the_robot_keeps(quiet):
    own, dash = run_then_join()
    assert [e["seq"] for e in dash.events] == [e["seq"] for e in own]
    assert dash.status("r1:loop").to_dict() == dict(own_status(own), machine="r1:loop")


def test_a_dashboard_that_joins_after_the_robot_let_the_runs_start_go_gets_its_end_as_a_snapshot(quiet,
                                                                                                  monkeypatch):
    monkeypatch.setattr(fsmscope.fleet.robot, "MAX_BATCH", 16)  # batches of 16 events (the size is looked at every 16)
    monkeypatch.setattr(fsmscope.fleet.robot, "RING", 3)  # of which the robot keeps the newest
    own, dash = run_then_join()
    assert [e["kind"] for e in dash.events] == ["snapshot"] and dash.events[0]["seq"] == own[-1]["seq"]
    assert dash.events[0]["status"]["outcome"] == "done"


def test_a_robot_that_leaves_is_seen_gone_and_seen_back(quiet):
    endpoint = free_endpoint()
    dash = Delivered(listen=[endpoint])
    try:
        robot = ZenohRobot("r1", connect=[endpoint], token=TOKEN)
        run_on(robot, slow_loop(4, 0.0))
        wait_for(lambda: ("r1:loop", True) in dash.alive, 10, what="the machine seen")
        robot.close()
        wait_for(lambda: dash.alive[-1] == ("r1:loop", False), 10, what="the machine seen gone")
        again = ZenohRobot("r1", connect=[endpoint], token=TOKEN)
        try:
            run_on(again, slow_loop(4, 0.0))
            wait_for(lambda: dash.alive[-1] == ("r1:loop", True), 10, what="the machine seen back")
        finally:
            again.close()
    finally:
        dash.watcher.close()


def test_a_robot_back_as_a_new_process_is_shown_from_a_new_snapshot(quiet):
    """Its seqs start again: what the dashboard shows is the new process's run, not the old one's."""
    endpoint = free_endpoint()
    dash = Delivered(listen=[endpoint])
    try:
        with ZenohRobot("r1", connect=[endpoint], token=TOKEN) as robot:
            run_on(robot, slow_loop(40, 0.0))
            wait_for(lambda: dash.events and dash.events[-1]["seq"] > 40, 10, what="the first process's run")
        wait_for(lambda: dash.alive[-1] == ("r1:loop", False), 10, what="the machine seen gone")
        with ZenohRobot("r1", connect=[endpoint], token=TOKEN) as again:
            own = run_on(again, slow_loop(4, 0.0))
            wait_for(lambda: dash.status("r1:loop").last_seq == own[-1]["seq"], 10,
                     what=lambda: "the new run: %r" % [(e["kind"], e["seq"]) for e in dash.events[-5:]])
            assert dash.status("r1:loop").to_dict() == dict(own_status(own), machine="r1:loop")
    finally:
        dash.watcher.close()


def gated_machine(gate: threading.Event) -> fsm.StateMachine:
    """FIRST, then WAIT until ``gate`` is set, then LAST: done."""
    sm = fsm.StateMachine(["done"])
    with sm:
        fsm.StateMachine.add("FIRST", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "WAIT"})
        fsm.StateMachine.add("WAIT", fsm.CBState(lambda ud: gate.wait(10) and "go", outcomes=["go"]), {"go": "LAST"})
        fsm.StateMachine.add("LAST", fsm.CBState(lambda ud: "done", outcomes=["done"]), {"done": "done"})
    return sm


def test_the_last_events_of_a_run_put_while_the_dashboard_joins_reach_it(quiet):
    """Put after the robot answered the join's history, before the join is applied: nothing follows
    them to show the gap, so the join asks for them itself."""
    endpoint = free_endpoint()
    gate = threading.Event()
    with ZenohRobot("r1", listen=[endpoint], token=TOKEN) as robot:
        own, runner = run_published(robot, gated_machine(gate))
        wait_for(lambda: own and own[-1]["kind"] == "transition" and own[-1]["to"] == "WAIT", 10,
                 what="the machine waiting at its gate")
        robot.flush()
        dash = Delivered(connect=[endpoint])
        answered = dash.watcher._history

        def history_then_the_runs_end(*query):
            answer = answered(*query)
            gate.set()  # the machine ends now, its last events on their way while the join is applied
            runner.join(10)
            robot.flush()
            time.sleep(0.5)
            return answer

        dash.watcher._history = history_then_the_runs_end
        try:
            wait_for(lambda: dash.status("r1:loop").last_seq == own[-1]["seq"], 10,
                     what=lambda: "the run's end: %r" % [(e["kind"], e["seq"]) for e in dash.events[-3:]])
        finally:
            dash.watcher.close()


@contextlib.contextmanager
def a_run_cut_for_a_second(before_the_cut: Callable[[Delivered], None] = lambda dash: None):
    """r1's machine (300 ticks of 10 ms) followed by a dashboard whose connection to it is cut for 1 s
    once 20 events came (``before_the_cut(dash)`` is called then), and restored: yields the dashboard
    and the robot's own events once the dashboard has the run's last one."""
    endpoint = free_endpoint()
    dash = Delivered(listen=[endpoint])
    proxy = Proxy(endpoint)
    robot = ZenohRobot("r1", connect=[proxy.endpoint], token=TOKEN)
    try:
        sm = slow_loop(300, 0.01)
        own: list[dict] = []
        runner = threading.Thread(target=lambda: own.extend(run_on(robot, sm)), daemon=True)
        runner.start()
        wait_for(lambda: len(dash.events) > 20, 10, what="events before the cut")
        before_the_cut(dash)
        proxy.cut()
        time.sleep(1.0)  # the machine runs on, unseen
        proxy.restore()
        runner.join(30)
        wait_for(lambda: dash.events[-1]["seq"] == own[-1]["seq"], 20, what="the last event after the cut")
        yield dash, own
    finally:
        robot.close()
        proxy.close()
        dash.watcher.close()


def every_event_after_the_first(dash: Delivered, own: list[dict]) -> bool:
    first = dash.events[0]["seq"]
    return [e["seq"] for e in dash.events[1:]] == [e["seq"] for e in own if e["seq"] > first]


def test_a_connection_cut_and_restored_while_the_machine_runs_leaves_no_gap(quiet):
    with a_run_cut_for_a_second() as (dash, own):
        assert every_event_after_the_first(dash, own)
        assert dash.watcher.backfilled == 1  # it joined from the first event
        assert dash.watcher.gaps_filled + dash.watcher.snapshots >= 1  # it did miss events, and got them back


def test_a_gap_whose_history_the_robot_did_not_answer_in_time_is_filled_later_not_jumped(quiet):
    unanswered = []

    def first_two_unanswered(dash: Delivered) -> None:
        answered = dash.watcher._history

        def history(*query):
            if len(unanswered) < 2:  # a robot (or a network) too slow for QUERY_TIMEOUT
                unanswered.append(query)
                return None
            return answered(*query)
        dash.watcher._history = history

    with a_run_cut_for_a_second(first_two_unanswered) as (dash, own):
        assert len(unanswered) == 2
        assert every_event_after_the_first(dash, own)


def test_a_robot_following_its_host_publishes_the_hosts_encoded_events_and_answers_from_its_status(quiet):
    """As `fsmscope run --zenoh` composes it (the hub is the host): the robot observes nothing itself."""
    endpoint = free_endpoint()
    robot = ZenohRobot("r1", listen=[endpoint], token=TOKEN)
    host = Status("loop")
    lock = threading.Lock()
    own: list[dict] = []
    try:
        sm = slow_loop(10, 0.0)
        reporter = fsm.attach(sm, own.append, name="loop")
        take = robot.follow("loop", MachineHandle(sm, reporter, can_start=False), lock, lambda: host)

        def host_observer(event: dict) -> None:
            with lock:
                host.apply(event)
            take([(event["seq"], dumps(event))])

        reporter.add_observer(host_observer)
        dash = Delivered(connect=[endpoint])
        try:
            wait_for(lambda: ("r1:loop", True) in dash.alive and dash.events, 10, what="the machine's snapshot")
            sm.execute()
            robot.flush()
            wait_for(lambda: dash.events[-1]["seq"] == own[-1]["seq"], 10, what="the last event")
            assert robot._machines["loop"].status.last_seq == 0  # the robot kept no Status of its own
            assert dash.status("r1:loop").to_dict() == dict(own_status(own), machine="r1:loop")
        finally:
            dash.watcher.close()
    finally:
        robot.close()


def test_two_dashboards_watch_the_same_robot_and_each_gets_every_event(quiet):
    first, second = free_endpoint(), free_endpoint()
    dashes = [Delivered(listen=[first]), Delivered(listen=[second])]
    robot = ZenohRobot("r1", connect=[first, second], token=TOKEN)
    try:
        own = run_on(robot, slow_loop(60))
        for dash in dashes:
            wait_for(lambda: dash.events and dash.events[-1]["seq"] == own[-1]["seq"], 10, what="the last event")
            assert dash.status("r1:loop").to_dict() == dict(own_status(own), machine="r1:loop")
    finally:
        robot.close()
        for dash in dashes:
            dash.watcher.close()


def test_a_closed_robot_keeps_no_more_than_a_batch_of_what_its_machine_still_does(quiet):
    robot = ZenohRobot("r1", token=TOKEN)
    sm = slow_loop(400, 0.0)
    fsm.attach(sm, robot, name="loop")
    sm.execute()
    robot.close()
    sm.get_children()["A"].count[0] = 0  # the loop ticks its 400 times again
    sm.execute()
    assert sum(map(len, robot._machines["loop"].pending)) < fsmscope.fleet.robot.MAX_BATCH


def test_a_machine_that_first_runs_after_its_robot_closed_runs_unpublished(quiet):
    robot = ZenohRobot("r1", token=TOKEN)
    sm = slow_loop(4, 0.0)
    fsm.attach(sm, robot, name="loop")
    robot.close()
    assert sm.execute() == "done" and "loop" not in robot._machines


def test_the_flusher_puts_a_quiet_machines_batch_at_the_tick_and_leaves_a_busy_ones_to_it_a_tick_longer(quiet):
    robot = ZenohRobot("r1", listen=[free_endpoint()], token=TOKEN)
    try:
        robot._declare("m")
        machine = robot._machines["m"]
        machine.take([(1, b"{}")])  # one hand-over in the tick: a machine that waits for it
        assert machine.flush(machine.due) is None and not machine.pending
        machine.take([(2, b"{}")])
        machine.due = time.monotonic() + 60  # the tick stays ahead while the test hands over again
        machine.take([(3, b"{}")])  # a second hand-over in the same tick: a busy machine
        due = machine.due
        assert machine.flush(due) == due + fsmscope.fleet.robot.LINGER and sum(map(len, machine.pending)) == 2
        assert machine.flush(due + fsmscope.fleet.robot.LINGER) is None and not machine.pending
    finally:
        robot.close()
