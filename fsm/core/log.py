"""SMACH's logging hooks.

Every line goes to the bound printer (``set_loggers``) and, when a tool listens, to the
introspection layer as a ``log`` event. ``_quiet`` lines are only printed: the start, transition
and termination lines, which the events already say and ``fsm.logfiles.transcript`` rebuilds, and
a Concurrence's debug lines of its outcome choice, which a replay leaves out.
"""

from typing import Callable

Printer = Callable[[str], object]

LEVELS = ("debug", "info", "warn", "error")  # least severe first, as rospy's log levels
_DEFAULT_PRINTERS: dict[str, Printer] = {
    "info": lambda m: print("[  INFO ] : " + str(m)),
    "warn": lambda m: print("[  WARN ] : " + str(m)),
    "debug": lambda m: print("[ DEBUG ] : " + str(m)),
    "error": lambda m: print("[ ERROR ] : " + str(m)),
}
_printers: dict[str, Printer] = dict(_DEFAULT_PRINTERS)

# Set by fsm.observation.introspection while a reporter listens: listener(level, message).
listener: Callable[[str, str], None] | None = None


def _emit(level: str, msg: object) -> None:
    _printers[level](msg)
    if listener is not None:
        listener(level, str(msg))


def loginfo(msg: object) -> None:
    _emit("info", msg)


def logwarn(msg: object) -> None:
    _emit("warn", msg)


def logdebug(msg: object) -> None:
    _emit("debug", msg)


def logerr(msg: object) -> None:
    _emit("error", msg)


def info_quiet(msg: str) -> None:
    """An INFO line that events already carry: printed, not sent as a log event."""
    _printers["info"](msg)


def debug_quiet(msg: str) -> None:
    """A DEBUG line printed, not sent as a log event: a Concurrence's outcome choice, which comes
    after its 'Concurrent Outcomes' line (rebuilt from its terminate event), so a replay leaves it out."""
    _printers["debug"](msg)


def set_loggers(info: Printer, warn: Printer, debug: Printer, error: Printer) -> None:
    """Rebind the printers; the order is info, warn, debug, error, as in SMACH."""
    _printers.update(info=info, warn=warn, debug=debug, error=error)


def print_from(level: str) -> None:
    """Print the lines of ``level`` and the more severe ones, word for word, and not the others, as
    rospy's log level does (SMACH prints every level). Only what is printed changes: a listening
    tool still gets every line as a log event."""
    least = LEVELS.index(level)
    _printers.update({name: _DEFAULT_PRINTERS[name] if LEVELS.index(name) >= least else _unprinted
                      for name in LEVELS})


def _unprinted(msg: str) -> None:
    pass


_shutdown_check: Callable[[], bool] = lambda: False


def is_shutdown() -> bool:
    return _shutdown_check()


def set_shutdown_check(cb: Callable[[], bool]) -> None:
    """When ``cb()`` turns True, running containers stop (as with ``rospy.is_shutdown``)."""
    global _shutdown_check
    _shutdown_check = cb
