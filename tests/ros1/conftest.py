"""The ros1 layer's master: one real rosmaster per module (tests/ros1_support.py), stopped after it; for
the modules that follow robots live, two robots nobody may change and a ``fsmscope ros1`` following them."""

import pytest

from ros1_support import Ros1, live_viewer, skip_without_ros1, two_robots


@pytest.fixture(scope="module")
def ros(tmp_path_factory):
    """A rosmaster of the module's own on a free port; skips, saying why, without ROS 1 or ../shared/reference."""
    skip_without_ros1()
    master = Ros1(tmp_path_factory.mktemp("ros1")).start()
    yield master
    master.stop()


@pytest.fixture(scope="module")
def robots(ros):
    """The module's robots r1 and r2 (``two_robots``), running before the viewer joins."""
    with two_robots(ros) as started_robots:
        yield started_robots


@pytest.fixture(scope="module")
def live(ros, robots):
    """The module's ``fsmscope ros1`` following ``robots`` (``live_viewer``)."""
    with live_viewer(ros) as viewer:
        yield viewer
