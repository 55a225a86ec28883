"""The router set-up of docs/fleet.md with Zenoh's own security as the first wall: ``fsmscope router``
given a configuration file (``--zenoh-config``) with user-password authentication (each robot and
dashboard its own user) and access control that lets each robot's user put only on its own keys,
and the dashboards' users watch and control. Real ``router``, ``run`` and ``serve`` processes on
the loopback, as a user starts them: a robot's user cannot publish as another robot, even holding
the fleet's token, and a session without a password is not let in."""

from __future__ import annotations

from pathlib import Path

import pytest
from fleet_support import (TOKEN, EVERY_MESSAGE, Dashboard, Robot, Router, access_configuration,
                           preempted_the_dashboard_has_the_robots_log, user_configuration)

from fsmscope.fleet.watcher import FleetWatcher
from fsmscope.server.testing.polling import wait_for

PASSWORDS = {"r1": "r1-secret", "operator": "operator-secret"}


def router_configuration(directory: Path) -> str:
    """The router's file (docs/fleet.md shows it): the users' dictionary; robot r1's user may do
    anything on r1's keys and its dashboards' heartbeats, the operator on the whole fleet's; anything
    no rule allows is denied."""
    return access_configuration(directory, "router", PASSWORDS, {
        "enabled": True,
        "default_permission": "deny",
        "rules": [
            {"id": "robot r1", "permission": "allow", "flows": ["ingress", "egress"], "messages": EVERY_MESSAGE,
             "key_exprs": ["fsmscope/r1/**", "fsmscope-dashboards/*/r1"]},
            # The dashboards' subscriptions (fsmscope/*/*/events) told to the robot: without them it
            # puts nowhere, since Zenoh sends a put only towards a subscriber it knows of.
            {"id": "hear of subscribers", "permission": "allow", "flows": ["egress"],
             "messages": ["declare_subscriber", "declare_liveliness_subscriber"], "key_exprs": ["fsmscope/**"]},
            {"id": "dashboards", "permission": "allow", "flows": ["ingress", "egress"], "messages": EVERY_MESSAGE,
             "key_exprs": ["fsmscope/**", "fsmscope-dashboards/**"]},
        ],
        "subjects": [{"id": "r1", "usernames": ["r1"]}, {"id": "operators", "usernames": ["operator"]}],
        "policies": [{"rules": ["robot r1", "hear of subscribers"], "subjects": ["r1"]},
                     {"rules": ["dashboards"], "subjects": ["operators"]}],
    })


@pytest.fixture
def router(tmp_path):
    router = Router("--zenoh-config", router_configuration(tmp_path))
    started: list = [router]
    yield router, started.append
    for proc in reversed(started):
        proc.stop()


def test_behind_a_router_with_passwords_a_robot_publishes_only_as_itself_and_the_operator_preempts_it(
        tmp_path, router):
    router, processes = router
    as_r1 = ("--zenoh-config", user_configuration(tmp_path, "r1", PASSWORDS["r1"]))
    robot = Robot("r1", router.endpoint, TOKEN, tmp_path / "r1.jsonl", options=as_r1)
    processes(robot)
    posing = Robot("r2", router.endpoint, TOKEN, tmp_path / "r2.jsonl", options=as_r1)  # r1's user, as r2
    processes(posing)
    dash = Dashboard(router.endpoint, "--zenoh-mode", "client", "--zenoh-token", TOKEN, "--zenoh-config",
                     user_configuration(tmp_path, "operator", PASSWORDS["operator"]), listen=False)
    processes(dash)
    wait_for(lambda: dash.machines().get("r1:patrol", {}).get("running"), 20, what="r1:patrol running")
    wait_for(lambda: tmp_path.joinpath("r2.jsonl").exists() and len(posing.events()) >= 6, 20,
             what="the posing robot's patrol running")
    assert "r2:patrol" not in dash.machines()  # its puts and its token were denied by the router
    preempted_the_dashboard_has_the_robots_log(dash, robot, 1)


@pytest.mark.parametrize("password", [None, "a guess"], ids=["no password", "a wrong password"])
def test_a_dashboard_without_the_routers_password_is_not_let_in(tmp_path, router, password):
    router, _ = router
    config = None if password is None else user_configuration(tmp_path, "operator", password)
    with pytest.raises(ValueError, match="cannot open a Zenoh session"):
        FleetWatcher(lambda events: None, lambda name, up: None, connect=[router.endpoint], mode="client",
                     config_file=config, tokens={None: TOKEN})
