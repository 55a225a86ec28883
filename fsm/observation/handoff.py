"""Events handed from a machine's thread to a sender's (fsmscope/server/publisher.py): the
observer appends to a bounded queue and never waits (when it is full the oldest event is dropped,
and counted); the sender is woken, takes the events, and says while it is busy with them."""

from __future__ import annotations

import collections
import threading
import time


class Handoff:
    """The observer (``handoff(event)``), the queue (``events``) and the sender's wake-up (``wake``)."""

    def __init__(self, size: int) -> None:
        self.events: collections.deque[dict] = collections.deque(maxlen=size)
        self.wake = threading.Event()
        self.dropped = 0  # events dropped because the queue was full
        self.busy = False  # the sender holds events it took and has not sent yet

    def __call__(self, event: dict) -> None:
        events = self.events
        if len(events) == events.maxlen:
            self.dropped += 1
        events.append(event)
        if not self.wake.is_set():
            self.wake.set()

    def drained(self, timeout: float) -> bool:
        """Wait until every event was taken and sent; False on timeout."""
        deadline = time.monotonic() + timeout
        while (self.events or self.busy) and time.monotonic() < deadline:
            time.sleep(0.005)
        return not self.events
