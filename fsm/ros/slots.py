"""Message fields by name, for slots on objects with attributes and on dicts alike.

ROS messages expose fields as ``__slots__`` attributes; here a message, request, goal or
result is any Python object, and plain dicts are common, so both access styles are served.
"""

from typing import Any, Iterable


def get_slot(msg: Any, name: str) -> Any:
    return msg[name] if isinstance(msg, dict) else getattr(msg, name)


def set_slot(msg: Any, name: str, value: Any) -> None:
    if isinstance(msg, dict):
        msg[name] = value
    else:
        setattr(msg, name, value)


def store(ud: Any, msg: Any, key: str | None, slots: Iterable[str]) -> None:
    """Write a response or result to userdata: whole under ``key``, and each slot under its name.

    Slots of a None message are skipped (smach_ros's action state does so; its service state raised).
    """
    if key is not None:
        ud[key] = msg
    if msg is not None:
        for name in slots:
            ud[name] = get_slot(msg, name)
