"""A machine of the original SMACH (each branch's core) sent away as an fsm machine is: a Publisher to
a real server over its websocket, and a Zenoh robot to a dashboard's watcher over real Zenoh sessions
on the loopback. What arrives is every event the machine sent, in order, and the state they build."""

import fsm
import pytest
from fleet_support import TOKEN, Delivered, free_endpoint
from fsm.observation.status import rebuild
from fsm.observation.structure import walk
from fsmscope import Publisher
from fsmscope.fleet.robot import ZenohRobot
from fsmscope.server.testing.polling import wait_for
from server_support import client

from original_support import SCENARIOS
from parity_support import Side

pytestmark = pytest.mark.timeout(60)


def nested(core):
    core.set_loggers(*[lambda msg: None] * 4)
    return SCENARIOS["nested"](Side(core))


def test_a_publisher_shows_an_original_machine_on_a_server(core, live_server):
    sm, own = nested(core), []
    publisher = Publisher(live_server.base_url, live_server.token)
    try:
        fsm.attach(sm, publisher, name="remote")
        fsm.attach(sm, own.append)
        assert publisher.connected.wait(5)
        assert sm.execute() == "succeeded"
        assert publisher.flush(5)
        http = client(live_server)
        status = wait_for(lambda: (r := http.get("/api/machines/remote/status")).status_code == 200
                          and r.json()["outcome"] and r.json())
        expected = rebuild(own)["remote"].to_dict()
        assert (status["outcome"], status["containers"]) == (expected["outcome"], expected["containers"])
        served = http.get("/api/machines/remote/structure").json()
        assert [n["path"] for n, _ in walk(served)] == [n["path"] for n, _ in walk(own[0]["root"])]
    finally:
        publisher.close()


def test_a_zenoh_robot_puts_an_original_machine_on_the_fleet(core):
    endpoint = free_endpoint()
    dash = Delivered(listen=[endpoint])
    robot = ZenohRobot("r1", connect=[endpoint], token=TOKEN)
    try:
        sm, own = nested(core), []
        fsm.attach(sm, robot, name="nested")
        fsm.attach(sm, own.append)
        assert sm.execute() == "succeeded"
        robot.flush()
        wait_for(lambda: dash.events and dash.events[-1]["seq"] == own[-1]["seq"], 10, what="the last event")
        assert [e["seq"] for e in dash.events if e["kind"] != "snapshot"] == [e["seq"] for e in own]
        assert dash.status("r1:nested").to_dict() == dict(rebuild(own)["nested"].to_dict(), machine="r1:nested")
    finally:
        robot.close()
        dash.watcher.close()
