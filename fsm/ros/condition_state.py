"""ConditionState: poll a condition callback, as smach_ros's ConditionState does."""

import time
import traceback
from typing import Any, Callable

from ..core.exceptions import InvalidUserCodeError
from .preemptible import PreemptibleState, to_seconds


class ConditionState(PreemptibleState):
    """Calls ``cond_cb(ud)`` every ``poll_rate`` seconds until it is truthy ('true').

    It gives up with 'false' after ``timeout`` seconds or after max_checks+1 calls (SMACH's
    loop runs while ``n_checks <= max_checks``; kept for compatibility); ``max_checks=-1``
    polls forever. An exception in ``cond_cb`` raises InvalidUserCodeError. The sleep
    between polls ends at once on a preempt, which gives 'preempted'.
    """

    def __init__(self, cond_cb: Callable[[Any], Any], input_keys: list[str] = [], poll_rate: Any = 0.05,
                 timeout: Any = None, max_checks: int = 1) -> None:
        PreemptibleState.__init__(self, outcomes=["true", "false", "preempted"], input_keys=input_keys)
        self._cond_cb = cond_cb
        if hasattr(cond_cb, "get_registered_input_keys") and hasattr(cond_cb, "get_registered_output_keys"):
            self.register_input_keys(cond_cb.get_registered_input_keys())
            self.register_output_keys(cond_cb.get_registered_output_keys())
        self._poll_rate = to_seconds(poll_rate)
        self._timeout = to_seconds(timeout)
        self._max_checks = max_checks

    def execute(self, ud: Any) -> str:
        start = time.monotonic()
        n_checks = 0
        while self._max_checks == -1 or n_checks <= self._max_checks:
            self._wake.clear()
            if self._timeout and time.monotonic() - start > self._timeout:
                break
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
            try:
                if self._cond_cb(ud):
                    return "true"
            except Exception:
                raise InvalidUserCodeError("Error thrown while executing condition callback %s: " % self._cond_cb
                                           + traceback.format_exc())
            n_checks += 1
            self._wake.wait(self._poll_rate)
        return "false"
