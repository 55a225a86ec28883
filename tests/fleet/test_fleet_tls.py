"""The fleet over TLS (``tls/`` endpoints, docs/fleet.md): a Zenoh configuration file
(``--zenoh-config``) gives the dashboard its certificate and the robot the authority it trusts.
A robot that trusts the certificate's authority reaches the dashboard; one that does not never
does. With mutual TLS the dashboard asks each robot for a certificate of its authority too: a robot
without one never reaches it. A configuration file Zenoh cannot read is refused with why."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import fsm
import pytest
from fleet_support import TOKEN, ROOT, free_endpoint, slow_loop

from fsmscope.fleet.robot import ZenohRobot
from fsmscope.fleet.watcher import FleetWatcher
from fsmscope.server.testing.polling import wait_for


def openssl(*args: str, cwd: Path) -> None:
    subprocess.run(["openssl", *args], cwd=cwd, check=True, capture_output=True)


def authority(directory: Path, name: str) -> Path:
    """A self-signed certificate authority: its certificate (``name``.pem; its key beside it)."""
    openssl("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj", "/CN=%s" % name,
            "-keyout", name + ".key", "-out", name + ".pem", cwd=directory)
    return directory / (name + ".pem")


@pytest.fixture(scope="module")
def certificates(tmp_path_factory) -> dict[str, Path]:
    """The dashboard's certificate for localhost, signed by authority "ca"; a second authority, "other"."""
    directory = tmp_path_factory.mktemp("tls")
    ca, other = authority(directory, "ca"), authority(directory, "other")
    openssl("req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=localhost", "-keyout", "dashboard.key",
            "-out", "dashboard.csr", cwd=directory)
    (directory / "names.cnf").write_text("subjectAltName=DNS:localhost,IP:127.0.0.1\n")
    openssl("x509", "-req", "-in", "dashboard.csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial",
            "-days", "2", "-extfile", "names.cnf", "-out", "dashboard.pem", cwd=directory)
    # The robot's own certificate, for mutual TLS: signed by "ca", for a client.
    openssl("req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=r1", "-keyout", "robot.key", "-out", "robot.csr",
            cwd=directory)
    (directory / "client.cnf").write_text("extendedKeyUsage=clientAuth\n")
    openssl("x509", "-req", "-in", "robot.csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial",
            "-days", "2", "-extfile", "client.cnf", "-out", "robot.pem", cwd=directory)
    return {"ca": ca, "other": other, "certificate": directory / "dashboard.pem", "key": directory / "dashboard.key",
            "robot_certificate": directory / "robot.pem", "robot_key": directory / "robot.key",
            "directory": directory}


def config_file(certificates: dict[str, Path], name: str, tls: dict[str, str]) -> str:
    path = certificates["directory"] / (name + ".json5")
    path.write_text(json.dumps({"transport": {"link": {"tls": tls}}}))
    return str(path)


def tls_endpoint() -> str:
    return "tls/localhost:" + free_endpoint().rsplit(":", 1)[1]


def listening(certificates, mutual: bool):
    """A watcher listening on a tls/ endpoint with its certificate (``mutual``: asking the robots for
    theirs, of its authority); yields (endpoint, what it delivered)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    endpoint = tls_endpoint()
    delivered: list[dict] = []
    tls = {"listen_certificate": str(certificates["certificate"]), "listen_private_key": str(certificates["key"])}
    if mutual:
        tls.update(enable_mtls=True, root_ca_certificate=str(certificates["ca"]))
    watcher = FleetWatcher(delivered.extend, lambda name, up: None, listen=[endpoint],
                           config_file=config_file(certificates, "dashboard", tls), tokens={None: TOKEN})
    try:
        yield endpoint, delivered
    finally:
        watcher.close()


@pytest.fixture
def dashboard(certificates):
    yield from listening(certificates, mutual=False)


@pytest.fixture
def mutual_dashboard(certificates):
    yield from listening(certificates, mutual=True)


def run_published(robot: ZenohRobot) -> list[dict]:
    own: list[dict] = []
    sm = slow_loop(20)
    fsm.attach(sm, robot, name="loop")
    fsm.attach(sm, own.append)
    sm.execute()
    robot.flush()
    return own


def test_a_robot_that_trusts_the_dashboards_authority_reaches_it_over_tls(certificates, dashboard):
    endpoint, delivered = dashboard
    trusting = config_file(certificates, "robot", {"root_ca_certificate": str(certificates["ca"])})
    robot = ZenohRobot("r1", connect=[endpoint], config_file=trusting, token=TOKEN)
    try:
        own = run_published(robot)
        wait_for(lambda: delivered and delivered[-1]["seq"] == own[-1]["seq"], 10, what="the last event over TLS")
        assert [e["seq"] for e in delivered if e["kind"] != "snapshot"][-len(own):] == [e["seq"] for e in own]
    finally:
        robot.close()


def assert_never_delivered(robot: ZenohRobot, delivered: list[dict]) -> None:
    try:
        run_published(robot)
        time.sleep(3.0)  # a robot that connected would have delivered within a second (tests above)
        assert delivered == []
    finally:
        robot.close()


def test_a_robot_that_trusts_another_authority_never_reaches_the_dashboard(certificates, dashboard):
    endpoint, delivered = dashboard
    distrusting = config_file(certificates, "stranger", {"root_ca_certificate": str(certificates["other"])})
    assert_never_delivered(ZenohRobot("r1", connect=[endpoint], config_file=distrusting, token=TOKEN), delivered)


def test_with_mutual_tls_a_robot_with_a_certificate_of_the_authority_reaches_the_dashboard(certificates,
                                                                                           mutual_dashboard):
    endpoint, delivered = mutual_dashboard
    identified = config_file(certificates, "robot", {"root_ca_certificate": str(certificates["ca"]),
                                                     "enable_mtls": True,
                                                     "connect_certificate": str(certificates["robot_certificate"]),
                                                     "connect_private_key": str(certificates["robot_key"])})
    robot = ZenohRobot("r1", connect=[endpoint], config_file=identified, token=TOKEN)
    try:
        own = run_published(robot)
        wait_for(lambda: delivered and delivered[-1]["seq"] == own[-1]["seq"], 10, what="the last event over mTLS")
    finally:
        robot.close()


def test_with_mutual_tls_a_robot_without_a_certificate_never_reaches_the_dashboard(certificates, mutual_dashboard):
    endpoint, delivered = mutual_dashboard
    anonymous = config_file(certificates, "anonymous", {"root_ca_certificate": str(certificates["ca"])})
    assert_never_delivered(ZenohRobot("r1", connect=[endpoint], config_file=anonymous, token=TOKEN), delivered)


def test_a_zenoh_configuration_file_that_cannot_be_read_is_refused_with_why(tmp_path):
    broken = tmp_path / "broken.json5"
    broken.write_text("{ transport: ")
    done = subprocess.run([sys.executable, "-m", "fsmscope", "serve", "--port", "0", "--zenoh",
                           "--zenoh-config", str(broken)], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert "argument --zenoh-config: cannot use %s as a Zenoh configuration" % broken in done.stderr
