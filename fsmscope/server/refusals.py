"""Controls refused before they reach a machine (a viewer's token, another page's lease), written in the
machine's audit all the same: a ``control`` event saying who asked, what and why not.

A refusal costs its asker nothing, so the audit takes at most one a second of each address and action
on a machine: a client that repeats a refused control is answered every time and cannot fill the
machine's log with its refusals.
"""

from __future__ import annotations

import threading
import time

from fsm.control.controls import Controls, Refused

EVERY = 1.0  # seconds between two refusals recorded of one address and action on one machine
KEPT = 4096  # (machine, address, action) remembered at most; the oldest are forgotten first


class Refusals:
    """The refusals one server recorded lately, to record each kind at most once per ``EVERY``."""

    def __init__(self, every: float = EVERY) -> None:
        self.every = every
        self._last: dict[tuple[str, str, str], float] = {}
        self._lock = threading.Lock()

    def record(self, controls: Controls, machine: str, address: str, action: str, client: str, why: str) -> None:
        """A ``control`` event of ``action`` by ``client`` refused for ``why``, unless one of ``address`` and
        ``action`` was recorded on ``machine`` less than ``every`` ago. May block briefly (a machine of
        another process records it there): call it from a worker thread."""
        key = (machine, address, action)
        now = time.monotonic()
        with self._lock:
            if now - self._last.get(key, -self.every) < self.every:
                return
            self._last.pop(key, None)
            self._last[key] = now
            while len(self._last) > KEPT:
                del self._last[next(iter(self._last))]
        try:
            controls.emit_control(action, client, why)
        except Refused:
            pass  # nothing here controls the machine (a replay, a publisher away): it has no audit to write to
