"""What fsmscope opens a Zenoh session as: it listens only where it is told to (Zenoh's own default
would have a peer listen on every interface), and an endpoint Zenoh cannot use ends the command
with why, before it starts; a command says where its session meets the others."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from fleet_support import TOKEN, ROOT, free_endpoint, started, stop

from fsmscope.fleet.robot import ZenohRobot


def listening_ports() -> set[int]:
    """The tcp ports this process listens on, read from /proc (the sockets among its open files)."""
    inodes = set()
    for fd in os.listdir("/proc/self/fd"):
        try:
            target = os.readlink("/proc/self/fd/" + fd)
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    ports = set()
    for table in ("/proc/self/net/tcp", "/proc/self/net/tcp6"):
        with open(table) as rows:
            for row in list(rows)[1:]:
                fields = row.split()
                if fields[3] == "0A" and fields[9] in inodes:  # LISTEN
                    ports.add(int(fields[1].rsplit(":", 1)[1], 16))
    return ports


def test_a_robot_that_connects_to_a_dashboard_listens_on_no_port():
    before = listening_ports()
    with ZenohRobot("r1", connect=[free_endpoint()], token=TOKEN):
        assert listening_ports() - before == set()


def test_a_robot_told_to_listen_listens_there_only():
    endpoint = free_endpoint()
    before = listening_ports()
    with ZenohRobot("r1", listen=[endpoint], token=TOKEN):
        assert listening_ports() - before == {int(endpoint.rsplit(":", 1)[1])}


@pytest.mark.parametrize("command", [
    ["serve", "--port", "0", "--zenoh", "--zenoh-listen", "nonsense"],
    ["run", "tests/robots/patrol.py", "--no-serve", "--zenoh", "r1", "--zenoh-connect", "nonsense"],
    ["router", "--listen", "nonsense"],
], ids=["serve", "run", "router"])
def test_an_endpoint_zenoh_cannot_use_ends_the_command_with_why(command):
    done = subprocess.run([sys.executable, "-m", "fsmscope", *command], cwd=ROOT, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 1
    assert done.stderr.strip().splitlines()[-1] == (
        "fsmscope %s: cannot open a Zenoh session: Endpoints must be of the form "
        "<protocol>/<address>[?<metadata>][#<config>]: nonsense" % command[0])


def test_a_router_whose_port_is_taken_says_so():
    endpoint = free_endpoint()
    with ZenohRobot("r1", listen=[endpoint], token=TOKEN):
        done = subprocess.run([sys.executable, "-m", "fsmscope", "router", "--listen", endpoint], cwd=ROOT,
                              capture_output=True, text=True, timeout=60)
    assert done.returncode == 1
    assert "Address already in use" in done.stderr
    assert "Traceback" not in done.stderr


def test_a_dashboard_given_no_endpoint_says_it_meets_nobody():
    proc, found = started(["serve", "--port", "0", "--zenoh"], r"following the fleet on Zenoh \((.*)\)")
    stop(proc)
    assert found.group(1) == "no endpoint and no scouting: it meets nobody"


def test_a_dashboard_says_where_it_meets_the_robots():
    endpoint = free_endpoint()
    proc, found = started(["serve", "--port", "0", "--zenoh", "--zenoh-listen", endpoint],
                          r"following the fleet on Zenoh \((.*)\)")
    stop(proc)
    assert found.group(1) == "listen " + endpoint
