"""The deadman a machine's own process applies when its link to the dashboard whose operator holds
the machine's lease is lost for longer than the lease's ``after``: the websocket publisher's
connection (fsmscope/server/publisher.py), or a dashboard's liveliness on Zenoh (fsmscope/fleet/control.py).

The dashboard says each lease (``lease`` frames, ``frames.lease_of``); ``lost()`` arms a timer per
machine leased, ``back()`` disarms them all. A timer armed for an outage that has ended does
nothing, even when it fires in the instant the link comes back.
"""

from __future__ import annotations

import threading

from .frames import apply_deadman, lease_of
from .controls import Controls


class Deadmen:
    """The leases one dashboard holds on this process's machines (``handles``: by name), and the
    deadmen they arm; what they do is a ``control`` event by ``client``."""

    def __init__(self, handles: dict[str, Controls], client: str, link: str) -> None:
        self.handles = handles
        self.client = client
        self.link = link  # what was lost, as the deadman's reason says it
        self._lock = threading.Lock()
        self._leases: dict[str, tuple[float, str]] = {}  # machine: (after, action) while a lease is held
        self._outage = 0  # bumped when the link is back: a deadman armed before does nothing
        self._timers: list[threading.Timer] = []

    def said(self, frame: dict) -> bool:
        """A ``lease`` frame from the dashboard: a lease held (arms a deadman on loss) or released;
        False for a malformed one."""
        said = lease_of(frame)
        if said is None:
            return False
        machine, lease = said
        with self._lock:
            if lease is None:
                self._leases.pop(machine, None)
            else:
                self._leases[machine] = lease
        return True

    def lost(self) -> None:
        """The link is lost: each machine leased gets its deadman's delay for the link to come back."""
        with self._lock:
            for machine, (after, action) in self._leases.items():
                timer = threading.Timer(after, self._fire, (self._outage, machine, after, action))
                timer.daemon = True
                self._timers.append(timer)
                timer.start()

    def back(self, forget: bool) -> None:
        """The link is back (or the process stops): no deadman fires; ``forget``: the leases too (the
        dashboard says them again on a new connection)."""
        with self._lock:
            self._outage += 1
            for timer in self._timers:
                timer.cancel()
            self._timers = []
            if forget:
                self._leases.clear()

    def _fire(self, outage: int, machine: str, after: float, action: str) -> None:
        with self._lock:
            if outage != self._outage:
                return
        handle = self.handles.get(machine)
        if handle is not None:
            apply_deadman(handle, action, self.client, "%s was lost for %.1f s" % (self.link, after), {"after": after})
