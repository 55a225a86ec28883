"""What another thread hands to a server's event loop: the fleet's watcher (fleet_bridge.py) and a ROS
graph's (ros_live.py) deliver events from threads of their own, the hub takes them on its loop
(``ingest_in_order``)."""

from __future__ import annotations

import asyncio
import collections
import threading
import sys
from typing import TYPE_CHECKING, Callable

if TYPE_CHECKING:
    from ..hub import Hub, MachineEntry


class LoopInbox:
    """What the watcher's threads hand to the event loop, in order: calls queued, run together when the
    watcher says the samples that came together are handled (``wake``). A fleet's robots put on the
    same tick, so its thousands of batches a second wake the loop a few hundred times, not once per
    batch: each wake costs the loop more than ingesting an event does."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self.loop = loop
        self._calls: collections.deque[tuple[Callable[..., None], tuple]] = collections.deque()
        self._lock = threading.Lock()
        self._scheduled = False

    def post(self, call: Callable[..., None], *args: object) -> None:
        """From any thread: ``call(*args)`` on the loop, after those posted before it, at the next ``wake``."""
        self._calls.append((call, args))

    def wake(self) -> None:
        """From any thread: run what was posted, unless the loop is about to."""
        with self._lock:
            if self._scheduled or not self._calls:
                return
            self._scheduled = True
        self.loop.call_soon_threadsafe(self._run)

    def _run(self) -> None:
        with self._lock:
            self._scheduled = False
        calls = self._calls
        for _ in range(len(calls)):  # those posted meanwhile come with a wake of their own
            call, args = calls.popleft()
            call(*args)


def ingest_in_order(hub: Hub, events: list[dict], where: str) -> MachineEntry | None:
    """One machine's ``events``, in order, through the hub's ingest door (each checked against the
    schema, one refused said on stderr as coming from ``where``); the machine's entry."""
    for event in events:
        problem = hub.ingest(event, "ingest")
        if problem:
            print("fsmscope: refused an event of %s from %s: %s" % (event.get("machine"), where, problem),
                  file=sys.stderr, flush=True)
    return hub.get(events[0]["machine"])
