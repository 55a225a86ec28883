"""The lease's part in the app: taking, beating, releasing and lapsing a machine's lease, each
recorded as a ``control`` event of that machine, and the deadman's action when a lease lapses.

fsmscope/server/lease.py keeps the leases; this connects them to the machines (their handles) and to the
audit. Every call may block briefly on a machine's locks: the routes run them in a worker thread.
"""

from __future__ import annotations

import asyncio
import sys
import traceback
from typing import Any

from fsm.control.controls import Controls
from fsm.control.frames import apply_deadman

from .hub import Hub, MachineEntry
from .lease import Lease, Leases, short

DEADMAN = "deadman"  # the client of what the deadman does
SWEEP_EVERY = 0.25  # seconds between two looks for lapsed leases


class LeaseControl:
    """The leases of ``hub``'s machines, recorded and enforced."""

    def __init__(self, hub: Hub, leases: Leases) -> None:
        self.hub = hub
        self.leases = leases

    def take(self, entry: MachineEntry, page: str, client: str, takeover: bool, how: str = "asked") -> Lease:
        """Take (or, ``takeover``, take over) the lease of ``entry``'s machine for ``page``."""
        lease, fresh, previous = self.leases.take(entry.name, page, client, takeover)
        if fresh:
            params: dict[str, Any] = {"page": short(page), "how": "taken over" if previous else how}
            if previous is not None:
                params["from"] = previous.who()
            self._changed(entry, client, params, held=True)
        return lease

    def admit(self, entry: MachineEntry, page: str | None, client: str) -> None:
        """Let a control from ``page`` act: a page's first control takes a free lease (recorded);
        raises lease.LeaseHeld when another page holds it."""
        if page is not None and self.leases.holder(entry.name) is None:
            self.take(entry, page, client, takeover=False, how="first control")
            return
        self.leases.admit(entry.name, page)

    def beat(self, entry: MachineEntry, page: str) -> Lease:
        return self.leases.beat(entry.name, page)

    def release(self, entry: MachineEntry, page: str, client: str) -> bool:
        released = self.leases.release(entry.name, page)
        if released is not None:
            self._changed(entry, client, {"page": short(page), "how": "released"}, held=False)
        return released is not None

    def sweep(self) -> None:
        """Apply the deadman to every lease whose holder went silent (runs in a worker thread)."""
        deadman = self.leases.deadman
        for name, lease in self.leases.lapsed():
            handle = self._handle(name)
            if handle is None:
                continue
            handle.lease_changed(False, deadman.after, deadman.action)
            apply_deadman(handle, deadman.action, DEADMAN,
                          "no heartbeat from %s for %.1f s" % (lease.who(), deadman.after),
                          {"page": short(lease.page), "after": deadman.after})

    async def run_deadman(self) -> None:
        """The app's deadman: look for lapsed leases until cancelled."""
        loop = asyncio.get_running_loop()
        while True:
            await asyncio.sleep(SWEEP_EVERY)
            try:
                await loop.run_in_executor(None, self.sweep)
            except Exception:
                sys.stderr.write("fsmscope: the deadman's sweep failed:\n" + traceback.format_exc())

    def _handle(self, name: str) -> Controls | None:
        """The machine's controls, whatever kind of machine it is."""
        entry = self.hub.get(name)
        return None if entry is None else entry.controls

    def _changed(self, entry: MachineEntry, client: str, params: dict, held: bool) -> None:
        handle = self._handle(entry.name)
        deadman = self.leases.deadman
        handle.lease_changed(held, deadman.after, deadman.action)
        handle.emit_control("lease", client, "accepted", params=params)
