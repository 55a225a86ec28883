"""One machine's stream: its Status, the hand-off from its threads, the ring of its encoded events,
and the sinks that take each event besides (docs/architecture.md; the loop's side is fsmscope/server/fanout.py).

A local machine's reporter gives ``Feed.take_batch`` its events in batches, on the delivery's
thread (fsm/observation/delivery.py, through ``fanout.Observer``), encoded once for every observer
and folded into the Status, which is the reporter's (``fold_by``: ``Reporter.folded_status``, the
one fold that the recorder's snapshots read too), under the reporter's lock, which is then the
feed's ``lock``. The feed gives them to the sinks registered (``add_sink``: the timeline index, a
Zenoh robot publishing the machine) and appends them to the bounded hand-off. A feed given events
from another process (``apply``, on the loop) folds its own Status under its own lock. Either way
the Status is never behind what the feed was given and never depends on the loop keeping up. When
the loop does not drain fast enough and the hand-off would hold more than ``HANDOFF_LIMIT``
events, they are dropped (counted): the ring then has a gap, and every client behind it is sent
``missed`` and a snapshot, taken from the Status, which is always complete. The loop owns the ring
and the clients; it reads the Status under the lock.

One sink sees the Status itself, under the lock: the keeper of copies of the Status
(``keep_status``: the past's keyframes, fsmscope/server/history.py), as it is before the event of
the seq it asked for (a local machine's batch ends there: ``next_cut``).
"""

from __future__ import annotations

import asyncio
import collections
import operator
import threading
from typing import Any, Callable, Protocol, Sequence

from fsm.observation import schema
from fsm.observation.delivery import Batch
from fsm.observation.encoding import dumps
from fsm.observation.status import Status

RING_SIZE = 20000          # recent events kept per machine for since=SEQ
HISTORY = schema.HISTORY_LIMIT  # events of the current run a new client is sent for its log, at most
HANDOFF_LIMIT = 20000      # encoded events waiting for the loop, per machine, before they are dropped

Item = tuple[int, bytes]  # an event as the ring keeps it: (seq, its JSON)
_SEQ = operator.itemgetter("seq")
EventSink = Callable[[Sequence[dict]], None]
EncodedSink = Callable[[Sequence[Item]], None]
# Given the Status (holding the lock) before an event whose seq is at least the one it asked for, and
# whether the feed starts over (a new Status): returns the seq of the next event it wants to see it before.
StatusKeeper = Callable[[Status, bool], int]


class Subscriber(Protocol):
    """What the feed knows of a client (fanout.Client): a flag to send a snapshot next, an event to wake it."""

    need_snapshot: bool
    wake: asyncio.Event


def status_answer(status: Status) -> dict:
    """What GET .../status answers for ``status``: its dict without the structure, with ``preempt_waiting_on``."""
    data = status.to_dict()
    data.pop("structure", None)
    data["preempt_waiting_on"] = status.preempt_waiting_on()
    return data


def _keep_nothing(status: Status, fresh: bool) -> int:
    return 1 << 62


