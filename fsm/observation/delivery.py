"""Events handed to the observers that take them in batches, on one thread of the process.

What a machine's thread does for an observed step is kept to what must be ordered there: the
reporter appends a record of the step (its time, run and the values of its event) to its pending
list, with no lock; the order of that list is the order of the seqs, which ``Reporter.deliver``
stamps as it makes the events of a batch (fsm/observation/introspection.py). Everything else happens
here, once per batch rather than once per event and once for every observer rather than once per
observer: each event is encoded once (``Batch.encoded``, the same bytes for the log, the dashboard's
ring and a robot's publisher), the machine's ``Status`` is folded once for every reader, and each
observer takes the whole batch (the recorder appends it to its buffer, the hub's feed to its
hand-off to the loop). Under the GIL, moving work to another thread does not make it cheaper
(decision 05); what batches save is the per-event work of every hop: a lock, a call, a wake-up, a
check, a Python loop iteration.

The thread wakes at the first event after a quiet spell, so an event of a machine that steps now and
then reaches its observers at once (the page's latency); after a batch of at least ``BUSY_BATCH``
events it lets the machine run ``INTERVAL`` before taking the next, so that a machine stepping as
fast as it can is delivered in a few batches per ``INTERVAL``, not in as many wake-ups as it has
events. A machine that has ``INLINE_BATCH`` events waiting delivers them itself, in its own thread
(``Reporter.transition``, ``Reporter._pend``): each batch the thread takes from a busy machine costs
it two hand-overs of the GIL, and a busy machine never waits for them; the thread, told how many it
delivered (``Reporter.inline``), sees it busy and comes back only after ``INTERVAL`` for what it
left (docs/decisions/12-a-busy-machine-delivers-its-own-batches.md). A root's termination is
delivered in the machine's thread before its ``execute`` returns (``Reporter.send``), so what ran is
with every observer when the call that ran it ends, and so are the other events someone acts on at
once (an error, a preempt, a control, a debugger's hold); ``Reporter.deliver`` does the same for an
observer that closes (the recorder, the hub).
"""

from __future__ import annotations

import collections
import os
import threading
import time
from typing import Any, Protocol

from .encoding import dumps_all
from .status import Status

INTERVAL = 0.005  # s a busy machine runs between two batches (well within the log's 100 ms)
BUSY_BATCH = 64  # a batch at least this large means the machine is busy: wait INTERVAL before the next
INLINE_BATCH = 256  # events waiting: the machine's own thread delivers them (see the module's docstring)


class Batch:
    """One machine's events, in order, as one observer after another takes them: ``events`` (the
    dicts, never changed once made), their JSON (``encoded``, made once, on first use) and the
    machine's ``Status`` after the last of them (None when no observer asked for one)."""

    __slots__ = ("machine", "events", "status", "_encoded")

    def __init__(self, machine: str, events: list[dict], status: Status | None) -> None:
        self.machine = machine
        self.events = events
        self.status = status
        self._encoded: list[bytes] | None = None

    def encoded(self) -> list[bytes]:
        data = self._encoded
        if data is None:
            data = self._encoded = dumps_all(self.events)
        return data


class BatchObserver(Protocol):
    """An observer that takes a machine's events in batches (``take_batch``), in the delivery's
    thread or, for a root's termination and a flush, in the thread that sent or asked for it;
    one batch at a time per machine, in order. It may also have ``next_cut(machine) -> seq | None``:
    the seq of the event after which it wants a batch to end (to read the Status there)."""

    def take_batch(self, batch: Batch) -> None: ...


class _Delivery:
    """The process's delivery thread and the reporters with events pending (``ready``)."""

    def __init__(self) -> None:
        self._ready: collections.deque[Any] = collections.deque()
        self._wake = threading.Event()
        self._idle = True  # the thread waits for a wake-up (set before it looks a last time)
        self._thread: threading.Thread | None = None
        self._start_lock = threading.Lock()

    def ready(self, reporter: Any) -> None:
        """In a machine's thread, holding ``reporter``'s lock: its pending list just got its first event."""
        self._ready.append(reporter)
        if self._idle:
            self._idle = False
            if self._thread is None:
                self._start()
            self._wake.set()

    def _start(self) -> None:
        with self._start_lock:
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name="fsm-delivery", daemon=True)
                self._thread.start()

    def _run(self) -> None:
        ready = self._ready
        while True:
            self._wake.wait()
            self._wake.clear()
            while True:
                largest = 0
                for _ in range(len(ready)):  # those ready now: a machine that makes more meanwhile comes again
                    reporter = ready.popleft()
                    try:
                        largest = max(largest, reporter.deliver(), reporter.inline)
                        reporter.inline = 0
                    except Exception:  # said once; the thread goes on for every other machine
                        reporter._failed(reporter.deliver, "delivering its events")
                if largest >= BUSY_BATCH:
                    time.sleep(INTERVAL)
                    continue
                self._idle = True  # before the last look: a reporter that comes after it wakes the thread
                if not ready:
                    break
                self._idle = False


    def _forget_after_fork(self) -> None:
        """In a child process made by fork: the thread did not come along; the next event starts one."""
        self.__init__()


delivery = _Delivery()
if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=delivery._forget_after_fork)
