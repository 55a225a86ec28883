"""Zenoh's access control on a robot (docs/fleet.md), given as a user gives it: a Zenoh configuration
file (``--zenoh-config``; here ``config_file=``, the same path through fsmscope/fleet/config.py) with
user-password authentication (``transport/auth/usrpwd``: the robot checks each session's user and
password against its dictionary file) and an ``access_control`` block naming what each user may do.
User "operator" may do everything on the fleet's keys; user "viewer" may watch (subscribe to the
events and the liveliness tokens, query ``.../state`` and ``.../history``), and its queries on
``.../control`` are denied: whatever token a control proves, the robot's Zenoh drops it before
fsmscope sees it. The operator's dashboard, holding a lease, is followed for the deadman (its
heartbeats, outside ``fsmscope/``, have their own key expression in the operator's rule). A
session whose password is wrong is not let in at all. Zenoh's ACL says all of this as it is;
docs/fleet.md shows the same file.

Real Zenoh sessions on the loopback: the robot listens on an explicit tcp endpoint, each dashboard
(a FleetWatcher) connects to it with its own user and password; no multicast scouting.

What Zenoh does with a denied query (eclipse-zenoh 1.10): the querier's ``get`` ends at once with
no reply, neither an error reply nor a time-out, as if no queryable matched. fsmscope/fleet/query.py takes
such an ending for "reached nobody yet" and asks again until its time-out, so a viewer's control
ends as "no answer" (None; the dashboard's 504) after the watcher's QUERY_TIMEOUT.
"""

from __future__ import annotations

import time
from pathlib import Path
from types import SimpleNamespace

import fsm
import pytest
from fleet_support import TOKEN, EVERY_MESSAGE, Dashboard, access_configuration, user_configuration, free_endpoint, run_published, slow_loop

from fsmscope.fleet import control, keys
from fsmscope.fleet.robot import ZenohRobot
from fsmscope.fleet.watcher import FleetWatcher
from fsmscope.server.testing.polling import wait_for

PASSWORDS = {"operator": "operator-secret", "viewer": "viewer-secret"}
NAME = "r1:loop"


def robot_configuration(directory: Path) -> str:
    """The robot's Zenoh configuration file (docs/fleet.md shows it): the users' dictionary, and what
    each may do; anything no rule allows is denied."""
    return access_configuration(directory, "robot", PASSWORDS, {
        "enabled": True,
        "default_permission": "deny",
        "rules": [
            # The dashboards' heartbeats too: the robot follows its operator's for the deadman.
            {"id": "everything", "permission": "allow", "flows": ["ingress", "egress"],
             "messages": EVERY_MESSAGE, "key_exprs": ["fsmscope/**", "fsmscope-dashboards/**"]},
            {"id": "watch", "permission": "allow", "flows": ["ingress"],
             "messages": ["declare_subscriber", "declare_liveliness_subscriber", "liveliness_query", "query"],
             "key_exprs": ["fsmscope/**"]},
            {"id": "be watched", "permission": "allow", "flows": ["egress"],
             "messages": ["put", "delete", "reply", "liveliness_token", "declare_queryable"],
             "key_exprs": ["fsmscope/**"]},
            # An explicit deny wins over an allow: no query on a machine's control key.
            {"id": "no control", "permission": "deny", "flows": ["ingress"], "messages": ["query"],
             "key_exprs": ["fsmscope/*/*/control"]},
        ],
        "subjects": [{"id": "operators", "usernames": ["operator"]},
                     {"id": "viewers", "usernames": ["viewer"]}],
        "policies": [{"rules": ["everything"], "subjects": ["operators"]},
                     {"rules": ["watch", "be watched", "no control"], "subjects": ["viewers"]}],
    })


