"""Where a script run by ``fsmscope run`` gets ``smach`` (and ROS's modules) from: meta path finders
the runner installs for the run and removes after, so a user's own ``import smach`` never sees them.

Which way is settled once, as the run starts, by whether ``smach`` can be imported:

* It cannot (the usual case here): ``smach``, ``smach_ros``, ``rospy``, ``roslib``, ``actionlib``,
  ``actionlib_msgs``, ``std_msgs`` and ``std_srvs`` are fsmscope's counterparts (this folder; names.py
  lists them), always, even where one of them is installed on its own: their states and servers share
  fsm's in-process bus, which a real rospy's services would not be on. The first one imported says so
  in one line.
* It can (the original SMACH): nothing is replaced. Once it is imported, ``on_original`` is given the
  module (the runner watches its machines); if importing it fails, the error says which smach failed
  and that its own error (a missing dependency, a syntax error) is the reason.

Either way, a ROS module that is not installed (and not covered) fails naming itself and saying why.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import importlib.util
import os
import sys
from types import ModuleType
from typing import Any, Callable, Sequence

from . import node
from .names import COVERED, is_ros_package, missing_module

HERE = os.path.dirname(os.path.abspath(__file__))
NOTICE = ("smach is not installed: running the script on fsm, fsmscope's SMACH-compatible runtime "
          "(with ROS-free rospy, smach_ros and actionlib)")


def smach_origin() -> str | None:
    """Where ``import smach`` would find a module, None if nowhere (nothing is imported to tell)."""
    try:
        spec = importlib.util.find_spec("smach")
    except (ImportError, ValueError):  # a smach in sys.modules without a spec is there all the same
        return "an imported module"
    return None if spec is None else str(spec.origin or (list(spec.submodule_search_locations or []) or ["?"])[0])


class ScriptImports(importlib.abc.MetaPathFinder):
    """Installed first on ``sys.meta_path`` for one run (``install``/``uninstall``)."""

    def __init__(self, on_original: Callable[[ModuleType], None], say: Callable[[str], None]) -> None:
        self._on_original = on_original
        self._say = say
        self.on_fsm = False
        self._said = False
        self._missing = _Missing()

    def install(self) -> None:
        original = smach_origin()
        self.on_fsm = original is None
        self._missing.original = original
        sys.meta_path.insert(0, self)
        sys.meta_path.append(self._missing)
        if not self.on_fsm and isinstance(sys.modules.get("smach"), ModuleType):  # imported before the run
            self._on_original(sys.modules["smach"])

    def uninstall(self) -> None:
        """Remove the finders; on fsm, forget the counterparts imported (the next ``import smach`` in
        this process fails again) and end their node."""
        for finder in (self, self._missing):
            if finder in sys.meta_path:
                sys.meta_path.remove(finder)
        if self.on_fsm and self._said:
            for name, module in list(sys.modules.items()):
                if name.partition(".")[0] in COVERED and (getattr(module, "__file__", None) or "").startswith(HERE):
                    del sys.modules[name]
            node.reset()

    def find_spec(self, fullname: str, path: Sequence[str] | None = None,
                  target: ModuleType | None = None) -> importlib.machinery.ModuleSpec | None:
        if self.on_fsm:
            return self._counterpart(fullname)
        if fullname == "smach":
            return self._original(path, target)
        return None

    def _counterpart(self, fullname: str) -> importlib.machinery.ModuleSpec | None:
        where = COVERED.get(fullname)
        if where is None:
            return None
        if not self._said:
            self._said = True
            self._say(NOTICE)
        location = os.path.join(HERE, where)
        if os.path.isdir(location):
            return importlib.util.spec_from_file_location(fullname, os.path.join(location, "__init__.py"),
                                                          submodule_search_locations=[location])
        return importlib.util.spec_from_file_location(fullname, location)

    def _original(self, path: Sequence[str] | None, target: ModuleType | None) -> importlib.machinery.ModuleSpec | None:
        for finder in sys.meta_path:
            if finder is self or not hasattr(finder, "find_spec"):
                continue
            spec = finder.find_spec("smach", path, target)
            if spec is not None:
                if spec.loader is not None and hasattr(spec.loader, "exec_module"):
                    spec.loader = _Original(spec.loader, spec.origin, self._on_original)
                return spec
        return None


class _Original(importlib.abc.Loader):
    """The original smach's own loader, telling what became of the import."""

    def __init__(self, loader: Any, origin: str | None, imported: Callable[[ModuleType], None]) -> None:
        self._loader, self._origin, self._imported = loader, origin, imported

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType | None:
        return self._loader.create_module(spec)

    def exec_module(self, module: ModuleType) -> None:
        try:
            self._loader.exec_module(module)
        except Exception as exc:
            exc.add_note("fsmscope run: smach is installed (%s) but cannot be imported: %s: %s"
                         % (self._origin, type(exc).__name__, exc))
            raise
        self._imported(module)

    def __getattr__(self, name: str) -> Any:  # get_code, get_source, is_package, resource readers
        return getattr(self._loader, name)


class _Missing(importlib.abc.MetaPathFinder):
    """Last on ``sys.meta_path``: a ROS module that nothing found (or a part a counterpart lacks)."""

    original: str | None = None  # where the original smach is, if it is

    def find_spec(self, fullname: str, path: Sequence[str] | None = None,
                  target: ModuleType | None = None) -> None:
        top = fullname.partition(".")[0]
        if top in COVERED or is_ros_package(top):
            raise missing_module(fullname, self.original)
        return None
