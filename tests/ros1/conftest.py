"""The ros1 layer's master: one real rosmaster per module (tests/ros1_support.py), stopped after it."""

import pytest

from ros1_support import Ros1, skip_without_ros1


@pytest.fixture(scope="module")
def ros(tmp_path_factory):
    """A rosmaster of the module's own on a free port; skips, saying why, without ROS 1 or ../shared/reference."""
    skip_without_ros1()
    master = Ros1(tmp_path_factory.mktemp("ros1")).start()
    yield master
    master.stop()
