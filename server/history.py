"""A machine's past: the status after any event, and its events page by page (docs/api.md, "Time travel").

``History`` (one per hub entry, ``entry.history``) answers from two places:

* memory: the feed's ring of encoded events (fanout.Feed.ring, the newest ``RING_SIZE``) and its
  keyframes (a ``Status.to_dict()`` every ``KEYFRAME_EVERY`` events, fanout.Feed.keyframes), so
  the recent past costs at most one keyframe copy plus ``KEYFRAME_EVERY`` events to apply;
* disk, for anything older: ``LogHistory(path, machine)``, the recording, through the recorder's
  ``.idx`` snapshots, or (a log without one) a sparse index built by one scan.

Without a recording, history reaches back as far as the ring: older seqs answer ``HistoryError``
410 "history reaches back to seq X". The loop owns the ring, so ``History.view()`` copies what
memory holds (references only) on the loop, and the copy (``HistoryView``) does the work anywhere,
a route's thread pool included.

This module is one piece (about 450 lines) because both halves answer the same four questions
(status at a seq, seq at a time, a page of events, the span) over the same seq ranges, and a
page or a seek crosses from one half into the other at the seam ``HistoryView`` keeps.
"""

from __future__ import annotations

import bisect
import os
import threading
from dataclasses import dataclass
from operator import itemgetter
from typing import TYPE_CHECKING, Any, Iterator

from fsm.logfiles.log_reader import complete_lines
from fsm.logfiles.recorder import index_path
from fsm.observation.encoding import dumps, loads
from fsm.observation.schema import validate
from fsm.observation.status import Status

if TYPE_CHECKING:
    from .fanout import Feed

SPARSE_EVERY = 2000  # a log without .idx: a mark (seq, t, offset, Status) every this many events of the machine
SCAN_BUDGET = 200_000  # events of the machine one page examines at most; beyond, it stops with more/next
MAX_LIMIT = 10_000  # events per page at most
DEFAULT_LIMIT = 1000

_seq_of = itemgetter(0)
Found = tuple[int, bytes, "dict | None"]  # (seq, the encoded event, the event when already decoded)


