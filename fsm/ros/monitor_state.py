"""MonitorState: watch a bus topic with a condition, as smach_ros's MonitorState does."""

import threading
from typing import Any, Callable

from ..core import log
from .bus import Bus, get_bus
from .preemptible import PreemptibleState


class MonitorState(PreemptibleState):
    """Subscribes to ``topic`` while it runs and calls ``cond_cb(ud, msg)`` on every message.

    A True return means "all is well, keep monitoring". False, or an exception (logged),
    ends the state with 'invalid'; ``max_checks`` True results (when positive) end it with
    'valid'; a preempt ends it with 'preempted' at once. With the default ``max_checks=-1``
    it never returns 'valid'. ``msg_type`` is kept for SMACH's signature: bus messages are
    any Python objects, and none is filtered by type.
    """

    def __init__(self, topic: str, msg_type: Any, cond_cb: Callable[[Any, Any], Any], max_checks: int = -1,
                 input_keys: list[str] = [], output_keys: list[str] = [], bus: Bus | None = None) -> None:
        PreemptibleState.__init__(self, outcomes=["valid", "invalid", "preempted"], input_keys=input_keys,
                                  output_keys=output_keys)
        self._topic = topic
        self._cond_cb = cond_cb
        self._max_checks = max_checks
        self._bus = get_bus(bus)
        self._lock = threading.Lock()
        self._n_checks = 0
        self._ended = False

    def execute(self, ud: Any) -> str:
        self._wake.clear()
        if self.preempt_requested():
            self.service_preempt()
            return "preempted"
        with self._lock:
            self._n_checks = 0
            self._ended = False
        sub = self._bus.subscribe(self._topic, lambda msg: self._on_message(ud, msg))
        try:
            while not self._ended and not self.preempt_requested():
                self._wake.wait()
                self._wake.clear()
        finally:
            sub.unregister()
        if self.preempt_requested():
            self.service_preempt()
            return "preempted"
        if self._max_checks > 0 and self._n_checks >= self._max_checks:
            return "valid"
        return "invalid"

    def _on_message(self, ud: Any, msg: Any) -> None:
        """Runs in the publisher's thread; messages after the verdict are ignored."""
        with self._lock:
            if self._ended:
                return
            try:
                if self._cond_cb(ud, msg):
                    self._n_checks += 1
                    self._ended = self._max_checks > 0 and self._n_checks >= self._max_checks
                else:
                    self._ended = True
            except Exception as e:
                log.logerr("Error thrown while executing condition callback %s: %s" % (self._cond_cb, e))
                self._ended = True
            if self._ended:
                self._wake.set()
