"""A State that waits without spinning and wakes at once when preempted.

smach_ros states block on services, action servers, topics and polls. Each of those waits
sleeps on ``self._wake``, which ``request_preempt`` sets; waits that may last long also
wake once a second to notice ``fsm.core.log.is_shutdown()``, as smach_ros's 1 s loops did.
"""

import threading
import time
from typing import Any, Callable

from ..core import log
from ..core.state import State

# How often a long wait looks at the shutdown check (smach_ros's wait step).
SHUTDOWN_CHECK_PERIOD = 1.0


def to_seconds(duration: Any) -> float | None:
    """Float seconds from None, a number, or a ``rospy.Duration``-like object with ``to_sec()``."""
    if duration is None:
        return None
    to_sec = getattr(duration, "to_sec", None)
    return float(to_sec() if to_sec is not None else duration)


class PreemptibleState(State):
    """Base of the smach_ros states: ``_wake`` is set by every preempt request."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        State.__init__(self, *args, **kwargs)
        self._wake = threading.Event()

    def request_preempt(self) -> None:
        State.request_preempt(self)
        self._wake.set()

    def _wait_for(self, available: Callable[[float, threading.Event | None], bool], timeout: float | None,
                  waiting_msg: str) -> bool:
        """Wait until ``available(seconds, wake)`` holds, up to ``timeout`` s (None: forever).

        False on timeout, preempt or shutdown; the caller tells them apart. ``waiting_msg`` is
        logged as a warning once per wait step while the thing is missing.
        """
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            self._wake.clear()
            if self.preempt_requested() or log.is_shutdown():
                return False
            if available(0.0, None):
                return True
            step = SHUTDOWN_CHECK_PERIOD
            if deadline is not None:
                step = min(step, deadline - time.monotonic())
                if step <= 0:
                    return False
            log.logwarn(waiting_msg)
            available(step, self._wake)
