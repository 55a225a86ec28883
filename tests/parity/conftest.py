"""The original SMACH core and fsm in one process, so that one script runs on both and what a user
sees of each (outcomes, log lines, userdata, callbacks, exceptions) can be compared.

The original (noetic-devel, pure Python) is read from ``../shared/reference`` beside the project
root (CI puts a copy of shared/ there too). It is loaded under its own name, ``smach``, for this
folder's modules only: whatever ``smach`` modules were there before are put back afterwards, and
both implementations' loggers and shutdown checks are restored after every test.

One module per section of ../shared/smach/BEHAVIORS.md (A-G). Not here: H (the introspection
protocol) and I (smach_ros's states) need ROS. A fact that cannot run on both is named, with why, in
its module's docstring; a documented fix of fsm (README's table, BEHAVIORS.md's [bug]) is asserted
as the difference it is.
"""

import importlib.util
import sys
from pathlib import Path

import fsm
import fsm.core.log
import pytest

pytest.register_assert_rewrite("parity_support")
from parity_support import Parity  # noqa: E402

REFERENCE = Path(__file__).resolve().parents[2].parent / "shared/reference/executive_smach"
ORIGINAL_SRC = REFERENCE / "noetic/smach/src"
CORES = {"noetic": ORIGINAL_SRC, "ros2": REFERENCE / "ros2/smach"}  # where each branch's ``smach`` package is


@pytest.fixture(scope="module")
def original():
    """The original ``smach`` package (noetic-devel), loaded from its source for this module's tests."""
    yield from _loaded(ORIGINAL_SRC)


@pytest.fixture(scope="module", params=sorted(CORES))
def either_core(request):
    """The original ``smach`` package of each branch in turn (noetic-devel, then ros2), for this module's tests."""
    yield from _loaded(CORES[request.param])


def _loaded(src: Path):
    init = src / "smach" / "__init__.py"
    if not init.exists():
        pytest.skip("the original SMACH core is not at %s (a copy of shared/ beside the project root)" % src)
    before = {name: module for name, module in sys.modules.items() if name == "smach" or name.startswith("smach.")}
    for name in before:
        del sys.modules[name]
    spec = importlib.util.spec_from_file_location("smach", init, submodule_search_locations=[str(init.parent)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["smach"] = module
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        for name in [n for n in sys.modules if n == "smach" or n.startswith("smach.")]:
            del sys.modules[name]
        sys.modules.update(before)


@pytest.fixture
def core(either_core):
    """``either_core`` with its log functions and shutdown check put back after the test (watching a
    machine wraps them)."""
    saved = {name: getattr(either_core, name) for name in ("loginfo", "logwarn", "logdebug", "logerr", "is_shutdown")}
    yield either_core
    for name, value in saved.items():
        setattr(either_core, name, value)
    either_core.Container._construction_stack.clear()


@pytest.fixture
def parity(original):
    """A ``Parity`` on the original and fsm; their loggers and shutdown checks restored afterwards."""
    defaults = {name: getattr(original, name) for name in ("loginfo", "logwarn", "logdebug", "logerr", "is_shutdown")}
    printers = dict(fsm.core.log._printers)
    shutdown_check = fsm.core.log._shutdown_check
    yield Parity(original)
    for name, value in defaults.items():
        setattr(original, name, value)
    fsm.core.log._printers.clear()
    fsm.core.log._printers.update(printers)
    fsm.core.log._shutdown_check = shutdown_check
    left_open = list(original.Container._construction_stack)
    original.Container._construction_stack.clear()
    assert not left_open, "a scenario left containers of the original open: %r" % left_open
