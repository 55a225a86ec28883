"""A machine's past: the status after any event, and its events page by page (docs/api.md, "Time travel").

``History`` (one per hub entry, ``entry.past``) answers from two places:

* memory: the feed's ring of encoded events (feed.Feed.ring, the newest ``RING_SIZE``) and the
  ``Keyframes`` it keeps of the feed's Status (a ``Status.to_dict()`` every ``KEYFRAME_EVERY``
  events, taken as the feed applies them), so the recent past costs at most one keyframe copy plus
  ``KEYFRAME_EVERY`` events to apply;
* disk, for anything older: the recording, read by ``LogHistory(path, machine)``
  (fsmscope/server/log_history.py).

Without a recording, history reaches back as far as the ring: older seqs are ``Refused``
410 "history reaches back to seq X". The loop owns the ring, so ``History.view()`` copies what
memory holds (references only) on the loop, and the copy (``HistoryView``) does the work anywhere,
a route's thread pool included. A page or a seek crosses from one to the other at the seam
``HistoryView`` keeps.
"""

from __future__ import annotations

import bisect
import collections
import os
from dataclasses import dataclass
from operator import itemgetter
from typing import TYPE_CHECKING, Any, Iterator

from fsm.control.controls import Refused
from fsm.observation.encoding import dumps, loads
from fsm.observation.status import Status

from .feed import RING_SIZE, status_answer
from .log_history import Found, LogHistory

if TYPE_CHECKING:
    from .feed import Feed

SCAN_BUDGET = 200_000  # events of the machine one page examines at most; beyond, it stops with more/next
MAX_LIMIT = 10_000  # events per page at most
DEFAULT_LIMIT = 1000
KEYFRAME_EVERY = 1000  # a copy of the Status every this many events, for the status at a seq the ring holds

_seq_of = itemgetter(0)


# Memory, and the two together.

