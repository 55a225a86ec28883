"""fsmscope: see, debug and control SMACH state machines from a browser, without ROS.

Everything fsmscope installs lives under this package, except the runtime ``fsm`` (the name users
already import, ``import fsm as smach``). What a program that runs machines imports is here::

    from fsmscope import IntrospectionServer, Publisher, attach, Recorder

The names are loaded when first used (PEP 562), so ``import fsmscope.fleet`` or the command line
does not pay for the web server's imports.
"""

from __future__ import annotations

import importlib
from typing import Any

# Public name -> the module that defines it.
_PUBLIC = {
    "IntrospectionServer": "fsmscope.server.introspection_server",
    "Publisher": "fsmscope.server.publisher",
    "attach": "fsm",
    "Recorder": "fsm",
    "add_global_hook": "fsm",
    "remove_global_hook": "fsm",
}

__all__ = sorted(_PUBLIC)


def __getattr__(name: str) -> Any:
    module = _PUBLIC.get(name)
    if module is None:
        raise AttributeError("module 'fsmscope' has no attribute %r" % name)
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_PUBLIC))
