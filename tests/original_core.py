"""The original SMACH core (ros/executive_smach, pure Python: its noetic-devel branch's or its ros2
branch's), loaded under its own name, ``smach``, for one test module: whatever ``smach`` modules were
there before are put back afterwards. Read from ``../shared/reference`` beside the project root (CI
puts a copy of shared/ there too); a module that needs it skips, saying why, where it is absent."""

import contextlib
import importlib.util
import sys
from pathlib import Path
from types import ModuleType
from typing import Iterator

import pytest

REFERENCE = Path(__file__).resolve().parents[1].parent / "shared/reference/executive_smach"
CORES = {"noetic": REFERENCE / "noetic/smach/src", "ros2": REFERENCE / "ros2/smach"}  # each branch's ``smach``


@contextlib.contextmanager
def loaded_original(branch: str = "noetic") -> Iterator[ModuleType]:
    """The original ``smach`` package of ``branch``, loaded from its source until the block ends."""
    init = CORES[branch] / "smach" / "__init__.py"
    if not init.exists():
        pytest.skip("the original SMACH core is not at %s (a copy of shared/ beside the project root)" % init.parent)
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