class Keyframes:
    """Copies of a feed's Status, (seq, ``Status.to_dict()`` after it), one every ``KEYFRAME_EVERY``
    events: as many as span the ring. The feed calls ``keep`` holding its lock (``Feed.keep_status``)."""

    def __init__(self) -> None:
        self.kept: collections.deque[tuple[int, dict]] = collections.deque(maxlen=RING_SIZE // KEYFRAME_EVERY + 2)

    def keep(self, status: Status, fresh: bool) -> int:
        """Keep a copy of ``status`` as it is now (``fresh``: a new epoch, the older ones go); returns the
        seq before which the next is wanted."""
        if fresh:
            self.kept.clear()
        self.kept.append((status.last_seq, status.to_dict()))
        return status.last_seq + KEYFRAME_EVERY


@dataclass(frozen=True)
class Recent:
    """What a feed holds, copied on the loop: its ring, its usable keyframes, the seqs they cover."""

    ring: list[tuple[int, bytes]]
    keyframes: list[tuple[int, dict]]
    first: int | None  # the oldest seq answered from memory (None: nothing)
    last: int  # the newest event the ring holds

    @classmethod
    def of(cls, feed: Feed, kept: Keyframes) -> Recent:
        """On the loop (which owns the ring), after ``Fanout.flush``."""
        ring = list(feed.ring)
        with feed.lock:
            keyframes = list(kept.kept) or [(feed.status.last_seq, feed.status.to_dict())]
        last = feed.loop_seq
        ring_first = ring[0][0] if ring else None
        # A keyframe is usable when every event after it is in the ring (and the ring is not behind it).
        keyframes = [k for k in keyframes if k[0] <= last and (ring_first is None or k[0] >= ring_first - 1)]
        if not keyframes:
            return cls(ring, [], None, last)
        return cls(ring, keyframes, max(keyframes[0][0], ring_first) if ring else keyframes[0][0], last)

    def status_at(self, seq: int) -> Status:
        keyframes = self.keyframes
        seq0, data = keyframes[bisect.bisect_right(keyframes, seq, key=_seq_of) - 1]
        status = Status.from_dict(data)
        ring = self.ring
        for i in range(bisect.bisect_right(ring, seq0, key=_seq_of), bisect.bisect_right(ring, seq, key=_seq_of)):
            status.apply(loads(ring[i][1]))
        return status

    def seq_at(self, t: float) -> int | None:
        ring = self.ring
        i0 = bisect.bisect_left(ring, self.first, key=_seq_of)
        i = bisect.bisect_right(ring, t, lo=i0, key=lambda item: loads(item[1])["t"])
        if i > i0:
            return ring[i - 1][0]
        seq0, data = self.keyframes[0]  # the state before the ring's first event may be kept too
        kept_t = data.get("last_t")
        if seq0 == self.first and kept_t is not None and kept_t <= t:
            return seq0
        return None

    def events(self, since: int, until: int, descending: bool) -> Iterator[Found]:
        ring = self.ring
        lo = bisect.bisect_left(ring, since, key=_seq_of)
        hi = bisect.bisect_right(ring, until, key=_seq_of)
        for i in (range(hi - 1, lo - 1, -1) if descending else range(lo, hi)):
            yield ring[i][0], ring[i][1], None


@dataclass(frozen=True)
class Page:
    """A page of events, encoded once: ``to_json()`` is GET .../history's answer."""

    events: list[bytes]
    first_seq: int | None
    last_seq: int | None
    more: bool
    next: int | None

    def to_json(self) -> bytes:
        return b'{"events":[%s],"first_seq":%s,"last_seq":%s,"more":%s,"next":%s}' % (
            b",".join(self.events), dumps(self.first_seq), dumps(self.last_seq), dumps(self.more), dumps(self.next))

    def to_dict(self) -> dict:
        return loads(self.to_json())


class HistoryView:
    """History as it stood when ``History.view()`` was taken: safe to use from any thread."""

    def __init__(self, recent: Recent | None, log: LogHistory | None) -> None:
        self.recent = recent
        self.log = log

    def span(self) -> dict:
        """{"first_seq", "last_seq"}: the oldest and newest seq it answers for (None, None: no events)."""
        recent, log = self.recent, self.log
        on_disk = log.first() if log is not None else None
        if recent is None:
            last = log.last() if log is not None else None
            return {"first_seq": on_disk and on_disk[0], "last_seq": last and last[0]}
        first = recent.first
        if on_disk is not None and (first is None or on_disk[0] < first):
            first = on_disk[0]
        return {"first_seq": first, "last_seq": recent.last}

    def status_at(self, seq: int | None = None, t: float | None = None) -> dict:
        """GET .../status?seq= (or ?t=): the status after event ``seq`` (or the last one at or before ``t``)."""
        if (seq is None) == (t is None):
            raise Refused(422, "give seq or t, not both")
        span = self.span()
        if t is not None:
            seq = self.seq_at(t)
        first, last = span["first_seq"], span["last_seq"]
        if last is None or seq > last:
            raise Refused(416, "seq %d is beyond the last event (%s)" % (seq, "none" if last is None else last))
        if first is None or seq < first:
            raise _gone(first)
        recent = self.recent
        if recent is not None and recent.first is not None and seq >= recent.first:
            return status_answer(recent.status_at(seq))
        if self.log is None:
            raise _gone(recent.first if recent is not None and recent.first is not None else first)
        return status_answer(self.log.status_at(seq))

    def seq_at(self, t: float) -> int:
        """The seq of the last event at or before time ``t``; 410 when ``t`` is before everything kept."""
        recent, log = self.recent, self.log
        seq = recent.seq_at(t) if recent is not None and recent.first is not None else None
        if seq is None and log is not None:
            seq = log.seq_at(t)
        if seq is None:
            first = self.span()["first_seq"]
            if first is None:
                raise Refused(416, "there are no events yet")
            raise Refused(410, "t %r is before what history keeps: it reaches back to seq %d" % (t, first))
        return seq

    def page(self, since: int | None = None, until: int | None = None, limit: int = DEFAULT_LIMIT,
             kinds: set[str] | None = None, path: str | None = None, order: str = "asc") -> Page:
        """GET .../history: events with ``since`` <= seq <= ``until``, at most ``limit``, oldest first;
        ``order="desc"``: the newest ``limit`` of the range (still oldest first), for paging backwards.
        ``next`` is the ``since`` (asc) or ``until`` (desc) of the next page."""
        if not 1 <= limit <= MAX_LIMIT:
            raise Refused(422, "limit must be between 1 and %d" % MAX_LIMIT)
        if since is not None and until is not None and since > until:
            raise Refused(422, "since (%d) is after until (%d)" % (since, until))
        span = self.span()
        first, last = span["first_seq"], span["last_seq"]
        if first is None or last is None:
            return Page([], first, last, False, None)
        if until is not None and until < first:
            raise _gone(first)
        since, until = max(first if since is None else since, first), min(last if until is None else until, last)
        if since > until:
            return Page([], first, last, False, None)
        descending = order == "desc"
        events, more, following = [], False, None
        examined = 0
        for seq, raw, event in self._events(since, until, descending):
            if kinds is not None or path is not None:
                event = event if event is not None else loads(raw)
                matches = (kinds is None or event["kind"] in kinds) and (path is None or event["path"] == path)
            else:
                matches = True
            if matches:
                if len(events) == limit:
                    more, following = True, seq
                    break
                events.append(raw)
            examined += 1
            if examined >= SCAN_BUDGET and seq != (since if descending else until):
                more, following = True, seq - 1 if descending else seq + 1
                break
        if descending:
            events.reverse()
        return Page(events, first, last, more, following)

    def events(self, since: int, until: int) -> Iterator[dict]:
        """The events with ``since`` <= seq <= ``until`` (within the span), oldest first, decoded."""
        for _, raw, event in self._events(since, until, False):
            yield event if event is not None else loads(raw)

    def _events(self, since: int, until: int, descending: bool) -> Iterator[Found]:
        """Events in [since, until] in the order asked: memory for what it covers, the log before that."""
        recent, log = self.recent, self.log
        split = until + 1  # the oldest seq memory answers for
        if recent is not None and recent.first is not None:
            split = max(since, recent.first)
        on_disk: Iterator[Found] = iter(())
        if log is not None and since < split:
            on_disk = (log.events_desc if descending else log.events)(since, min(until, split - 1))
        in_memory = recent.events(split, until, descending) if split <= until else iter(())
        if descending:
            yield from in_memory
            yield from on_disk
        else:
            yield from on_disk
            yield from in_memory


def _gone(first: int | None) -> Refused:
    if first is None:
        return Refused(410, "no history is kept yet")
    return Refused(410, "history reaches back to seq %d" % first)


class History:
    """A hub entry's history: its feed's recent past (``feed``, None for a log alone: then it keeps no
    keyframes of it) and its recording (``log``)."""

    def __init__(self, feed: Feed | None = None, log: LogHistory | None = None) -> None:
        self.feed = feed
        self.log = log
        self.keyframes = Keyframes()
        if feed is not None:
            feed.keep_status(self.keyframes.keep)

    @classmethod
    def from_log(cls, path: str | os.PathLike, machine: str) -> History:
        """A machine served from a log alone (``fsmscope replay --serve``): everything is read from disk."""
        return cls(None, LogHistory(path, machine))

    def view(self) -> HistoryView:
        """On the loop, after ``Fanout.flush()``: a copy of what memory holds (references; cheap)."""
        return HistoryView(Recent.of(self.feed, self.keyframes) if self.feed is not None else None, self.log)

    # The same questions, for callers on the loop (tests, the CLI): the routes use a view in a thread.
    def span(self) -> dict:
        return self.view().span()

    def status_at(self, seq: int | None = None, t: float | None = None) -> dict:
        return self.view().status_at(seq, t)

    def seq_at(self, t: float) -> int:
        return self.view().seq_at(t)

    def page(self, **kwargs: Any) -> dict:
        return self.view().page(**kwargs).to_dict()
