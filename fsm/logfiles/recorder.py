"""Records events to a JSON Lines log (docs/events.md, "Log files"), cheaply enough to leave on.

``Recorder(path)`` is an observer: ``fsm.attach(sm, recorder)``. It takes a machine's events in
batches (``take_batch``, fsm/observation/delivery.py: the events already encoded, once for every
observer), or one at a time when called with one (``recorder(event)``), into an in-memory buffer; a
background thread appends the buffer to the file and flushes it at least every
``flush_interval`` seconds (and at once when a machine terminates, or when ``flush_bytes`` bytes
wait). ``close()`` has the machines it was attached to deliver what they made, writes what is
left and fsyncs. Nothing is ever fsynced per event.

Every ``snapshot_every`` events of a machine the recorder writes a ``snapshot`` event (the
state rebuilt by ``fsm.observation.status.Status``) and a line ``{"machine", "seq", "t", "offset"}`` in the
``<path>.idx`` sidecar, so a reader can rebuild the state at any event without reading the
log from its start (``fsm.logfiles.log_reader.seek``); a batch ends where a snapshot is due
(``next_cut``). The Status of a machine the recorder was attached to is its reporter's
(``Reporter.folded_status``: one fold per event for every reader); the recorder folds one itself
only for events given to it otherwise.

While open, the recorder holds an exclusive ``flock`` on the log: a second recorder of it (another
process's ``--append``) is refused with ``LogBusy`` rather than interleave two runs' seqs in one
file, and a reader that can take the lock knows that nobody writes the file any more
(``fsm.logfiles.log_reader.follow``).

A write that fails (a full disk) ends the recording there, said once on stderr: the log holds
the events before it (a last line cut short is skipped by readers), later events are dropped,
the machine runs on, ``close()`` raises nothing and ``failure`` says why.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from typing import Any

from ..observation import closing, encoding
from ..observation import schema
from ..observation.delivery import Batch
from ..observation.status import Status

try:
    import fcntl
except ImportError:  # not on Unix: followers fall back to an idle timeout
    fcntl = None

DEFAULT_SNAPSHOT_EVERY = 2000
DEFAULT_FLUSH_INTERVAL = 0.05  # half the 100 ms budget, so a write in progress still fits in it
DEFAULT_FLUSH_BYTES = 4 << 20  # or sooner, when this many bytes wait


if encoding.orjson is not None:
    def _dumps_line(obj: Any, _dumps: Any = encoding.orjson.dumps,
                    _opt: int = encoding.orjson.OPT_NON_STR_KEYS | encoding.orjson.OPT_APPEND_NEWLINE) -> bytes:
        return _dumps(obj, option=_opt)
else:
    def _dumps_line(obj: Any) -> bytes:
        return encoding.dumps(obj) + b"\n"


class LogBusy(OSError):
    """The log is open in another recorder (of this process or another): it is not written twice."""


def index_path(path: str | os.PathLike) -> str:
    return os.fspath(path) + ".idx"


class Recorder:
    """An observer that appends every event it is given to ``path``; thread-safe. ``new``: the log
    must not exist yet (FileExistsError), its index is written anew, and if it is closed having
    received nothing it is removed (a command that fails before it records leaves no file)."""

    def __init__(self, path: str | os.PathLike, snapshot_every: int = DEFAULT_SNAPSHOT_EVERY,
                 flush_interval: float = DEFAULT_FLUSH_INTERVAL, flush_bytes: int = DEFAULT_FLUSH_BYTES,
                 index: bool = True, new: bool = False) -> None:
        self.path = os.fspath(path)
        self.snapshot_every = max(1, int(snapshot_every))
        self.flush_interval = flush_interval
        self.flush_bytes = flush_bytes
        directory = os.path.dirname(self.path)
        if directory:
            os.makedirs(directory, exist_ok=True)
        self._new = new
        self._file = open(self.path, "xb" if new else "ab")
        if fcntl is not None:
            try:
                fcntl.flock(self._file.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                self._file.close()
                raise LogBusy("%s is being written by another recorder" % self.path) from None
        self._index = open(index_path(self.path), "wb" if new else "ab") if index else None
        self._taken = self._file.seek(0, os.SEEK_END)  # bytes handed to the writer so far
        self._lock = threading.Lock()  # guards the buffers and statuses
        self._io_lock = threading.Lock()  # one writer to the files at a time
        # Encoded lines wait in one bytearray: appending to it is about 3x cheaper than keeping
        # one bytes object per event alive until the writer takes them.
        self._buf = bytearray()
        self._index_chunks: list[bytes] = []
        self._statuses: dict[str, Status] = {}
        self._folds: set[str] = set()  # the machines whose Status the recorder folds itself
        self._folded: dict[str, Status] = {}  # the reporters' Statuses, until their machine's first event
        self._reporters: list[Any] = []  # the reporters of the machines attached: they deliver before closing
        self._snapshot_at: dict[str, int] = {}  # per machine: the seq at which to write the next snapshot
        self.lines = 0  # lines handed to the writer (events and snapshots)
        self._waiting = 0  # lines in the buffer (counted as they come: counting the buffer's newlines costs per byte)
        self.snapshots = 0
        self.machines: list[str] = []
        self._closed = False
        self.failure: OSError | None = None  # the write that ended the recording, if one did
        self._wake = threading.Event()
        self._writer = threading.Thread(target=self._write_loop, name="fsm-recorder", daemon=True)
        self._writer.start()
        closing.close_at_exit(self)

    def attached(self, reporter: Any) -> None:
        """``fsm.attach`` gave this recorder a machine: its snapshots are taken from the Status its
        reporter folds (read in ``take_batch``, which its reporter's ``deliver`` calls holding that
        Status's lock), and closing has that reporter deliver what it made first."""
        status, _ = reporter.folded_status()
        with self._lock:
            self._reporters.append(reporter)
            if reporter.machine not in self._statuses:
                self._folded[reporter.machine] = status
                self._snapshot_at[reporter.machine] = reporter.last_seq + 1 + self.snapshot_every

    def take_batch(self, batch: Batch) -> None:
        """A machine's events, encoded and folded (fsm/observation/delivery.py): one append for all of them."""
        events = batch.events
        data = batch.encoded()
        machine = batch.machine
        with self._lock:
            if self._closed or self.failure is not None:
                return
            buf = self._buf
            buf += b"\n".join(data)
            buf += b"\n"
            self._waiting += len(data)
            status = self._statuses.get(machine)
            if status is None:
                status = self._new_machine(machine, events[0]["seq"])
            if machine in self._folds:
                for event in events:
                    status.apply(event)
            if status.last_seq >= self._snapshot_at[machine]:
                self._snapshot(status)
            full = len(buf) >= self.flush_bytes
        if full or events[-1]["kind"] == "terminate":
            self._wake.set()

    def next_cut(self, machine: str) -> int | None:
        """The seq after which the next snapshot of ``machine`` is due: a batch ends there."""
        return self._snapshot_at.get(machine)

    # Given an event by hand (an import, a test): an encode, an append and one step of the reducer.
    def __call__(self, event: dict) -> None:
        data = encoding.encoded(event)
        with self._lock:
            if self._closed or self.failure is not None:
                return
            buf = self._buf
            buf += data
            buf += b"\n"
            self._waiting += 1
            machine = event["machine"]
            status = self._statuses.get(machine)
            if status is None:
                status = self._new_machine(machine, event["seq"])
            if machine in self._folds:
                status.apply(event)
            if status.last_seq >= self._snapshot_at[machine]:
                self._snapshot(status)
            full = len(buf) >= self.flush_bytes
        if full or event["kind"] == "terminate":
            self._wake.set()

    @property
    def events(self) -> int:
        """Events recorded so far (snapshots not counted)."""
        return self.lines + self._waiting - self.snapshots

    def _new_machine(self, machine: str, seq: int) -> Status:
        status = self._folded.pop(machine, None)
        if status is None:
            status = Status(machine)
            self._folds.add(machine)
        self._statuses[machine] = status
        self._snapshot_at.setdefault(machine, seq + self.snapshot_every)
        self.machines.append(machine)
        return status

    def _snapshot(self, status: Status) -> None:
        """Append the machine's rebuilt state as a snapshot event and index it (holding ``_lock``)."""
        self._snapshot_at[status.machine] = status.last_seq + self.snapshot_every
        if status.root_path is None:  # no structure seen yet: nothing a reader could start from
            return
        event = schema.build.snapshot(status.last_seq, time.time(), status.run, status.machine, status.root_path,
                                      status.to_dict())
        offset = self._taken + len(self._buf)
        self._index_chunks.append(_dumps_line({"machine": status.machine, "seq": status.last_seq, "t": status.last_t,
                                               "offset": offset}))
        self._buf += _dumps_line(event)
        self._waiting += 1
        self.snapshots += 1

    # Writing.
    def _take(self) -> tuple[bytes, bytes]:
        with self._lock:
            data, self._buf = self._buf, bytearray()
            index_chunks, self._index_chunks = self._index_chunks, []
            self._taken += len(data)
            self.lines += self._waiting
            self._waiting = 0
            return data, b"".join(index_chunks)

    def flush(self) -> None:
        """Write and flush everything recorded so far (no fsync); after a failed write, nothing."""
        with self._io_lock:
            data, index = self._take()
            if self._file.closed or self.failure is not None:
                return
            try:
                if data:
                    self._file.write(data)
                    self._file.flush()
                if index and self._index is not None:  # after the log, so an offset never points past its data
                    self._index.write(index)
                    self._index.flush()
            except OSError as exc:
                self._fail(exc)

    def _fail(self, exc: OSError) -> None:
        """The recording ends at the first write that failed: said once, the events after it dropped."""
        with self._lock:
            if self.failure is not None:
                return
            self.failure = exc
            self._buf, self._index_chunks, self._waiting = bytearray(), [], 0
        sys.stderr.write("fsm: recorder could not write %s: %s; the recording ends there\n"
                         % (self.path, exc.strerror or exc))

    def _write_loop(self) -> None:
        while not self._closed and self.failure is None:
            self._wake.wait(self.flush_interval)
            self._wake.clear()
            self.flush()

    def close(self) -> None:
        """Write what is left, fsync and close; later events are dropped. Idempotent; raises nothing
        on a failed write (``failure`` says it)."""
        if self._closed:
            return
        for reporter in list(self._reporters):
            reporter.deliver()
        with self._lock:
            if self._closed:
                return
            self._closed = True
        self._wake.set()
        if self._writer is not threading.current_thread():
            self._writer.join()
        with self._io_lock:
            data, index = self._take()
            for handle, chunk in ((self._file, data), (self._index, index)):
                if handle is None:
                    continue
                try:
                    if chunk and self.failure is None:
                        handle.write(chunk)
                    handle.flush()
                    os.fsync(handle.fileno())
                except OSError as exc:
                    self._fail(exc)
                _close_dropping_unwritten(handle)  # closing the log also releases its flock
        if self._new and os.path.getsize(self.path) == 0:
            for path in (self.path, index_path(self.path)):
                if os.path.exists(path):
                    os.remove(path)
        closing.closed(self)

    @property
    def closed(self) -> bool:
        return self._closed

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __repr__(self) -> str:
        return "Recorder(%r, events=%d%s)" % (self.path, self.events, ", closed" if self._closed else "")


def _close_dropping_unwritten(handle: Any) -> None:
    """Close ``handle``; what a failed write left in its buffer is dropped (closing tries to write
    it again, fails again, and closes the file all the same)."""
    try:
        handle.close()
    except OSError:
        pass