class Feed:
    """One machine's stream: its Status, the hand-off from its threads, the ring of encoded events, its clients."""

    def __init__(self, name: str) -> None:
        self.status = Status(name)
        self.lock: Any = threading.Lock()  # guards the Status; for a local machine its reporter's (fold_by)
        self._handing = threading.Lock()  # guards the hand-off
        self.handoff: collections.deque[Item] = collections.deque()  # machine thread -> loop
        self.dropped = 0  # events dropped from the hand-off since the loop last drained it
        self.queued = False  # the feed waits in the fan-out's ready queue
        self.ring: collections.deque[Item] = collections.deque(maxlen=RING_SIZE)
        self.loop_seq = 0  # the seq of the newest event the loop has taken (the ring's end, gaps or not)
        self.clients: set[Subscriber] = set()
        self.idle: set[Subscriber] = set()  # clients whose sender waits for the next event
        self._snapshot: tuple[int, int, str] | None = None  # (id(status), last_seq, frame)
        self._event_sinks: tuple[EventSink, ...] = ()
        self._encoded_sinks: tuple[EncodedSink, ...] = ()
        self._keeper: StatusKeeper = _keep_nothing
        self._next_kept = 1 << 62  # the seq before which the keeper wants to see the Status next

    # The sinks (registered before events come: the composition's, fsmscope/server/hub.py and fsmscope/server/cli/).
    def add_sink(self, sink: EventSink) -> None:
        """``sink(events)`` with every event from now on, in order: a local machine's in batches."""
        self._event_sinks += (sink,)

    def replace_sink(self, old: EventSink, new: EventSink) -> None:
        self._event_sinks = tuple(new if sink == old else sink for sink in self._event_sinks)

    def add_encoded_sink(self, sink: EncodedSink) -> None:
        """``sink([(seq, JSON), ...])`` with every batch of events from now on, in order: one that keeps or
        sends their bytes (one call per batch, not per event: a busy machine pays for each call)."""
        self._encoded_sinks += (sink,)

    def keep_status(self, keeper: StatusKeeper) -> None:
        """``keeper`` sees the Status, holding the lock, before the events it asks for (one keeper)."""
        with self.lock:
            self._keeper = keeper
            self._next_kept = 0  # the first event applied takes one of the state before it

    def fold_by(self, status: Status, lock: Any) -> None:
        """A local machine: ``status`` is the one its reporter folds (``Reporter.folded_status``) before
        the feed is given each batch, read holding ``lock``, the reporter's, which the caller holds."""
        self.status, self.lock = status, lock
        if self._next_kept <= status.last_seq + 1:
            self._next_kept = self._keeper(status, False)

    # In the delivery's thread (fsm/observation/delivery.py), holding the lock.
    def take_batch(self, batch: Batch) -> bool:
        """A local machine's events, folded into the Status and encoded (once for every observer): give
        them to the sinks, let the keeper see the Status, hand them over; True when the loop must be told."""
        events = batch.events
        items = list(zip(map(_SEQ, events), batch.encoded()))
        for sink in self._event_sinks:
            sink(events)
        for sink in self._encoded_sinks:
            sink(items)
        if self.status.last_seq + 1 >= self._next_kept:  # the Status is after the batch's last event
            self._next_kept = self._keeper(self.status, False)
        with self._handing:
            handoff = self.handoff
            if len(handoff) + len(items) > HANDOFF_LIMIT:  # the loop is not keeping up: drop, clients get a snapshot
                self.dropped += len(handoff)
                handoff.clear()
            handoff.extend(items)
            if self.queued:
                return False
            self.queued = True
            return True

    def next_cut(self) -> int:
        """The seq after which the keeper wants to see the Status: a batch ends there."""
        return self._next_kept - 1

    # On the loop.
    def take_handoff(self) -> int:
        """Move what the machine threads handed over into the ring; wake idle senders. Returns how many."""
        with self._handing:
            items, self.handoff = self.handoff, collections.deque()
            dropped, self.dropped = self.dropped, 0
            self.queued = False
        if not items:
            return 0
        if dropped:  # a gap: clients whose cursor falls in it are sent missed + a snapshot
            self.ring.clear()
        self.ring.extend(items)
        self.loop_seq = items[-1][0]
        if self.idle:
            self.wake_idle()
        return len(items)

    def apply(self, event: dict) -> None:
        """An event from another process: update the Status, keep the event (encoded once), wake idle senders."""
        seq = event["seq"]
        with self.lock:
            if seq >= self._next_kept:
                self._next_kept = self._keeper(self.status, False)
            self.status.apply(event)
        for sink in self._event_sinks:
            sink((event,))
        item = (seq, dumps(event))
        for sink in self._encoded_sinks:
            sink((item,))
        self.ring.append(item)
        self.loop_seq = seq
        if self.idle:
            self.wake_idle()

    def reset(self, status: Status) -> None:
        """A new epoch (an ingesting process restarted, or sent a snapshot): clients start over."""
        with self.lock:
            self.status = status
            self._next_kept = self._keeper(status, True)
        self.ring.clear()
        self.loop_seq = status.last_seq
        for client in self.clients:
            client.need_snapshot = True
        self.wake_idle()

    def wake_idle(self) -> None:
        idle = self.idle
        if idle:
            for client in idle:
                client.wake.set()
            idle.clear()

    def status_dict(self) -> dict:
        """GET .../status's answer for the Status now (``status_answer``), consistent: machine threads
        apply events to it concurrently."""
        with self.lock:
            return status_answer(self.status)

    def snapshot(self) -> tuple[int, str]:
        """(last_seq, the snapshot frame): built once per state, shared by every client that needs it."""
        with self.lock:
            status = self.status
            cached = self._snapshot
            if cached is not None and cached[0] == id(status) and cached[1] == status.last_seq:
                return cached[1], cached[2]
            data = status.to_dict()
            key = (id(status), status.last_seq)
        frame = dumps(schema.frame.snapshot(data, key[1])).decode()
        self._snapshot = (key[0], key[1], frame)
        return key[1], frame

    def run_history(self, upto: int) -> bytes:
        """The current run's events up to ``upto`` (from the ring, the newest ``HISTORY`` at most), as a
        snapshot's encoded ``history``; its ``complete`` says whether it reaches back to the run's start."""
        with self.lock:
            start = self.status.run_seq
        ring = self.ring
        first = ring[0][0] if ring else upto + 1
        events = [data for seq, data in ring if start <= seq <= upto]
        complete = first <= start and len(events) <= HISTORY
        return schema.encoded_history(complete, events[-HISTORY:])

    def keeps_after(self, since: int) -> bool:
        """Whether the ring still holds every event after ``since`` (a client can resume from there)."""
        return since <= self.status.last_seq and self.encoded_from(since + 1, 1) is not None

    def encoded_from(self, seq: int, limit: int) -> list[bytes] | None:
        """Up to ``limit`` encoded events from ``seq`` on; None when ``seq`` is no longer kept."""
        ring = self.ring
        if seq > self.loop_seq:
            return []
        if not ring:
            return None
        first = ring[0][0]
        if seq < first:
            return None
        idx = seq - first
        if idx >= len(ring) or ring[idx][0] != seq:  # seqs with a gap: find it the slow way
            for idx, (s, _) in enumerate(ring):
                if s >= seq:
                    break
            else:
                return []
        stop = min(len(ring), idx + limit)
        return [ring[i][1] for i in range(idx, stop)]
