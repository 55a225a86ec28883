"""SMACH's log lines, as a node publishes them on ``/rosout`` (smach_ros points SMACH's loggers at
rospy's, or rclpy's), read back: which line says what of the run.

The texts are those of the original core (smach/src/smach/state_machine.py, concurrence.py,
iterator.py; /work/shared/smach/BEHAVIORS.md A.3-A.7): a line names labels and outcomes, never a
container's path, so the follower finds the container by its labels. Nothing is evaluated: the
outcomes of "Concurrent Outcomes: {...}" are read by a pattern, not by Python.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

# rosgraph_msgs/Log (ROS 1) and rcl_interfaces/msg/Log (ROS 2) levels, as the events' words.
LEVELS = {1: "debug", 2: "info", 4: "warn", 8: "error", 16: "error",
          10: "debug", 20: "info", 30: "warn", 40: "error", 50: "error"}

_Q = r"'((?:[^'\\]|\\.)*)'"  # a quoted label or outcome, as Python's %s of a str between quotes puts it
_TOLD = {
    "start": re.compile(r"State machine starting in initial state %s with userdata: \n\t(\[.*\])\Z" % _Q, re.S),
    "transition": re.compile(r"State machine transitioning %s:%s-->%s\Z" % (_Q, _Q, _Q)),
    "terminate": re.compile(r"State machine terminating %s:%s:%s\Z" % (_Q, _Q, _Q)),
    "concurrence_start": re.compile(r"Concurrence starting with userdata: \n\t(\[.*\])\Z", re.S),
    "returned": re.compile(r"Concurrent state %s returned outcome %s on termination\.\Z" % (_Q, _Q)),
    "outcomes": re.compile(r"Concurrent Outcomes: \{(.*)\}\Z", re.S),
    "iterating": re.compile(r"Iterating (.*) of (.*)\Z", re.S),
    "serviced": re.compile(r"Concurrence serviced preempt\.\Z"),
}
# SMACH's other lines (said as ``log`` events of the machine, as fsm's watcher sends them).
_OTHER = ("Preempt requested on state machine before executing the next state.", "Last state '",
          "State '", "Could not execute ", "Container consistency check failed.", "Attempting to copy ",
          "Attempting to get state '", "Attempting to set initial state", "Attempting to set state '",
          "Outcome callback returned ", "Userdata key '", "Reading from SMACH userdata key '",
          "Writing to SMACH userdata key '", "InvalidStateError: ", "InvalidTransitionError: ",
          "InvalidUserCodeError: ", "Both loop_outcomes and break_outcomes ", "Error raised during SMACH container")
_ITEM = re.compile(r"%s: (%s|None)" % (_Q, _Q))


@dataclass(frozen=True)
class Said:
    """One SMACH line: ``kind`` (a key of _TOLD, or "other"), its values (labels, outcomes, ...)."""

    kind: str
    values: tuple
    level: str
    text: str


def read(text: str, level: int) -> Said | None:
    """What a line of /rosout says of a SMACH run; None for a line that is not SMACH's."""
    word = LEVELS.get(level, "info")
    for kind, pattern in _TOLD.items():
        found = pattern.match(text)
        if found:
            values = found.groups()
            if kind in ("start", "concurrence_start"):
                values = tuple(map(_unquoted, values[:-1])) + (keys(values[-1]),)
            elif kind == "outcomes":
                values = (outcomes(values[0]),)
            elif kind != "iterating":
                values = tuple(map(_unquoted, values))
            return Said(kind, values, word, text)
    if text.startswith(_OTHER):
        return Said("other", (), word, text)
    return None


def is_smach(text: str) -> bool:
    """Whether a line of /rosout is one of SMACH's (the bag reader keeps these only)."""
    return read(text, 2) is not None


def keys(listed: str) -> list[str]:
    """The keys of ``str(list(userdata.keys()))``: ``['a', 'b']``."""
    return [_unquoted(k) for k in re.findall(_Q, listed)]


def outcomes(listed: str) -> dict[str, str | None] | None:
    """``{'A': 'done', 'B': None}`` read from the inside of the braces; None if it is not that form."""
    found = {_unquoted(m.group(1)): None if m.group(2) == "None" else _unquoted(m.group(3))
             for m in _ITEM.finditer(listed)}
    rebuilt = ", ".join("%r: %r" % item for item in found.items())
    return found if rebuilt == listed or not listed else None


def _unquoted(text: str) -> str:
    return re.sub(r"\\(.)", r"\1", text) if "\\" in text else text
