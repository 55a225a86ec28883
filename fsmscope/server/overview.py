"""The fleet overview: one tile per machine the hub knows (a robot's over Zenoh, another process's,
this process's own, a replay), each saying what an operator scans a fleet for: whose machine it is,
whether it runs, failed, finished, idles or is gone, the state it is in, how fast its events come
and when one last came. Tiles are read from the hub's entries as they are, never from the events
themselves: a fleet at thousands of events a second costs the overview nothing per event.

The event rate and the last-seen time are the server's own observations of each machine's
``last_seq``, sampled each time tiles are made (the overview's stream makes them twice a second),
so they are on the server's clock whatever a robot's clock says.
"""

from __future__ import annotations

import collections
import time
from typing import TYPE_CHECKING

from fsm.observation import schema
from fsm.observation.vocabularies import run_state

if TYPE_CHECKING:
    from .hub import Hub, MachineEntry

RATE_WINDOW = 5.0  # seconds of samples the event rate is the mean over


def state_of(entry: MachineEntry) -> str:
    """The tile's run state (fsm/observation/vocabularies.py); a run that ended stays failed or done
    when its process goes (the tile's ``connected`` says it is gone too)."""
    status = entry.feed.status
    return run_state(entry.running(), status.outcome, status.error, entry.origin.connected)


class Overview:
    """The tiles of the hub's machines; keeps each machine's recent ``last_seq`` samples."""

    def __init__(self, hub: Hub) -> None:
        self.hub = hub
        self._samples: dict[str, collections.deque[tuple[float, int]]] = {}
        self._seen: dict[str, tuple[int, float]] = {}  # name: (last_seq, when it was first seen at that seq)

    def tiles(self) -> list[dict]:
        """Every machine's tile (``schema.TILE``), in the hub's order, sampled now."""
        now, wall = time.monotonic(), time.time()
        entries = self.hub.machines()
        names = {entry.name for entry in entries}
        for gone in set(self._samples) - names:
            del self._samples[gone]
            self._seen.pop(gone, None)
        return [self._tile(entry, now, wall) for entry in entries]

    def _tile(self, entry: MachineEntry, now: float, wall: float) -> dict:
        feed = entry.feed
        with feed.lock:  # a local machine's thread applies its events
            status = feed.status
            seq, last_t, outcome, error = status.last_seq, status.last_t, status.outcome, status.error or {}
            active = status.active_leaves() if status.structure is not None else []
        samples = self._samples.setdefault(entry.name, collections.deque())
        samples.append((now, seq))
        while samples and now - samples[0][0] > RATE_WINDOW:
            samples.popleft()
        first_t, first_seq = samples[0]
        rate = (seq - first_seq) / (now - first_t) if now - first_t >= 0.5 and seq >= first_seq else 0.0
        seen = self._seen.get(entry.name)
        if seen is None or seen[0] != seq:
            # First sight: when its newest event was made (never later than now); then: when it changed.
            seen = (seq, min(last_t or wall, wall) if seen is None else wall)
            self._seen[entry.name] = seen
        origin = entry.origin
        return schema.tile(name=entry.name, robot=origin.robot,
                           machine=entry.name.partition(":")[2] if origin.robot else entry.name, source=origin.source,
                           state=state_of(entry), outcome=outcome,
                           error=error.get("exc_type") or error.get("message") or None, active=active,
                           rate=round(rate, 1), last_seq=seq, last_seen=seen[1] if seq else None,
                           connected=not origin.gone)
