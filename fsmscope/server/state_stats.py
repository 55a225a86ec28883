"""Per-state statistics of a served machine (visits, time in state, last outcome): the numbers
``fsmscope replay`` prints, from the same code (fsm/logfiles/summary.py's ``Summary``), for
GET /api/machines/{name}/summary (docs/api.md, "State statistics").

Nothing is paid per event: a machine's ``Summary`` is fed only when somebody asks, with the events
since the last question (from memory, or the recording for older ones), at most ``CATCH_UP`` per
question and ``CATCH_UP_SECONDS`` of work, so a page polling every second reads only the last second's
events, a first question about a long recording answers at once with what it has counted so far
(``counted`` says how far), and a machine faster than counting is never slowed down by it: its
summary says how far behind it is.
"""

from __future__ import annotations

import threading
import time

from fsm.logfiles.summary import Summary

from .history import HistoryView

CATCH_UP = 100_000  # events read for one question at most
CATCH_UP_SECONDS = 0.005  # of this thread's CPU time read for one question, about (looked at every LOOK events)
LOOK = 256  # events counted between two looks at the time spent


class StateStats:
    """One machine's Summary, and the seqs of the events it has counted."""

    def __init__(self, machine: str) -> None:
        self.machine = machine
        self.lock = threading.Lock()  # questions come from the thread pool
        self._start()

    def _start(self) -> None:
        self.summary = Summary()
        self.first: int | None = None  # the first seq counted (None: none yet)
        self.upto = 0  # the last seq counted

    def answer(self, view: HistoryView, structure: dict | None, path: str | None) -> dict:
        """The statistics of ``path`` (every state when None), after reading the events not yet counted.
        ``structure``: the machine's current structure (its container kinds, when its events say none)."""
        with self.lock:
            span = view.span()
            first, last = span["first_seq"], span["last_seq"]
            if last is not None:
                self._catch_up(view, first, last, structure)
            seen = self.summary.machines.get(self.machine)
            paths = (list(seen.visits) if seen is not None else []) if path is None else [path]
            states = {p: self.summary.state(self.machine, p) for p in paths}
            return {"counted": {"first_seq": self.first, "last_seq": self.upto or None}, "last_seq": last,
                    "complete": last is None or self.upto >= last, "states": states}

    def _catch_up(self, view: HistoryView, first: int, last: int, structure: dict | None) -> None:
        if last < self.upto or first > self.upto + 1:  # numbered from 1 again (restarted), or a gap: start over
            self._start()
        since = max(first, self.upto + 1)
        until = min(last, since + CATCH_UP - 1)
        if since > until:
            return
        if self.first is None:
            self.first = since
            if structure is not None:  # its events from the first counted on may hold no structure event
                self.summary.structures.add(self.machine, structure)
        deadline = time.thread_time() + CATCH_UP_SECONDS
        for counted, event in enumerate(view.events(since, until), 1):
            self.summary.add(event)
            if counted % LOOK == 0 and time.thread_time() > deadline:
                self.upto = event["seq"]
                return
        self.upto = until
