"""The one ROS-free node of a script run by ``fsmscope run``: its name, how ROS names resolve
against it, and its shutdown (``rospy.signal_shutdown``, ``rospy.on_shutdown``).

The counterpart modules (``rospy``, ``actionlib``, ``smach_ros``) are loaded under ROS's names,
so what they share lives here, under fsmscope's own name. ``reset`` ends the node when the run
ends: what the script left open (services, action servers) is shut down, and fsm's shutdown
check is given back.
"""

from __future__ import annotations

import threading
import traceback
from typing import Any, Callable

import fsm
from fsm.core import log

_lock = threading.Lock()
_name = "/unnamed"
_shutdown = threading.Event()
_hooks: list[Callable[..., Any]] = []
_given_back: Callable[[], bool] | None = None  # fsm's shutdown check before smach_ros took it


def init(name: str) -> None:
    global _name
    _name = "/" + name.strip("/")


def name() -> str:
    return _name


def resolve(ros_name: str) -> str:
    """A graph name as rospy resolves it in the root namespace: ``x`` and ``/x`` are ``/x``,
    ``~x`` is ``/<node>/x``."""
    if ros_name.startswith("~"):
        return _name + "/" + ros_name[1:].lstrip("/")
    return ros_name if ros_name.startswith("/") else "/" + ros_name


def is_shutdown() -> bool:
    return _shutdown.is_set()


def wait_for_shutdown(timeout: float | None) -> bool:
    """Sleep until shutdown or ``timeout`` seconds; True if shut down."""
    return _shutdown.wait(timeout)


def on_shutdown(hook: Callable[..., Any]) -> None:
    with _lock:
        _hooks.append(hook)


def signal_shutdown(reason: str) -> None:
    """Shut the node down once: ``is_shutdown()`` turns True and each hook runs, with no argument
    as rospy's ``on_shutdown`` hooks (a raising one is logged, the others still run)."""
    with _lock:
        if _shutdown.is_set():
            return
        _shutdown.set()
        hooks = list(_hooks)
        _hooks.clear()
    for hook in hooks:
        try:
            hook()
        except Exception:
            log.logerr("signal_shutdown hook error: " + traceback.format_exc())


def stop_machines_on_shutdown() -> None:
    """Make fsm's containers stop when the node shuts down, as smach_ros does with smach's."""
    global _given_back
    if _given_back is None:
        _given_back = log._shutdown_check
        fsm.set_shutdown_check(is_shutdown)


def reset() -> None:
    """End the node (the run is over) and make a fresh one for the next run in this process."""
    global _given_back
    signal_shutdown("the script's run ended")
    if _given_back is not None:
        fsm.set_shutdown_check(_given_back)
        _given_back = None
    init("unnamed")
    _shutdown.clear()
