"""actionlib, ROS-free: SimpleActionServer and SimpleActionClient with actionlib's call shapes,
over fsm's in-process actionlib (fsm.ros.actionlib) on the default bus; ``actionlib.msg``.

Names resolve as rospy's do (``count`` is ``/count``). A server's terminal status given no result
gets the action's empty result, as actionlib's does. An action server left running ends with the
node (``rospy.signal_shutdown``, or the end of the run).
"""

from __future__ import annotations

from typing import Any, Callable

from fsm.ros import actionlib as _fsm
from fsm.ros.actionlib import GoalStatus
from fsm.ros.preemptible import to_seconds
from fsmscope.counterparts import node
from fsmscope.counterparts.names import not_covered

__all__ = ["GoalStatus", "SimpleActionServer", "SimpleActionClient"]


def _forever_if_zero(timeout: Any) -> float | None:
    """actionlib's ``rospy.Duration()`` (zero), its default, means no timeout."""
    seconds = to_seconds(timeout)
    return None if not seconds else seconds


class SimpleActionServer(_fsm.SimpleActionServer):
    def __init__(self, name: str, ActionSpec: type, execute_cb: Callable[[Any], Any] | None = None,
                 auto_start: bool = True) -> None:
        if execute_cb is None:
            raise NotImplementedError("fsmscope's ROS-free actionlib runs an execute_cb; goal and preempt "
                                      "callbacks without one are not covered")
        self._empty_result = lambda: ActionSpec().action_result.result
        _fsm.SimpleActionServer.__init__(self, node.resolve(name), execute_cb, auto_start=auto_start)
        node.on_shutdown(self.shutdown)

    def set_succeeded(self, result: Any = None, text: str = "") -> None:
        _fsm.SimpleActionServer.set_succeeded(self, self._empty_result() if result is None else result, text)

    def set_preempted(self, result: Any = None, text: str = "") -> None:
        _fsm.SimpleActionServer.set_preempted(self, self._empty_result() if result is None else result, text)

    def set_aborted(self, result: Any = None, text: str = "") -> None:
        _fsm.SimpleActionServer.set_aborted(self, self._empty_result() if result is None else result, text)


class SimpleActionClient(_fsm.SimpleActionClient):
    def __init__(self, ns: str, ActionSpec: type) -> None:
        _fsm.SimpleActionClient.__init__(self, node.resolve(ns))

    def wait_for_server(self, timeout: Any = None) -> bool:
        return _fsm.SimpleActionClient.wait_for_server(self, _forever_if_zero(timeout))

    def wait_for_result(self, timeout: Any = None) -> bool:
        return _fsm.SimpleActionClient.wait_for_result(self, _forever_if_zero(timeout))


def __getattr__(name: str) -> Any:
    raise not_covered("actionlib", name, __all__)
