"""One machine's events in a log on disk, read by seq or by time without reading the whole log.

``LogHistory(path, machine)`` answers from a recording (live or finished) through the recorder's
``.idx`` snapshots, or, for a log without a usable one (foreign, hand-made, stale), from a sparse
index it builds by one scan: a mark (seq, t, offset and a Status copy) every ``SPARSE_EVERY``
events. fsmscope/server/history.py puts it behind a hub entry's history (``History``).
"""

from __future__ import annotations

import bisect
import os
import threading
from typing import Any, Iterator

from fsm.logfiles.log_reader import complete_lines
from fsm.logfiles.recorder import index_path
from fsm.observation.encoding import loads
from fsm.observation.schema import validate
from fsm.observation.status import Status

SPARSE_EVERY = 2000  # a log without .idx: a mark (seq, t, offset, Status) every this many events of the machine

Found = tuple[int, bytes, "dict | None"]  # (seq, the encoded event, the event when already decoded)


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
                for _, seq, _, event in self._valid(self._head):
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
            marks = self._marks
            if marks and (last is None or marks[-1].seq > last[0]):  # a log may end at a snapshot
                last = (marks[-1].seq, marks[-1].t)
            start = max(offset, marks[-1].offset if marks else 0)
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
            marks, seqs = list(self._marks), list(self._mark_seqs)
        k = bisect.bisect_left(seqs, until)
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


def _end_of_complete_lines(path: str, offset: int) -> int:
    """The offset just past the last complete line at or after ``offset``."""
    try:
        with open(path, "rb") as handle:
            for offset, raw in complete_lines(handle, offset):
                offset += len(raw)
    except OSError:
        pass
    return offset
