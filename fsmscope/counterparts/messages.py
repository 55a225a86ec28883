"""ROS message, service and action types as plain dataclasses, for the few the counterparts offer.

A type is built the shape genpy generates it: fields as ``__slots__`` in order (positional or
keyword arguments, each with its zero default), ``_type``; a service has ``_request_class`` and
``_response_class``; an action's ``XAction()`` holds ``action_goal.goal``,
``action_result.result`` and ``action_feedback.feedback`` (smach_ros reads its default goal from
there). Not kept: headers, goal ids, serialisation, md5 sums. Dataclasses are what
fsm's events encode field by field, so a message in userdata shows as its fields.
"""

from __future__ import annotations

import copy
import dataclasses
from typing import Any


def message(ros_type: str, **fields: Any) -> type:
    """A message class: ``message("std_msgs/Bool", data=False)``; a field's default is copied for
    each message (a nested message is made fresh)."""
    package, name = ros_type.split("/")
    spec = [(field, type(default), dataclasses.field(default_factory=lambda d=default: copy.deepcopy(d)))
            for field, default in fields.items()]
    cls = dataclasses.make_dataclass(name, spec, slots=True)
    cls.__module__, cls._type = package + ".msg", ros_type
    return cls


class _Service:
    _type: str
    _request_class: type
    _response_class: type


def service(ros_type: str, request: dict[str, Any], response: dict[str, Any]) -> tuple[type, type, type]:
    """The service class, its request and its response: ``service("std_srvs/SetBool", {"data":
    False}, {"success": False, "message": ""})``."""
    package, name = ros_type.split("/")
    req = message(ros_type + "Request", **request)
    resp = message(ros_type + "Response", **response)
    req.__module__ = resp.__module__ = package + ".srv"
    srv = type(name, (_Service,), {"_type": ros_type, "_request_class": req, "_response_class": resp,
                                    "__module__": package + ".srv"})
    return srv, req, resp


def action(ros_type: str, goal: dict[str, Any], result: dict[str, Any],
           feedback: dict[str, Any]) -> dict[str, type]:
    """The seven classes of an action, by name: ``XAction``, ``XActionGoal``, ``XActionResult``,
    ``XActionFeedback``, ``XGoal``, ``XResult``, ``XFeedback``."""
    made = {"Goal": message(ros_type + "Goal", **goal), "Result": message(ros_type + "Result", **result),
            "Feedback": message(ros_type + "Feedback", **feedback)}
    for part in ("Goal", "Result", "Feedback"):
        made["Action" + part] = message(ros_type + "Action" + part, **{part.lower(): made[part]()})
    made["Action"] = message(ros_type + "Action", action_goal=made["ActionGoal"](),
                             action_result=made["ActionResult"](), action_feedback=made["ActionFeedback"]())
    name = ros_type.split("/")[1]
    return {name + part: cls for part, cls in made.items()}


def coerce(cls: type, value: Any) -> Any:
    """``value`` as an instance of ``cls``, as rospy converts what a service handler returns: the
    instance itself, a dict of fields, a tuple or list of them in order, or a single field's value."""
    if isinstance(value, cls):
        return value
    if isinstance(value, dict):
        return cls(**value)
    if isinstance(value, (tuple, list)):
        return cls(*value)
    if value is None:
        raise TypeError("the service handler returned None, not a %s" % cls.__name__)
    return cls(value)
