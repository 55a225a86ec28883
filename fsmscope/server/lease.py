"""The operator lease and its deadman (docs/debugging.md, "One operator at a time").

At most one page controls a machine at a time: the page that holds its lease. A page takes a free
lease with its first control (or explicitly), another operator's page takes it over explicitly,
and every change is a ``control`` event, so the audit says who held control when. The holder's page
sends a heartbeat; when the beats stop for ``Deadman.after`` seconds (the laptop lid closed, the
tab killed, the network gone) the lease lapses and the machine does ``Deadman.action``: pause,
preempt, or nothing.

A lease belongs to a page (``X-Fsmscope-Page``: random per page load), not to a token: the
operators share one token, and two tabs of one operator are two pages. Preempt and "stop after
this run" never need the lease: whoever may control may always stop (an emergency stop that waits
for a lease is not one). A script that sends no page id controls a machine nobody holds, and is
refused one that a page holds, like any other page.

This module keeps the leases and says when they lapse; fsmscope/server/lease_control.py records the events
and applies the deadman's action.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import Callable

from fsm.control.frames import DEADMAN_ACTIONS

BEAT_EVERY = 1.0  # seconds between a holder page's heartbeats (fsmscope/static/lease.js reads it from GET .../lease)


@dataclass(frozen=True)
class Deadman:
    """What a machine does when its lease holder's heartbeat stops for ``after`` seconds."""

    after: float = 3.0
    action: str = "pause"

    def __post_init__(self) -> None:
        if self.action not in DEADMAN_ACTIONS:
            raise ValueError("the deadman's action must be one of %s, not %r" % (", ".join(DEADMAN_ACTIONS),
                                                                              self.action))
        if not self.after > BEAT_EVERY:
            raise ValueError("the deadman's time must be longer than a heartbeat (%.1f s), not %r"
                             % (BEAT_EVERY, self.after))


@dataclass
class Lease:
    """Who controls one machine: a page (its id), from where, since when, last heard when."""

    page: str
    client: str
    since: float  # wall-clock time it was taken
    beat: float  # monotonic time of its last sign of life (a heartbeat or a control)

    def who(self) -> str:
        """In words: its client, which names the page ("127.0.0.1 (operator, page 3f2a9c1d)")."""
        return self.client


def short(page: str) -> str:
    """The part of a page id shown to people: enough to tell pages apart."""
    return page[:8]


class LeaseHeld(Exception):
    """Another page holds the lease: the request is refused (409) with this message."""


class Leases:
    """The leases of one server's machines, by machine name. Thread-safe: controls run in worker threads."""

    def __init__(self, deadman: Deadman, clock: Callable[[], float] = time.monotonic) -> None:
        self.deadman = deadman
        self._clock = clock
        self._leases: dict[str, Lease] = {}
        self._lock = threading.Lock()

    def holder(self, name: str) -> Lease | None:
        return self._leases.get(name)

    def take(self, name: str, page: str, client: str, takeover: bool = False) -> tuple[Lease, bool, Lease | None]:
        """(the page's lease, whether it is new, the other page's lease it replaced). Raises LeaseHeld
        when another page holds it and ``takeover`` is false."""
        with self._lock:
            current = self._leases.get(name)
            if current is not None and current.page == page:
                current.beat = self._clock()
                return current, False, None
            if current is not None and not takeover:
                raise LeaseHeld(self._held_message(name, current))
            lease = self._leases[name] = Lease(page, client, time.time(), self._clock())
            return lease, True, current

    def admit(self, name: str, page: str | None) -> None:
        """Let a control from ``page`` (None: a script) act on machine ``name``: the lease is free or the
        page's own (then it is a sign of life). Raises LeaseHeld otherwise."""
        with self._lock:
            current = self._leases.get(name)
            if current is None:
                return
            if current.page != page:
                raise LeaseHeld(self._held_message(name, current))
            current.beat = self._clock()

    def beat(self, name: str, page: str) -> Lease:
        """The holder's heartbeat; raises LeaseHeld when this page no longer holds the lease."""
        with self._lock:
            current = self._leases.get(name)
            if current is None or current.page != page:
                raise LeaseHeld(self._lost_message(name, current))
            current.beat = self._clock()
            return current

    def release(self, name: str, page: str) -> Lease | None:
        """Give the lease up; the released lease, or None when this page did not hold it."""
        with self._lock:
            current = self._leases.get(name)
            if current is None or current.page != page:
                return None
            del self._leases[name]
            return current

    def lapsed(self) -> list[tuple[str, Lease]]:
        """Remove and return the leases whose holder has been silent for the deadman's time."""
        now = self._clock()
        with self._lock:
            gone = [(name, lease) for name, lease in self._leases.items() if now - lease.beat >= self.deadman.after]
            for name, _ in gone:
                del self._leases[name]
        return gone

    @staticmethod
    def _held_message(name: str, lease: Lease) -> str:
        return ("%s controls machine %r since %s: take control over to control it"
                % (lease.who(), name, time.strftime("%H:%M:%S", time.localtime(lease.since))))

    @staticmethod
    def _lost_message(name: str, lease: Lease | None) -> str:
        if lease is None:
            return "this page no longer controls machine %r (its lease lapsed or was released)" % name
        return "this page no longer controls machine %r: %s took control over" % (name, lease.who())
