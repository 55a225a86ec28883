"""Robots behind a router (docs/fleet.md, "Robots behind a zenohd router"): the robot and the
dashboard are clients of a Zenoh session in router mode on the loopback, the routing zenohd runs
(zenohd itself is not a Python package). Everything goes through the router: the machine is found,
every event arrives, a control reaches the robot and its answer comes back, and a robot that leaves
is seen gone. Then the README's set-up in real processes, with ``fsmscope router``: one site's
router, and two sites' routers linked."""

from __future__ import annotations


import fsm
import pytest
import zenoh
from fleet_support import (TOKEN, Dashboard, Robot, Router, free_endpoint, preempted_the_dashboard_has_the_robots_log,
                           run_published, slow_loop)

from fsmscope.fleet.config import session_config
from fsmscope.fleet.robot import ZenohRobot
from fsmscope.fleet.watcher import FleetWatcher
from fsmscope.server.testing.polling import wait_for



@pytest.fixture
def behind_a_router():
    """A router; a dashboard's watcher and robot r1, both its clients. Yields (watcher, robot,
    what the watcher delivered, whom it saw come and go)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    endpoint = free_endpoint()
    router = zenoh.open(session_config(listen=[endpoint], mode="router"))
    delivered: list[dict] = []
    seen: list[tuple[str, bool]] = []
    watcher = FleetWatcher(delivered.extend, lambda name, up: seen.append((name, up)), connect=[endpoint],
                           mode="client", tokens={None: TOKEN})
    robot = ZenohRobot("r1", connect=[endpoint], mode="client", token=TOKEN)
    try:
        yield watcher, robot, delivered, seen
    finally:
        robot.close()
        watcher.close()
        router.close()


def test_a_dashboard_behind_a_router_gets_every_event_of_a_robot_behind_it(behind_a_router):
    watcher, robot, delivered, seen = behind_a_router
    own, runner = run_published(robot, slow_loop(40))
    runner.join(20)
    robot.flush()
    wait_for(lambda: delivered and delivered[-1]["seq"] == own[-1]["seq"], 10,
             what=lambda: "the last event (%d) through the router: %r" % (
                 own[-1]["seq"], [(e["kind"], e["seq"]) for e in delivered[-3:]]))
    assert [e["seq"] for e in delivered if e["kind"] != "snapshot"][-len(own):] == [e["seq"] for e in own]
    assert ("r1:loop", True) in seen


def test_a_control_goes_through_the_router_to_the_robot_and_its_answer_comes_back(behind_a_router):
    watcher, robot, delivered, seen = behind_a_router
    sm = slow_loop(100_000, 0.02)
    own, runner = run_published(robot, sm)
    try:
        wait_for(lambda: watcher.controls.get("r1:loop"), 10, what="the machine joined through the router")
        answer = watcher.ask("r1", "loop", TOKEN, "preempt", {"reason": "through the router"}, "operator")
        assert answer["status"] == 202
        runner.join(10)
        assert not runner.is_alive()
        assert [(e["action"], e["reason"]) for e in own if e["kind"] == "control"] == [("preempt", "through the router")]
    finally:
        sm.request_preempt()
        runner.join(10)


def test_a_robot_behind_a_router_that_leaves_is_seen_gone(behind_a_router):
    watcher, robot, delivered, seen = behind_a_router
    own, runner = run_published(robot, slow_loop(5, 0.0))
    runner.join(10)
    wait_for(lambda: ("r1:loop", True) in seen, 10, what="the machine seen through the router")
    robot.close()
    wait_for(lambda: seen[-1] == ("r1:loop", False), 10, what=lambda: "the machine seen gone: %r" % seen)


@pytest.fixture
def processes():
    """Stops, after the test, the real processes the test started (given to it)."""
    started: list = []
    yield started.append
    for proc in reversed(started):
        proc.stop()


@pytest.mark.parametrize("sites", [1, 2], ids=["one router", "two sites' routers linked"])
def test_a_dashboard_behind_fsmscope_routers_shows_a_robots_whole_run_and_preempts_it(tmp_path, processes, sites):
    routers = [Router()]
    processes(routers[0])
    if sites == 2:
        routers.append(Router("--connect", routers[0].endpoint))  # the dashboard's site joins the robot's
        processes(routers[1])
    robot = Robot("r1", routers[0].endpoint, TOKEN, tmp_path / "r1.jsonl")
    processes(robot)
    dash = Dashboard(routers[-1].endpoint, "--zenoh-mode", "client", "--zenoh-token", TOKEN, listen=False)
    processes(dash)
    wait_for(lambda: dash.machines().get("r1:patrol", {}).get("running"), 20, what="r1:patrol running")
    preempted_the_dashboard_has_the_robots_log(dash, robot, 1)


def test_a_robot_started_while_its_router_is_down_runs_and_its_whole_run_reaches_the_dashboard_later(
        tmp_path, processes):
    endpoint = free_endpoint()
    robot = Robot("r1", endpoint, TOKEN, tmp_path / "r1.jsonl")  # a peer of the router: it starts without it
    processes(robot)
    wait_for(lambda: tmp_path.joinpath("r1.jsonl").exists() and len(robot.events()) >= 6, 20,
             what="the robot's patrol recorded with no router up")
    processes(Router(endpoint=endpoint))
    dash = Dashboard(endpoint, "--zenoh-mode", "client", "--zenoh-token", TOKEN, listen=False)
    processes(dash)
    wait_for(lambda: dash.machines().get("r1:patrol", {}).get("running"), 20, what="r1:patrol running")
    preempted_the_dashboard_has_the_robots_log(dash, robot, 1)