@pytest.fixture
def fleet(tmp_path):
    """Robot r1 (control token TOKEN) listening with the configuration above, its machine "loop"
    ticking every 20 ms until preempted; ``dashboard(user, password)`` connects a dashboard's watcher
    to it. Yields a namespace: robot, its endpoint, own (the robot's recorded events), runner, dashboard."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    endpoint = free_endpoint()
    robot = ZenohRobot("r1", listen=[endpoint], token=TOKEN, config_file=robot_configuration(tmp_path))
    sm = slow_loop(100_000, 0.02)
    own, runner = run_published(robot, sm)
    watchers: list[FleetWatcher] = []

    def dashboard(user: str, password: str) -> SimpleNamespace:
        seen: list[dict] = []
        alive: list[tuple[str, bool]] = []
        watcher = FleetWatcher(seen.extend, lambda name, up: alive.append((name, up)), connect=[endpoint],
                               config_file=user_configuration(tmp_path, user, password), tokens={None: TOKEN})
        watchers.append(watcher)
        return SimpleNamespace(watcher=watcher, seen=seen, alive=alive)

    try:
        yield SimpleNamespace(robot=robot, own=own, runner=runner, dashboard=dashboard, endpoint=endpoint)
    finally:
        sm.request_preempt()
        runner.join(10)
        for watcher in watchers:
            watcher.close()
        robot.close()


def joined(dashboard: SimpleNamespace) -> None:
    wait_for(lambda: NAME in dashboard.watcher.controls, 10, what="the dashboard joined the robot's machine")


def controls_of(events: list[dict]) -> list[dict]:
    return [e for e in events if e["kind"] == "control"]


def test_a_viewers_dashboard_sees_the_robots_machine_and_its_events(fleet):
    viewer = fleet.dashboard("viewer", PASSWORDS["viewer"])
    wait_for(lambda: len(viewer.seen) >= 20, 10, what=lambda: "20 events for the viewer, got %d" % len(viewer.seen))
    assert (NAME, True) in viewer.alive  # the machine's liveliness token reached it
    assert viewer.watcher.controls[NAME] == {"can_start": False}  # its state query was answered
    seen = [e for e in list(viewer.seen) if e["kind"] != "snapshot"]
    seqs = [e["seq"] for e in seen]
    assert seqs == list(range(seqs[0], seqs[0] + len(seqs)))  # in order, without a gap
    wait_for(lambda: fleet.own[-1]["seq"] >= seqs[-1], 5, what="the robot's own record of those events")
    own = {e["seq"]: e for e in list(fleet.own)}
    assert [(e["seq"], e["kind"], e["path"]) for e in seen] == [(s, own[s]["kind"], own[s]["path"]) for s in seqs]


def test_a_viewers_control_is_never_applied_even_with_the_robots_token(fleet, monkeypatch):
    monkeypatch.setattr("fsmscope.fleet.watcher.QUERY_TIMEOUT", 1.5)  # the dashboard's 5 s, shortened
    viewer = fleet.dashboard("viewer", PASSWORDS["viewer"])
    joined(viewer)
    started = time.monotonic()
    answer = viewer.watcher.ask("r1", "loop", TOKEN, "preempt", {"reason": "from a viewer"}, "viewer")
    waited = time.monotonic() - started
    assert answer is None  # no answer came: the dashboard says the robot did not answer (504)
    assert waited < 1.5 + 2.0  # ended with the watcher's time-out, did not hang
    events = len(fleet.own)
    wait_for(lambda: len(fleet.own) >= events + 10, 5, what="the machine still running after the viewer's preempt")
    assert fleet.runner.is_alive()
    assert not any(e["kind"] == "terminate" for e in list(fleet.own))
    assert controls_of(list(fleet.own)) == []
    assert fleet.robot.controls.refused == 0  # not refused by fsmscope's token check: it never got there


def test_a_viewers_dashboard_answers_its_preempt_with_a_504_naming_the_access_control(fleet, tmp_path):
    dash = Dashboard("--zenoh", fleet.endpoint, "--zenoh-token", "r1=" + TOKEN,
                     "--zenoh-config", user_configuration(tmp_path, "viewer", PASSWORDS["viewer"]))
    try:
        wait_for(lambda: dash.machines().get(NAME, {}).get("running"), 15, what="the dashboard showing the machine")
        answer = dash.post("/api/machines/%s/preempt" % NAME, {})
        assert answer.status_code == 504
        assert "access control denies this dashboard's controls" in answer.json()["detail"]
        assert dash.machines()[NAME]["running"] and controls_of(list(fleet.own)) == []
    finally:
        dash.stop()


def test_zenoh_ends_a_viewers_query_on_the_control_key_at_once_without_a_reply(fleet):
    viewer = fleet.dashboard("viewer", PASSWORDS["viewer"])
    joined(viewer)
    session = viewer.watcher.session
    started = time.monotonic()
    key = keys.control_key("r1", "loop")
    payload, proof = control.request(TOKEN, key, {"action": "preempt", "params": {}, "client": "viewer", "counter": 1,
                                                  "dashboard": viewer.watcher.id, "origin": fleet.robot.controls.origin})
    replies = list(session.get(key, payload=payload, attachment=proof, timeout=5.0))
    assert replies == []  # neither the robot's answer nor an error reply
    assert time.monotonic() - started < 2.5  # not the query's 5 s time-out
    [state] = list(session.get(keys.state_key("r1", "loop"), timeout=5.0))  # a query it may ask is answered
    assert state.ok is not None
    assert controls_of(list(fleet.own)) == []


def test_the_operators_control_with_the_token_is_applied(fleet):
    operator = fleet.dashboard("operator", PASSWORDS["operator"])
    joined(operator)
    answer = operator.watcher.ask("r1", "loop", TOKEN, "preempt", {"reason": "the operator stops it"}, "operator")
    assert answer["status"] == 202
    fleet.runner.join(10)
    assert not fleet.runner.is_alive()  # the run ended
    [event] = controls_of(list(fleet.own))
    assert (event["seq"], event["action"], event["client"], event["result"], event["reason"]) == (
        answer["seq"], "preempt", "operator", "accepted", "the operator stops it")


def test_the_robot_applies_the_deadman_when_the_operators_dashboard_holding_the_lease_is_gone(fleet):
    operator = fleet.dashboard("operator", PASSWORDS["operator"])
    joined(operator)
    lease = {"held": True, "after": 0.3, "action": "preempt", "dashboard": operator.watcher.id}
    assert operator.watcher.ask("r1", "loop", TOKEN, "lease", lease, "operator") == {"status": 200}
    operator.watcher.close()
    wait_for(lambda: any(e["kind"] == "terminate" for e in list(fleet.own)), 10, what="the run ended by the deadman")
    assert [(e["action"], e["client"]) for e in controls_of(list(fleet.own))] == [("deadman", "robot"),
                                                                                  ("preempt", "robot")]


def test_a_session_with_a_wrong_password_reaches_nothing(fleet):
    intruder = fleet.dashboard("operator", "not-" + PASSWORDS["operator"])
    viewer = fleet.dashboard("viewer", PASSWORDS["viewer"])  # opened after the intruder, it sees the machine
    wait_for(lambda: len(viewer.seen) >= 10, 10, what="the rightful viewer seeing the machine")
    time.sleep(0.5)  # the intruder has had longer than the viewer, and half a second more
    assert list(intruder.watcher.session.info.peers_zid()) == []  # the robot closed its link
    assert (intruder.seen, intruder.alive, intruder.watcher.controls) == ([], [], {})
    assert controls_of(list(fleet.own)) == []
