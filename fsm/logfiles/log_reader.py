"""Reads JSON Lines event logs: every complete event, with line-numbered problems for the rest.

* ``read_events(path)`` yields events in file order. A line that is not a complete event
  (a crash cut it short, or it is corrupt), or whose event does not fit the schema
  (``fsm.observation.schema.validate``), is skipped and reported, with its line number, to
  ``on_problem`` (and kept in ``Reader.problems``). An event of a newer schema version stops
  the read with ``SchemaError``: guessing at it would be worse.
* ``follow(path)`` does the same for a log still being written, until its writer is gone.
* ``seek(path, machine, seq)`` rebuilds one machine's state at one event from the nearest
  snapshot (found through the ``.idx`` sidecar), or by scanning when the index is missing
  or stale.
* ``complete_lines(handle, offset)`` yields the lines from a byte offset on, with their offsets,
  for readers that index a log themselves (fsmscope/server/history.py); a last line still being written
  is left for later.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from typing import Any, Callable, Iterator

from ..observation.encoding import loads
from .recorder import fcntl, index_path
from ..observation.schema import VERSION, validate
from ..observation.status import Status

SUPPORTED_VERSIONS = (VERSION,)


class LogError(Exception):
    """The log cannot be read at all (missing, a directory, unreadable)."""


class SchemaError(LogError):
    """The log holds events of a schema version this reader does not know."""


@dataclass(frozen=True)
class Problem:
    line: int
    message: str
    truncated: bool = False  # the last line, cut short (the writer was killed mid-write)

    def __str__(self) -> str:
        return "line %d: %s" % (self.line, self.message)


def _open(path: str | os.PathLike) -> Any:
    try:
        return open(path, "rb")
    except FileNotFoundError:
        raise LogError("%s: no such file" % os.fspath(path)) from None
    except IsADirectoryError:
        raise LogError("%s: is a directory" % os.fspath(path)) from None
    except OSError as exc:
        raise LogError("%s: %s" % (os.fspath(path), exc.strerror or exc)) from None


class Reader:
    """Parses lines into events, counting lines and collecting problems."""

    def __init__(self, path: str | os.PathLike, on_problem: Callable[[Problem], None] | None = None) -> None:
        self.path = os.fspath(path)
        self.on_problem = on_problem
        self.problems: list[Problem] = []
        self.lineno = 0
        self.numbered = True  # False after a seek into the middle: problems then say line 0

    def _problem(self, message: str, truncated: bool = False) -> None:
        problem = Problem(self.lineno if self.numbered else 0, message, truncated)
        self.problems.append(problem)
        if self.on_problem is not None:
            self.on_problem(problem)

    def parse(self, raw: bytes, complete: bool = True) -> dict | None:
        """One line (``complete``: it ended with a newline) -> an event, or None after reporting why."""
        self.lineno += 1
        if not raw.strip():
            if complete:
                self._problem("empty line")
            return None
        try:
            event = loads(raw)
        except ValueError as exc:
            if not complete:
                self._problem("truncated last line (%d bytes): the writer stopped mid-line" % len(raw), True)
            else:
                self._problem("not JSON: %s" % (str(exc).splitlines() or ["?"])[0])
            return None
        if type(event) is not dict:
            self._problem("not a JSON object")
            return None
        version = event.get("v")
        if version not in SUPPORTED_VERSIONS:
            if type(version) is int and version > max(SUPPORTED_VERSIONS):  # a newer fsmscope wrote it
                raise SchemaError("%s line %d: schema version %d is not supported (this fsmscope reads version %s)"
                                  % (self.path, self.lineno, version, ", ".join(map(str, SUPPORTED_VERSIONS))))
            self._problem("no schema version ('v')" if version is None else "bad schema version %r" % (version,))
            return None
        problem = validate(event)
        if problem:
            self._problem("invalid event: " + problem)
            return None
        return event

    def events(self, handle: Any) -> Iterator[dict]:
        parse = self.parse
        lineno = self.lineno
        try:
            for raw in handle:
                lineno += 1
                try:  # the fast path: a complete, valid event
                    event = loads(raw)
                    if raw[-1:] == b"\n" and validate(event) is None:
                        yield event
                        continue
                except ValueError:
                    pass
                self.lineno = lineno - 1
                event = parse(raw, raw.endswith(b"\n"))  # says what is wrong, or accepts it
                if event is not None:
                    yield event
        finally:
            self.lineno = lineno


def read_events(path: str | os.PathLike, on_problem: Callable[[Problem], None] | None = None,
                reader: Reader | None = None) -> Iterator[dict]:
    """Every complete event of the log, in file order (raises LogError / SchemaError)."""
    reader = reader or Reader(path, on_problem)
    with _open(path) as handle:
        yield from reader.events(handle)


def writer_active(path: str | os.PathLike) -> bool:
    """True while a Recorder holds the log open (it keeps an exclusive flock on it)."""
    if fcntl is None:
        return True
    try:
        with open(path, "rb") as handle:
            try:
                fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                return True
            fcntl.flock(handle.fileno(), fcntl.LOCK_UN)
            return False
    except OSError:
        return False


def follow(path: str | os.PathLike, on_problem: Callable[[Problem], None] | None = None,
           poll: float = 0.1, wait: float = 10.0, idle: float | None = None,
           stop: Callable[[], bool] | None = None, reader: Reader | None = None) -> Iterator[dict]:
    """Yield the log's events as they are appended, until its writer has closed it.

    Waits up to ``wait`` seconds for the file to appear. Without file locks (or with
    ``idle``), it also stops after ``idle`` seconds without new data. ``stop()`` ends it early.
    """
    reader = reader or Reader(path, on_problem)
    deadline = time.monotonic() + wait
    while not os.path.exists(path):
        if time.monotonic() >= deadline:
            raise LogError("%s: no such file (waited %g s)" % (os.fspath(path), wait))
        time.sleep(poll)
    if idle is None and fcntl is None:
        idle = 5.0
    with _open(path) as handle:
        partial = b""
        quiet_since = time.monotonic()
        writer_gone_once = False
        while True:
            chunk = handle.read(1 << 20)
            if chunk:
                quiet_since = time.monotonic()
                writer_gone_once = False
                lines = (partial + chunk).split(b"\n")
                partial = lines.pop()
                for raw in lines:
                    event = reader.parse(raw + b"\n")
                    if event is not None:
                        yield event
                continue
            if stop is not None and stop():
                break
            if idle is not None and time.monotonic() - quiet_since >= idle:
                break
            # The writer may have written its last bytes just before releasing the lock:
            # stop only when the lock was free on two polls in a row with nothing new between.
            if not writer_active(path):
                if writer_gone_once:
                    break
                writer_gone_once = True
            time.sleep(poll)
        if partial:
            event = reader.parse(partial, complete=False)
            if event is not None:
                yield event


# Seeking.

def complete_lines(handle: Any, offset: int = 0) -> Iterator[tuple[int, bytes]]:
    """(its offset, the line) for each complete line of ``handle`` from ``offset`` (a line's start) on.

    A last line without its newline is left out silently: its writer may be mid-write, and it
    is read whole on a later call.
    """
    handle.seek(offset)
    for raw in handle:
        if raw[-1:] != b"\n":
            return
        yield offset, raw
        offset += len(raw)


def read_index(path: str | os.PathLike) -> list[dict]:
    """The snapshot index beside a log ([] when missing; unreadable lines are ignored)."""
    entries = []
    try:
        with open(index_path(path), "rb") as handle:
            for raw in handle:
                try:
                    entry = loads(raw)
                except ValueError:
                    continue
                if type(entry) is dict and type(entry.get("offset")) is int and type(entry.get("seq")) is int:
                    entries.append(entry)
    except OSError:
        pass
    return entries


@dataclass
class SeekResult:
    status: Status
    used_index: bool  # False: the log was scanned from its start
    offset: int  # byte offset the replay of events started from


def _snapshot_at(handle: Any, offset: int, machine: str, seq: int) -> dict | None:
    """The snapshot line the index points to, or None when the index is stale."""
    try:
        handle.seek(offset)
        raw = handle.readline()
        event = loads(raw)
    except (OSError, ValueError):
        return None
    if (type(event) is dict and event.get("kind") == "snapshot" and event.get("machine") == machine
            and event.get("seq") == seq and validate(event) is None):
        return event
    return None


def seek(path: str | os.PathLike, machine: str, seq: int,
         on_problem: Callable[[Problem], None] | None = None) -> SeekResult:
    """The state of ``machine`` right after its event ``seq`` (or its last event before it).

    Starts from the latest indexed snapshot at or before ``seq``; falls back to scanning the
    whole log when there is no usable index entry. Lines are numbered from the start only
    when scanning (after a seek, problem line numbers are unknown and reported as 0).
    """
    candidates = sorted((e for e in read_index(path) if e.get("machine") == machine and e["seq"] <= seq),
                        key=lambda e: e["seq"], reverse=True)
    with _open(path) as handle:
        for entry in candidates[:3]:
            snapshot = _snapshot_at(handle, entry["offset"], machine, entry["seq"])
            if snapshot is None:
                continue
            status = Status.from_dict(snapshot["status"])
            status.last_seq = snapshot["seq"]
            reader = Reader(path, on_problem)
            reader.numbered = False
            _apply_until(reader.events(handle), status, machine, seq)
            return SeekResult(status, True, entry["offset"])
        handle.seek(0)
        status = Status(machine)
        _apply_until(Reader(path, on_problem).events(handle), status, machine, seq)
        return SeekResult(status, False, 0)


def _apply_until(events: Iterator[dict], status: Status, machine: str, seq: int) -> None:
    apply = status.apply
    for event in events:
        if event["machine"] != machine:
            continue
        event_seq = event["seq"]
        if event_seq > seq:
            break
        if event["kind"] == "snapshot" and event_seq <= status.last_seq:
            continue
        apply(event)
