"""What the tools that act on a machine (its controls, its debugger) read differently on each runtime:
fsm's own, or the original smach (ros/executive_smach's core, noetic-devel or its ros2 branch;
fsm/observation/original.py tells one). docs/debugging.md, "Machines of the original smach".

fsm's containers call the tools' seams themselves (the debugger's gates, the global hooks run as a
top-level container starts); the original offers only its public methods and the callbacks of each
container, and says a few things its own way: whether it runs, when to stop waiting, how it takes
an initial state.
"""

from __future__ import annotations

from typing import Any, Callable

from ..core import log
from .original import is_original, smach_package
from .structure import is_concurrence


def shutdown_check(machine: Any) -> Callable[[], bool]:
    """The shutdown check the machine's own runtime loops on: fsm's, or the original's (which
    smach_ros sets to ``rospy.is_shutdown``)."""
    package = smach_package(machine) if is_original(machine) else None
    if package is None or not callable(getattr(package, "is_shutdown", None)):
        return log.is_shutdown
    return lambda: bool(package.is_shutdown())


def is_running(container: Any) -> bool:
    """Whether the container runs. fsm's say it (``is_running()``). An original one's ``execute``, as
    the watch fsmscope wraps it in says it (fsm/observation/original_container.py): the ros2 branch's
    StateMachine keeps ``is_running()`` true after a run that raised, the Iterator's flag (both
    branches) too, and the Concurrence has neither. A run that began before the watch (a machine
    attached while it runs) is told by its own flag."""
    watch = getattr(container, "_fsm_watch", None) if is_original(container) else None
    if watch is not None and (watch.entered or watch.ended):
        return watch.entered
    running = getattr(container, "is_running", None)
    if callable(running):
        return bool(running())
    return getattr(container, "_is_running", False) is True


def set_initial_state(container: Any, states: list[str], userdata: dict) -> None:
    """The container starts its next run in ``states`` (none: where it would) with ``userdata`` merged
    into its own, through its ``set_initial_state``. The original's merges its own UserData (its
    ``update`` reads another's ``_data``), so the userdata is given as one; its Concurrence's compares
    the list of states with 0, a TypeError on Python 3 whatever it is given, so there the userdata is
    merged as that method means to (a Concurrence takes no initial states)."""
    if not is_original(container):
        container.set_initial_state(list(states), userdata if userdata else None)
        return
    given = type(container.userdata)()
    for key, value in userdata.items():
        given[key] = value
    if is_concurrence(container):
        container.userdata.update(given)
    else:
        container.set_initial_state(list(states), given)
