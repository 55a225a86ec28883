"""Events -> the log lines SMACH printed for them, word for word, with a time and the nesting path.

The runtime prints its start, transition, termination and Concurrence lines without
sending them as ``log`` events (the events already say them); this module rebuilds each of
them from the events, so that a replay reads like the live console. ``log`` events are
printed as they were logged.

A line reads ``12:34:56.789 /SM_ROOT/SUB [  INFO ] : State machine transitioning 'A':'done'-->'B'``:
everything from the level prefix on is exactly what SMACH would have printed. Once a log
holds more than one machine, the path is prefixed with the machine's name (``foo_bar:/SM_ROOT``).

SMACH had no operator controls or debugger: a ``control`` event (preempt, initial-state, start,
publish from the dashboard) and a ``debug`` event (pause, hold, step, forced outcome, breakpoints)
read word for word as the browser's transcript (fsmscope/static/transcript.js) writes them.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from decimal import Decimal
from typing import Any, Iterable, Iterator

from .structure_index import StructureIndex

PREFIXES = {"info": "[  INFO ] : ", "warn": "[  WARN ] : ", "debug": "[ DEBUG ] : ", "error": "[ ERROR ] : "}
SERVICED_PREEMPT = "Concurrence serviced preempt."
CONTROL_PARAMS_LIMIT = 120  # characters of a control's params shown, as in the browser


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
        if kind == "control":
            return [control_message(event)]
        if kind == "debug":
            return [debug_message(event)]
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
            if outcome == "preempted" and (event["machine"], event["path"]) in self._serviced:
                return []  # without a 'preempted' outcome it goes on to its outcome map, and prints it
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


def control_message(event: dict) -> tuple[str, str]:
    """(level, text) of a control event, as fsmscope/static/transcript.js words it: the operator's action
    reads the same in a headless replay as in the dashboard."""
    accepted = event.get("result") == "accepted"
    params = " " + value_text(event["params"], CONTROL_PARAMS_LIMIT) if event.get("params") else ""
    reason = " (%s)" % event["reason"] if event.get("reason") else ""
    result = "accepted" if accepted else "refused: %s" % event.get("result")
    return ("info" if accepted else "warn", "Control %s%s from %s%s: %s" % (
        _coalesce(event.get("action"), "?"), params, _coalesce(event.get("client"), "?"), reason, result))


def debug_message(event: dict) -> tuple[str, str]:
    """(level, text) of a debug event, as fsmscope/static/transcript.js words it."""
    action, state = event["action"], event.get("state")
    by = " by %s" % event["by"] if event.get("by") else ""
    if action == "mode":
        level = " (the step ends at %s's next transition)" % event["level"] if event.get("level") else ""
        return "info", "Debugger %s%s%s" % (MODE_WORDS.get(event["mode"], event["mode"]), level, by)
    if action == "hold":
        outcome = ":'%s'" % event["outcome"] if event.get("outcome") is not None else ""
        return "warn", "Holding %s '%s'%s: %s" % (event["at"], state, outcome, event["detail"])
    if action == "release":
        return "info", "Released '%s' (%s)" % (state, _coalesce(event.get("by"), "?"))
    if action == "forced":
        returned = event.get("returned")
        said = "it did not run" if returned is None else "it returned '%s'" % returned
        return "warn", "Forced outcome '%s' of '%s' (%s)%s" % (event["outcome"], state, said, by)
    listed = "; ".join(breakpoint_text(bp) for bp in event.get("breakpoints") or []) or "none"
    return "info", "Breakpoints: %s%s" % (listed, by)


MODE_WORDS = {"run": "running", "pause": "pausing at the next transition", "step": "stepping one transition"}


def breakpoint_text(bp: dict) -> str:
    """``before /SM_ROOT/PICK/CLOSE when attempts > 2``, as fsmscope/static/transcript.js writes it."""
    text = "%s %s" % (bp.get("at"), bp.get("state"))
    if bp.get("outcome") is not None:
        text += " with outcome '%s'" % bp["outcome"]
    if bp.get("when"):
        text += " when %s" % bp["when"]
    return text


def _coalesce(value: Any, default: Any) -> Any:
    """JavaScript's ``value ?? default``."""
    return default if value is None else value


def value_text(value: Any, limit: int = 200) -> str:
    """fsmscope/static/transcript.js's valueText: an encoded value (docs/events.md) on one line, cut after
    ``limit`` characters as JavaScript counts them."""
    if isinstance(value, dict) and isinstance(value.get("$repr"), str):
        text = value["$repr"]
    elif isinstance(value, dict) and value.get("$truncated"):
        text = "%s… (%s bytes, truncated)" % (_coalesce(value.get("repr"), ""), js_json(value.get("size")))
    else:
        text = js_json(value)
    units = text.encode("utf-16-le", "surrogatepass")  # JavaScript's length counts UTF-16 units
    if len(units) <= 2 * limit:
        return text
    return units[:2 * limit].decode("utf-16-le", "replace") + "…"  # half a pair: U+FFFD, as the browser draws it


def js_json(value: Any) -> str:
    """JSON.stringify of a JSON value: compact, non-ASCII as is, numbers and key order as in
    JavaScript (so that a line reads the same here and in the browser)."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return _js_number(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, dict):
        return "{%s}" % ",".join("%s:%s" % (json.dumps(key, ensure_ascii=False), js_json(value[key]))
                                 for key in _js_key_order(value))
    return "[%s]" % ",".join(map(js_json, value))


def _js_number(value: float) -> str:
    """Number#toString: the shortest digits that read back as the same double (those of Python's
    repr), written plainly from 1e-7 to 1e21 and with an exponent outside; an integer is a double."""
    x = float(value)
    if x == 0:
        return "0"
    _, digits, exponent = Decimal(repr(abs(x))).normalize().as_tuple()
    s, k = "".join(map(str, digits)), len(digits)
    n = k + exponent  # x = 0.s * 10**n
    if k <= n <= 21:
        text = s + "0" * (n - k)
    elif 0 < n <= 21:
        text = s[:n] + "." + s[n:]
    elif -6 < n <= 0:
        text = "0." + "0" * -n + s
    else:
        text = s[0] + ("." + s[1:] if k > 1 else "") + "e%+d" % (n - 1)
    return "-" + text if x < 0 else text


def _js_key_order(obj: dict) -> list[str]:
    """A JavaScript object's key order: array indices ("0", "7", ...) ascending, then the rest as inserted."""
    def is_index(key: str) -> bool:
        return key.isascii() and key.isdigit() and (key == "0" or key[0] != "0") and int(key) < 2 ** 32 - 1
    return sorted(filter(is_index, obj), key=int) + [key for key in obj if not is_index(key)]


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
