"""Events -> the log lines SMACH printed for them, word for word, with a time and the nesting path.

The runtime prints its start, transition, termination and Concurrence lines without
sending them as ``log`` events (the events already say them); this module rebuilds each of
them from the events, so that a replay reads like the live console. ``log`` events are
printed as they were logged.

A line reads ``12:34:56.789 /SM_ROOT/SUB [  INFO ] : State machine transitioning 'A':'done'-->'B'``:
everything from the level prefix on is exactly what SMACH would have printed. Once a log
holds more than one machine, the path is prefixed with the machine's name (``foo_bar:/SM_ROOT``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Iterable, Iterator

from .structure_index import StructureIndex

PREFIXES = {"info": "[  INFO ] : ", "warn": "[  WARN ] : ", "debug": "[ DEBUG ] : ", "error": "[ ERROR ] : "}
SERVICED_PREEMPT = "Concurrence serviced preempt."


@dataclass(frozen=True)
class Line:
    t: float | None
    level: str
    machine: str
    path: str
    msg: str


def _keys(userdata: dict) -> str:
    return str(list(userdata))


class Transcript:
    """Turns events, one at a time, into the SMACH log lines they stand for."""

    def __init__(self, structures: StructureIndex | None = None) -> None:
        self.structures = structures or StructureIndex()
        self._own_structures = structures is None
        self._serviced: set[tuple[str, str]] = set()  # Concurrences that logged a serviced preempt
        self.machines: list[str] = []

    def lines(self, event: dict) -> list[Line]:
        kind = event["kind"]
        if self._own_structures:
            self.structures.apply(event)
        machine = event["machine"]
        if machine not in self.machines:
            self.machines.append(machine)
        msgs = self._messages(kind, event)
        return [Line(event.get("t"), level, machine, event["path"], msg) for level, msg in msgs]

    def _messages(self, kind: str, event: dict) -> list[tuple[str, str]]:
        if kind == "log":
            if event.get("msg") == SERVICED_PREEMPT:
                self._serviced.add((event["machine"], event["path"]))
            return [(event.get("level", "info"), str(event.get("msg", "")))]
        if kind not in ("start", "transition", "terminate"):
            return []
        ctype = self.structures.container_type(event)
        if kind == "start":
            self._serviced.discard((event["machine"], event["path"]))
            userdata = event.get("userdata") or {}
            if ctype == "Concurrence":
                return [("info", "Concurrence starting with userdata: \n\t%s" % _keys(userdata))]
            if ctype == "Iterator":
                return []
            initial = (event.get("initial") or event.get("active") or ["None"])[0]
            return [("info", "State machine starting in initial state '%s' with userdata: \n\t%s"
                     % (initial, _keys(userdata)))]
        if kind == "transition":
            if ctype == "Concurrence":
                return [("info", "Concurrent state '%s' returned outcome '%s' on termination."
                         % (event["from"], event["outcome"]))]
            if ctype == "Iterator":
                return []
            return [("info", "State machine transitioning '%s':'%s'-->'%s'"
                     % (event["from"], event["outcome"], event["to"]))]
        # terminate
        outcome = event.get("outcome")
        if outcome is None:
            return []  # failures are logged by the runtime itself (log events)
        if ctype == "Concurrence":
            if (event["machine"], event["path"]) in self._serviced:
                return []
            return [("info", "Concurrent Outcomes: " + str(event.get("outcomes") or {}))]
        if ctype == "Iterator":
            return []
        last = (event.get("last") or ["None"])[0]
        return [("info", "State machine terminating '%s':'%s':'%s'"
                 % (last, event.get("state_outcome", outcome), outcome))]

    def format(self, line: Line, with_time: bool = True) -> str:
        where = line.path if len(self.machines) < 2 else "%s:%s" % (line.machine, line.path)
        text = "%s %s%s" % (where, PREFIXES.get(line.level, PREFIXES["info"]), line.msg)
        return "%s %s" % (format_time(line.t), text) if with_time else text


_second: list = [None, ""]  # the last whole second formatted, and its text


def format_time(t: float | None) -> str:
    """Local wall-clock time with milliseconds: ``12:34:56.789``."""
    if t is None:
        return "--:--:--.---"
    whole = int(t // 1)
    if _second[0] != whole:
        _second[:] = [whole, time.strftime("%H:%M:%S", time.localtime(whole))]
    return "%s.%03d" % (_second[1], int((t - whole) * 1000))


def messages(events: Iterable[dict]) -> Iterator[Line]:
    """Every SMACH log line the events stand for, in order."""
    transcript = Transcript()
    for event in events:
        yield from transcript.lines(event)


def transcript(events: Iterable[dict], with_time: bool = True) -> Iterator[str]:
    """The formatted lines of a replay."""
    t = Transcript()
    for event in events:
        for line in t.lines(event):
            yield t.format(line, with_time)
