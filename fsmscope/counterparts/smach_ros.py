"""smach_ros, ROS-free, for a script run by ``fsmscope run`` (loaded under the name ``smach_ros``).

Its four states are fsm's (fsm.ros: docs/smach_ros.md says where they differ from smach_ros's),
given smach_ros's call shapes: a service or action class as the spec (``SetBool``,
``TwoIntsAction``: the default request or goal is made from it), names resolved as rospy's
(``square`` is ``/square``), and the servers the script starts with the ROS-free ``rospy`` and
``actionlib``. As smach_ros does, importing it makes running machines stop when the node shuts down.

``IntrospectionServer`` keeps smach_ros's call shape and serves nothing itself: ``fsmscope run``
already shows every machine the script runs (on its dashboard, or only in its recording with
``--no-serve``), so a second dashboard would only split them. ``ActionServerWrapper`` and
``IntrospectionClient`` are not covered.
"""

from __future__ import annotations

import copy
from typing import Any

from fsm.ros.condition_state import ConditionState
from fsm.ros.monitor_state import MonitorState as _MonitorState
from fsm.ros.service_state import ServiceState as _ServiceState
from fsm.ros.simple_action_state import SimpleActionState as _SimpleActionState
from fsmscope.counterparts import node
from fsmscope.counterparts.names import not_covered

__all__ = ["IntrospectionServer", "ServiceState", "SimpleActionState", "MonitorState", "ConditionState",
           "set_preempt_handler"]

node.stop_machines_on_shutdown()


class ServiceState(_ServiceState):
    def __init__(self, service_name: str, service_spec: Any, *args: Any, **kwargs: Any) -> None:
        _ServiceState.__init__(self, node.resolve(service_name), getattr(service_spec, "_request_class", service_spec),
                               *args, **kwargs)


class SimpleActionState(_SimpleActionState):
    def __init__(self, action_name: str, action_spec: Any, *args: Any, **kwargs: Any) -> None:
        _SimpleActionState.__init__(self, node.resolve(action_name), lambda: copy.copy(action_spec().action_goal.goal),
                                    *args, **kwargs)


class MonitorState(_MonitorState):
    def __init__(self, topic: str, msg_type: Any, *args: Any, **kwargs: Any) -> None:
        _MonitorState.__init__(self, node.resolve(topic), msg_type, *args, **kwargs)


class IntrospectionServer:
    """smach_ros's call shape, ``(server_name, state, path)``, ``start()``, ``stop()``, ``clear()``;
    the machine is watched by ``fsmscope run`` whether this is started or not."""

    def __init__(self, server_name: str, state: Any, path: str) -> None:
        self.server_name, self.state, self.path = server_name, state, path

    def start(self) -> None:
        pass

    def stop(self) -> None:
        pass

    def clear(self) -> None:
        pass


def set_preempt_handler(sc: Any) -> None:
    """Preempt container ``sc`` when the node shuts down, as smach_ros's does."""
    node.on_shutdown(sc.request_preempt)


def __getattr__(name: str) -> Any:
    raise not_covered("smach_ros", name, __all__)
