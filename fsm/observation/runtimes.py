"""Which SMACH runs a machine: fsm's own runtime, or the original smach (ros/executive_smach's
core, noetic-devel or its ros2 branch, imported as ``smach``), and the few facts the tools that act
on a machine must read differently on each (docs/debugging.md, "Machines of the original smach").

fsm's containers call the tools' seams themselves (the reporter, the debugger's gates, the global
hooks run as a top-level container starts); the original offers only its public methods and the
start, transition and termination callbacks of each container, as smach_ros used them. What it
says differently is answered here, once.
"""

from __future__ import annotations

import sys
from types import ModuleType
from typing import Any, Callable

from ..core import log
from ..core.state import State


def is_original(state: Any) -> bool:
    """A state of the original smach (or of a user's class derived from it): anything not fsm's."""
    return not isinstance(state, State)


def original_package(state: Any) -> ModuleType | None:
    """The original ``smach`` package the state's class comes from (each of its modules imports it
    as ``smach``); None for a class of neither."""
    for cls in type(state).__mro__:
        if cls.__module__.startswith("smach."):
            package = getattr(sys.modules.get(cls.__module__), "smach", None)
            if isinstance(package, ModuleType):
                return package
    return None


def shutdown_check(machine: Any) -> Callable[[], bool]:
    """The shutdown check the machine's own runtime loops on: fsm's, or the original's (which
    smach_ros sets to ``rospy.is_shutdown``)."""
    package = original_package(machine) if is_original(machine) else None
    if package is None:
        return log.is_shutdown
    return lambda: bool(package.is_shutdown())


def is_running(container: Any) -> bool:
    """Whether the container says it runs: fsm's containers and the original's StateMachine have
    ``is_running()``, the original's Iterator only its flag; its Concurrence has neither, and runs
    while a thread of its children does."""
    running = getattr(container, "is_running", None)
    if callable(running):
        return bool(running())
    if is_original_concurrence(container):
        return any(thread.is_alive() for thread in list(getattr(container, "_threads", {}).values()))
    return getattr(container, "_is_running", False) is True


def set_original_initial_state(container: Any, states: list[str], userdata: dict) -> None:
    """``set_initial_state`` of a container of the original. It merges the original's own UserData
    (its ``update`` reads another's ``_data``), so ``userdata`` is given as one. Its Concurrence's
    compares the list of states with 0, a TypeError on Python 3 whatever it is given: there the
    userdata is merged as that method means to (a Concurrence takes no initial states)."""
    given = type(container.userdata)()
    for key, value in userdata.items():
        given[key] = value
    if is_original_concurrence(container):
        container.userdata.update(given)
    else:
        container.set_initial_state(list(states), given)


def is_original_concurrence(container: Any) -> bool:
    """The original's Concurrence, or a user's class derived from it."""
    return any(cls.__name__ == "Concurrence" and cls.__module__ == "smach.concurrence"
               for cls in type(container).__mro__)
