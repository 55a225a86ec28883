"""The demo's tests share one real ``fsmscope demo`` process: it starts with the first test of this
folder that needs it and stops after the folder's last test (a package-scoped fixture), so it never
runs, and costs CPU, behind the tests of the other layers."""

import pytest
from demo_support import SharedDemo


@pytest.fixture(scope="package")
def shared_demo(tmp_path_factory):
    """One real ``fsmscope demo`` at real time (episodes of about 6 s, a pause of 1 s between them):
    ``process()`` starts it, ``let_go()`` leaves it as it was found."""
    shared = SharedDemo(tmp_path_factory.mktemp("shared-demo"))
    yield shared
    assert shared.stop() in (None, 130)  # interrupted, cleanly


@pytest.fixture
def demo(shared_demo):
    """The shared demo's process, let go after the test (no breakpoint, no hold, no lease, running)."""
    yield shared_demo.process()
    shared_demo.let_go()