class HistoryError(Exception):
    """A question history cannot answer: ``status`` is the HTTP status (410, 416, 422)."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status
        self.message = message


def status_answer(status: Status) -> dict:
    """What GET .../status answers for ``status``: its dict without the structure, with ``preempt_waiting_on``."""
    data = status.to_dict()
    data.pop("structure", None)
    data["preempt_waiting_on"] = status.preempt_waiting_on()
    return data


# Disk.

class Mark:
    """A point of a log to start reading from, with the machine's state there.

    Recorder logs: a snapshot line (``offset`` is the line's start, ``status`` None: read it there).
    Scanned logs: ``offset`` is just past the line of event ``seq``, ``status`` its Status dict.
    """

    __slots__ = ("seq", "t", "offset", "status")

    def __init__(self, seq: int, t: float, offset: int, status: dict | None = None) -> None:
        self.seq, self.t, self.offset, self.status = seq, t, offset, status


class LogHistory:
    """One machine's events in a log on disk (a recording, live or finished, or any JSON Lines log).

    Marks come from the recorder's ``.idx`` (read again as it grows) or, when there is no usable
    one, from one scan of the log, continued as far as each question needs. Lines that are not
    complete valid events (corrupt, cut short, another schema) are skipped; a last line still
    being written is read once it is whole. Thread-safe.

    For a recorded run served as a replay: ``History.from_log(path, machine)``.
    """

    def __init__(self, path: str | os.PathLike, machine: str, every: int = SPARSE_EVERY) -> None:
        self.path = os.fspath(path)
        self.machine = machine
        self.every = every
        self._lock = threading.Lock()
        self._marks: list[Mark] = []
        self._mark_seqs: list[int] = []
        self._mode: str | None = None  # "index" (the .idx) or "scan"; chosen at the first question
        self._idx_read = 0  # bytes of the .idx read so far
        self._scan_offset = 0  # scan mode: where the scan stopped, and the state there
        self._scan_status = Status(machine)
        self._since_mark = 0
        self._first: tuple[int, float] | None = None
        self._head = 0  # first(): read up to here without finding the machine
        self._tail: tuple[int, tuple[int, float] | None] = (0, None)  # last(): (read up to here, (seq, t) seen)

    # Questions (any thread).
    def first(self) -> tuple[int, float] | None:
        """(seq, t) of the machine's first event in the log; None when it has none yet."""
        with self._lock:
            if self._first is None:
                for offset, seq, _, event in self._valid(self._head):
                    self._first = (seq, event["t"])
                    break
                else:
                    self._head = _end_of_complete_lines(self.path, self._head)
            return self._first

    def last(self) -> tuple[int, float] | None:
        """(seq, t) of the machine's last complete event in the log (None: none yet)."""
        with self._lock:
            self._prepare(end=True)
            if self._mode == "scan":
                status = self._scan_status
                return (status.last_seq, status.last_t) if status.last_t is not None else None
            offset, last = self._tail
            start = max(offset, self._marks[-1].offset if self._marks else 0)
            for _, seq, _, event in self._valid(start):
                if event["kind"] != "snapshot":
                    last = (seq, event["t"])
            self._tail = (_end_of_complete_lines(self.path, start), last)
            return last

    def status_at(self, seq: int) -> Status:
        """The machine's state right after its last event <= ``seq`` (an empty Status before its first)."""
        with self._lock:
            self._prepare(seq=seq)
            marks = self._marks[:bisect.bisect_right(self._mark_seqs, seq)]
        status, offset = Status(self.machine), 0
        for mark in reversed(marks):
            start = self._start(mark)
            if start is not None:
                status, offset = start
                break
        for _, event_seq, _, event in self._valid(offset, status.last_seq + 1):
            if event_seq > seq:
                break
            status.apply(event)
        return status

    def seq_at(self, t: float) -> int | None:
        """The seq of the machine's last event with ``t`` <= ``t`` (times taken as non-decreasing); None: none."""
        with self._lock:
            self._prepare(t=t)
            marks = self._marks[:bisect.bisect_right(self._marks, t, key=lambda m: m.t)]
        found = marks[-1].seq if marks else None
        for _, seq, _, event in self._valid(marks[-1].offset if marks else 0):
            if event["kind"] == "snapshot":
                continue
            if event["t"] > t:
                break
            found = seq
        return found

    def events(self, since: int, until: int) -> Iterator[Found]:
        """The machine's events with ``since`` <= seq <= ``until``, oldest first (snapshots left out)."""
        with self._lock:
            self._prepare(seq=since)
            i = bisect.bisect_left(self._mark_seqs, since)
            offset = self._marks[i - 1].offset if i else 0
        for _, seq, raw, event in self._valid(offset, since):
            if seq > until:
                return
            if event["kind"] != "snapshot":
                yield seq, raw[:-1], event

    def events_desc(self, since: int, until: int) -> Iterator[Found]:
        """The same events, newest first: the log is read forward one stretch between marks at a time."""
        with self._lock:
            self._prepare(seq=until)
            marks = list(self._marks)
        k = bisect.bisect_left([m.seq for m in marks], until)
        for j in range(k, -1, -1):
            start = marks[j - 1].offset if j else 0
            end = marks[j].offset if j < len(marks) else None
            found = []  # validated only when taken, newest first: a page takes the newest `limit` of them
            for offset, seq, raw, event in self._lines(start):
                if end is not None and offset >= end:
                    break
                if seq > until and validate(event) is None:
                    break
                if since <= seq <= until:
                    found.append((seq, raw, event))
            for seq, raw, event in reversed(found):
                if event["kind"] != "snapshot" and validate(event) is None:
                    yield seq, raw[:-1], event
            if j and marks[j - 1].seq < since:
                return

    # Reading.
    def _valid(self, offset: int, since: int = 0) -> Iterator[tuple[int, int, bytes, dict]]:
        """(line offset, seq, line, event) for the machine's valid events from ``offset``; lines with a
        seq below ``since`` are passed over without validating them (a corrupt one cannot matter)."""
        for line in self._lines(offset):
            if line[1] >= since and validate(line[3]) is None:
                yield line

    def _lines(self, offset: int) -> Iterator[tuple[int, int, bytes, dict]]:
        """(line offset, seq, line, object) for each line from ``offset`` that parses as an object naming
        this machine with an integer seq: an event, unless ``validate`` says otherwise."""
        machine = self.machine
        try:
            handle = open(self.path, "rb")
        except OSError:  # not written yet, or gone: nothing to read
            return
        with handle:
            for line_offset, raw in complete_lines(handle, offset):
                try:
                    event = loads(raw)
                except ValueError:
                    continue
                if type(event) is not dict or event.get("machine") != machine:
                    continue
                seq = event.get("seq")
                if type(seq) is not int:
                    continue
                yield line_offset, seq, raw, event

    def _start(self, mark: Mark) -> tuple[Status, int] | None:
        """(the state at ``mark``, where to read on from); None when its snapshot line is unusable."""
        if mark.status is not None:
            return Status.from_dict(mark.status), mark.offset
        for offset, seq, raw, event in self._valid(mark.offset):
            if seq != mark.seq or event["kind"] != "snapshot" or offset != mark.offset:
                return None
            status = Status.from_dict(event["status"])
            status.last_seq = seq
            return status, offset + len(raw)
        return None

    # Marks (holding the lock).
    def _prepare(self, seq: int | None = None, t: float | None = None, end: bool = False) -> None:
        """Have every mark at or before ``seq`` / time ``t`` / the end of what is written."""
        if self._mode is None:
            self._read_index()
            self._mode = "index" if self._marks else "scan"
        if self._mode == "index":
            self._read_index()
        else:
            self._scan(seq, t, end)

    def _read_index(self) -> None:
        """Add the marks of the .idx lines written since the last call (none when there is no .idx)."""
        try:
            index, log = open(index_path(self.path), "rb"), open(self.path, "rb")
        except OSError:
            return
        with index, log:
            for offset, raw in complete_lines(index, self._idx_read):
                self._idx_read = offset + len(raw)
                try:
                    entry = loads(raw)
                except ValueError:
                    continue
                if type(entry) is dict and entry.get("machine") == self.machine:
                    mark = self._index_mark(entry, log)
                    if mark is not None:
                        self._add(mark)

    def _index_mark(self, entry: dict, log: Any) -> Mark | None:
        """A mark from one .idx entry, when it points at a line start of ``log`` past the previous mark."""
        seq, offset, t = entry.get("seq"), entry.get("offset"), entry.get("t")
        if type(seq) is not int or type(offset) is not int or offset <= 0:
            return None
        if self._marks and (seq <= self._marks[-1].seq or offset <= self._marks[-1].offset):
            return None
        mark = Mark(seq, t, offset)
        if type(t) not in (int, float):  # an .idx of an older recorder: the time is in the snapshot
            start = self._start(mark)
            mark.t = start[0].last_t if start is not None else None
            return mark if mark.t is not None else None
        log.seek(offset - 1)
        return mark if log.read(2) == b"\n{" else None

    def _scan(self, seq: int | None, t: float | None, end: bool) -> None:
        """Continue the scan until past ``seq`` / ``t`` (or to the end), adding a mark every ``every`` events."""
        status = self._scan_status
        if (not end and (seq is None or status.last_seq >= seq)
                and (t is None or (status.last_t is not None and status.last_t > t))):
            return
        for offset, event_seq, raw, event in self._valid(self._scan_offset):
            self._scan_offset = offset + len(raw)
            if event["kind"] == "snapshot" and event_seq <= status.last_seq:
                continue
            status.apply(event)
            self._since_mark += 1
            if self._since_mark >= self.every:
                self._since_mark = 0
                self._add(Mark(event_seq, event["t"], self._scan_offset, status.to_dict()))
            if not end and (seq is None or event_seq >= seq) and (t is None or event["t"] > t):
                return

    def _add(self, mark: Mark) -> None:
        self._marks.append(mark)
        self._mark_seqs.append(mark.seq)


# Memory, and the two together.

@dataclass(frozen=True)
class Recent:
    """What a feed holds, copied on the loop: its ring, its usable keyframes, the seqs they cover."""

    ring: list[tuple[int, bytes]]
    keyframes: list[tuple[int, dict]]
    first: int | None  # the oldest seq answered from memory (None: nothing)
    last: int  # the newest event the ring holds

    @classmethod
    def of(cls, feed: Feed) -> Recent:
        """On the loop (which owns the ring), after ``Fanout.flush``."""
        ring = list(feed.ring)
        with feed.lock:
            keyframes = list(feed.keyframes) or [(feed.status.last_seq, feed.status.to_dict())]
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
            raise HistoryError(422, "give seq or t, not both")
        span = self.span()
        if t is not None:
            seq = self.seq_at(t)
        first, last = span["first_seq"], span["last_seq"]
        if last is None or seq > last:
            raise HistoryError(416, "seq %d is beyond the last event (%s)" % (seq, "none" if last is None else last))
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
                raise HistoryError(416, "there are no events yet")
            raise HistoryError(410, "t %r is before what history keeps: it reaches back to seq %d" % (t, first))
        return seq

    def page(self, since: int | None = None, until: int | None = None, limit: int = DEFAULT_LIMIT,
             kinds: set[str] | None = None, path: str | None = None, order: str = "asc") -> Page:
        """GET .../history: events with ``since`` <= seq <= ``until``, at most ``limit``, oldest first;
        ``order="desc"``: the newest ``limit`` of the range (still oldest first), for paging backwards.
        ``next`` is the ``since`` (asc) or ``until`` (desc) of the next page."""
        if not 1 <= limit <= MAX_LIMIT:
            raise HistoryError(422, "limit must be between 1 and %d" % MAX_LIMIT)
        if since is not None and until is not None and since > until:
            raise HistoryError(422, "since (%d) is after until (%d)" % (since, until))
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


def _gone(first: int | None) -> HistoryError:
    if first is None:
        return HistoryError(410, "no history is kept yet")
    return HistoryError(410, "history reaches back to seq %d" % first)


def _end_of_complete_lines(path: str, offset: int) -> int:
    """The offset just past the last complete line at or after ``offset``."""
    try:
        with open(path, "rb") as handle:
            for offset, raw in complete_lines(handle, offset):
                offset += len(raw)
    except OSError:
        pass
    return offset


class History:
    """A hub entry's history: its feed's recent past (``feed``, None for a log alone) and its recording (``log``)."""

    def __init__(self, feed: Feed | None = None, log: LogHistory | None = None) -> None:
        self.feed = feed
        self.log = log

    @classmethod
    def from_log(cls, path: str | os.PathLike, machine: str) -> History:
        """A machine served from a log alone (``fsmscope replay --serve``): everything is read from disk."""
        return cls(None, LogHistory(path, machine))

    def view(self) -> HistoryView:
        """On the loop, after ``Fanout.flush()``: a copy of what memory holds (references; cheap)."""
        return HistoryView(Recent.of(self.feed) if self.feed is not None else None, self.log)

    # The same questions, for callers on the loop (tests, the CLI): the routes use a view in a thread.
    def span(self) -> dict:
        return self.view().span()

    def status_at(self, seq: int | None = None, t: float | None = None) -> dict:
        return self.view().status_at(seq, t)

    def seq_at(self, t: float) -> int:
        return self.view().seq_at(t)

    def page(self, **kwargs: Any) -> dict:
        return self.view().page(**kwargs).to_dict()
