"""The fleet overview in real Chromium, over three real robot processes (``fsmscope run
robots/patrol.py --zenoh rN``) and one real dashboard (``fsmscope serve --zenoh``), on Zenoh
sessions on the loopback with explicit tcp endpoints and no multicast: every machine has a tile,
a killed robot's tile shows gone and comes back when it is restarted, the failed one is found by
the filter, and a tile opens the machine's dashboard, from which it is preempted on its robot."""

from __future__ import annotations

import pytest
from fleet_support import Dashboard, Robot
from fsmscope.server.testing.browser import PAGE_WAIT_MS


TOKEN = "fleet-token"
LIVELINESS_S = 10  # a killed robot's link is dropped after fleet.config.LEASE_MS (3 s): well within this


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    """(the dashboard, robots r1..r3 by name); r2's patrol fails on its third scan."""
    logs = tmp_path_factory.mktemp("robots")
    dash = Dashboard("--zenoh-token", TOKEN)
    robots = {name: Robot(name, dash.endpoint, TOKEN, logs / (name + ".jsonl"), fail=name == "r2")
              for name in ("r1", "r2", "r3")}
    try:
        yield dash, robots
    finally:
        for robot in robots.values():
            robot.stop()
        dash.stop()


@pytest.fixture
def overview(browser, fleet):
    dash, robots = fleet
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    page.set_default_timeout(PAGE_WAIT_MS)
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto("%s/fleet?token=%s" % (dash.base, dash.token))
    yield page
    page.close()
    assert errors == []


def tile(name: str) -> str:
    return '.tile[data-name="%s"]' % name


def test_every_robot_machine_has_a_tile(overview):
    for robot in ("r1", "r2", "r3"):
        overview.wait_for_selector(tile(robot + ":patrol"))
    assert overview.text_content(tile("r1:patrol") + " .tile-robot") == "r1"
    assert overview.text_content(tile("r1:patrol") + " .tile-machine") == "patrol"
    overview.wait_for_selector(tile("r1:patrol") + ".running")
    rate = "() => parseFloat(document.querySelector('.tile[data-name=\"r1:patrol\"] .tile-rate').textContent) > 0"
    overview.wait_for_function(rate)
    assert overview.text_content(tile("r1:patrol") + " .tile-active") in ("MOVE", "SCAN")


def test_only_failed_shows_the_failed_robot_alone(overview):
    overview.wait_for_selector(tile("r2:patrol") + ".failed")
    assert "RuntimeError" in overview.text_content(tile("r2:patrol") + " .pill")
    overview.select_option("#state-filter", "failed")
    overview.wait_for_function("() => document.querySelectorAll('.tile').length === 1")
    assert overview.get_attribute(".tile", "data-name") == "r2:patrol"
    assert "state=failed" in overview.url  # a copied address shows the same view


def test_a_killed_robot_shows_gone_and_is_back_when_restarted(overview, fleet):
    dash, robots = fleet
    overview.wait_for_selector(tile("r3:patrol") + ".running")
    robots["r3"].kill()
    overview.wait_for_selector(tile("r3:patrol") + ".gone", timeout=LIVELINESS_S * 1000)
    robots["r3"].start()
    overview.wait_for_selector(tile("r3:patrol") + ".running", timeout=LIVELINESS_S * 1000)


def test_a_tile_opens_the_machines_dashboard_which_preempts_it_on_its_robot(overview, fleet):
    dash, robots = fleet
    overview.click(tile("r1:patrol"))
    overview.wait_for_selector("#run-state.running")
    assert overview.evaluate("window.fsmscope.name") == "r1:patrol"
    overview.wait_for_selector("#preempt-btn:not([disabled])")
    overview.click("#preempt-btn")
    overview.wait_for_selector("#preempt-dialog[open]")
    overview.click("#preempt-confirm")
    overview.wait_for_selector("#run-state:has-text('finished: preempted')")
    assert robots["r1"].ended() == 0
    [control] = [e for e in robots["r1"].events() if e["kind"] == "control"]
    assert (control["action"], control["result"]) == ("preempt", "accepted")
    assert "Preempt accepted (event %d)" % control["seq"] in overview.text_content("#notice")
