"""The original SMACH core (ros/executive_smach's noetic-devel, pure Python), loaded under its own
name, ``smach``, for one test module: whatever ``smach`` modules were there before are put back
afterwards. Read from ``../shared/reference`` beside the project root (CI puts a copy of shared/
there too); a module that needs it skips, saying why, where it is absent."""

import contextlib
import importlib.util
import sys
from pathlib import Path
from types import ModuleType
from typing import Iterator

import pytest

ORIGINAL_SRC = Path(__file__).resolve().parents[1].parent / "shared/reference/executive_smach/noetic/smach/src"


@contextlib.contextmanager
def loaded_original() -> Iterator[ModuleType]:
    """The original ``smach`` package, loaded from its source until the block ends."""
    init = ORIGINAL_SRC / "smach" / "__init__.py"
    if not init.exists():
        pytest.skip("the original SMACH core is not at %s (a copy of shared/ beside the project root)" % ORIGINAL_SRC)
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
