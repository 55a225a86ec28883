"""SMACH's own log lines of a machine of the original SMACH, as ``log`` events.

The original logs through four functions of its package, ``smach.loginfo``, ``logwarn``,
``logdebug`` and ``logerr`` (smach_ros points them at rospy's with ``smach.set_loggers``), looked
up at each call. ``watch(package)`` wraps whichever are set now (it is called at each run's start,
so loggers set later are wrapped then): a wrapper calls the function it wraps, with the same
arguments and first, so what is printed does not change, and then, when the line is logged inside
an observed container (``fsm.core.reporting.current``), sends it as a ``log`` event of that
container, as fsm's own log does.

As in fsm (fsm/core/log.py), the lines that the start, transition and terminate events already say
are not sent: ``fsm.logfiles.transcript`` rebuilds them word for word from those events.
"""

from __future__ import annotations

import functools
from typing import Any, Callable

from ..core import reporting
from .schema import build

LOGGERS = (("info", "loginfo"), ("warn", "logwarn"), ("debug", "logdebug"), ("error", "logerr"))

# SMACH's lines that events carry (fsm's info_quiet and debug_quiet lines).
_QUIET_INFO_STARTS = ("State machine starting in initial state '", "State machine transitioning '",
                      "State machine terminating '", "Concurrence starting with userdata: \n\t",
                      "Concurrent Outcomes: ")
_QUIET_DEBUG = frozenset(("SMACH Concurrence determining contained state outcomes.",
                          "Terminating concurrent split with mapped outcome."))


def quiet(level: str, text: str) -> bool:
    """Whether SMACH's line is one the events already say (so it is not sent as a ``log`` event)."""
    if level == "info":
        return text.startswith(_QUIET_INFO_STARTS) or (
            text.startswith("Concurrent state '") and text.endswith("' on termination."))
    if level == "debug":
        return text in _QUIET_DEBUG or (text.startswith("Skipping mapped outcome '")
                                        and text.endswith("' with fewer constraints."))
    return False


def watch(package: Any) -> None:
    """Wrap the package's log functions that are not wrapped yet (never raising)."""
    for level, name in LOGGERS:
        try:
            current = getattr(package, name)
            if not callable(current) or getattr(current, "_fsm_log_level", None) is not None:
                continue
            setattr(package, name, _wrapped(level, current))
        except Exception:  # a package without its loggers: its lines are not observed
            continue


def _wrapped(level: str, inner: Callable[..., Any]) -> Callable[..., Any]:
    said = _QUIET_INFO_STARTS if level == "info" else None  # the lines of every step, told at once

    @functools.wraps(inner)
    def logged(msg: Any = "", *args: Any, **kwargs: Any) -> Any:
        result = inner(msg, *args, **kwargs)
        if said is not None and not args and type(msg) is str and msg.startswith(said):
            return result
        ctx = reporting.current()
        if ctx is not None:
            _send(ctx, level, msg, args)
        return result

    logged._fsm_log_level = level  # type: ignore[attr-defined]
    return logged


def _send(ctx: tuple[Any, str], level: str, msg: Any, args: tuple) -> None:
    try:
        text = str(msg) if not args else str(msg) % args
        if not quiet(level, text):
            ctx[0].send(build.log, ctx[1], level, text)
    except Exception:  # a message that cannot be written: the line was printed, the event is left out
        pass
