"""Publish a machine's events to a standalone server (``fsmscope serve``) from another process, and
take its controls back.

    from fsmscope.server.publisher import Publisher
    fsm.attach(sm, Publisher("http://127.0.0.1:8765", token), name="picker")

The observer only appends to a bounded buffer (the machine's thread never waits for the
network). A background thread applies the events to its own ``fsm.observation.status.Status`` and sends
them in batches over the authenticated websocket ``/api/ingest``. When the server is gone,
the machine runs on: events keep being folded into the Status, and on reconnecting (with
backoff) the publisher first sends a ``snapshot`` event of each machine, then new events.

The server checks every event against the schema (``fsm.observation.schema``) and answers a refused one
with a ``rejected`` frame; the publisher counts those (``rejected``) and says why on stderr.
At exit the publisher sends what it still holds (``close()`` runs from ``atexit``), so a
script that ends right after its machine does not leave the dashboard showing it running;
``with Publisher(url, token) as pub:`` closes it at the end of the block.

Every machine attached to it takes the dashboard's controls (docs/debugging.md, "Remote machines"):
the server sends ``control`` frames over the same connection, a worker thread applies them
(fsm/control/frames.py) and the sender answers each after the events it caused. While an
operator holds a machine's lease, a connection lost for longer than the lease's ``after`` makes
the publisher apply the deadman itself.

Imports only the standard library, ``websockets`` and ``fsm`` (no FastAPI).
"""

from __future__ import annotations

import collections
import queue
import sys
import threading
import time
import urllib.parse
from typing import Any

from fsm.control.deadman import Deadmen
from fsm.control.frames import answer
from fsm.control.handle import MachineHandle
from fsm.observation import closing, introspection, schema
from fsm.observation.encoding import dumps, loads
from fsm.observation.handoff import Handoff
from fsm.observation.status import Status


BUFFER = 100_000      # events held for the sender before the oldest are dropped
MAX_BATCH = 2000      # events per frame
DEADMAN_CLIENT = "publisher"  # the client of what the publisher does on its own


def ingest_url(url: str, token: str | None) -> str:
    parts = urllib.parse.urlsplit(url)
    scheme = {"http": "ws", "https": "wss"}.get(parts.scheme, parts.scheme)
    query = urllib.parse.parse_qs(parts.query)
    if token is None and "token" in query:
        token = query["token"][0]
    path = parts.path.rstrip("/")
    if not path.endswith("/api/ingest"):
        path += "/api/ingest"
    q = urllib.parse.urlencode({"token": token}) if token else ""
    return urllib.parse.urlunsplit((scheme, parts.netloc, path, q, ""))


class Publisher:
    """An observer (``fsm.attach(sm, Publisher(url, token))``) that forwards events to a server and
    takes its controls; ``can_start``: whether the dashboard may run a machine again (in a new thread)."""

    def __init__(self, url: str, token: str | None = None, buffer: int = BUFFER, backoff_max: float = 5.0,
                 start: bool = True, can_start: bool = False) -> None:
        self.url = ingest_url(url, token)
        self.can_start = can_start
        self._handoff = Handoff(buffer)
        self._buf = self._handoff.events
        self._wake = self._handoff.wake
        self._stop = threading.Event()
        self._statuses: dict[str, Status] = {}
        self._backoff_max = backoff_max
        self._handles: dict[str, MachineHandle] = {}  # the machines attached, by name: they take controls
        self._handles_changed = 0  # bumped by each attach: the server is told again
        self._controls: queue.Queue[tuple[int, dict] | None] = queue.Queue()
        self._worker: threading.Thread | None = None
        self._answers: collections.deque[tuple[int, str, int, dict]] = collections.deque()
        self._deadmen = Deadmen(self._handles, DEADMAN_CLIENT, "the connection to the dashboard")
        self.connected = threading.Event()
        self.sent = 0
        self.connects = 0
        self.rejected = 0  # events the server refused (see stderr for why)
        self._thread: threading.Thread | None = None
        closing.close_at_exit(self)
        if start:
            self.start()

    # The observer: runs in the machine's thread.
    def __call__(self, event: dict) -> None:
        self._handoff(event)

    @property
    def dropped(self) -> int:
        """Events dropped because the buffer was full (the server was away too long)."""
        return self._handoff.dropped

    def attached(self, reporter: introspection.Reporter) -> None:
        """``fsm.attach`` gave this publisher a machine (Reporter.add_observer): it takes controls from now on."""
        self._handles[reporter.machine] = MachineHandle(reporter.root, reporter, self.can_start)
        self._handles_changed += 1
        self._wake.set()

    def start(self) -> Publisher:
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name="fsmscope-publisher", daemon=True)
            self._thread.start()
        return self

    def close(self, timeout: float = 5.0) -> None:
        """Send what is buffered (waiting up to ``timeout`` for a connection), then stop. Idempotent."""
        deadline = time.monotonic() + timeout
        if self._buf and not self._stop.is_set() and self.connected.wait(timeout):
            self.flush(max(0.0, deadline - time.monotonic()))
        self._stop.set()
        self._wake.set()
        self._deadmen.back(forget=True)
        if self._worker is not None:
            self._controls.put(None)
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(max(0.1, deadline - time.monotonic()))
        closing.closed(self)

    def flush(self, timeout: float = 5.0) -> bool:
        """Wait until every buffered event was handed to the socket; False on timeout."""
        return self._handoff.drained(timeout)

    def __enter__(self) -> Publisher:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # The sender thread.
    def _take(self) -> list[dict]:
        buf = self._buf
        batch = []
        while buf and len(batch) < MAX_BATCH:
            event = buf.popleft()
            status = self._statuses.get(event["machine"])
            if status is None:
                status = self._statuses[event["machine"]] = Status(event["machine"])
            status.apply(event)
            batch.append(event)
        return batch

    def _snapshots(self) -> list[dict]:
        return [schema.build.snapshot(status.last_seq, time.time(), status.run, name, status.root_path or "/SM_ROOT",
                                      status.to_dict())
                for name, status in self._statuses.items() if status.last_seq]

    def _hello(self) -> str:
        """Which machines take controls, sent first on every connection and again after an attach."""
        self._announced = self._handles_changed
        handles = dict(self._handles)
        return dumps(schema.frame.hello(sorted(handles),
                                        {name: handle.can_start for name, handle in handles.items()})).decode()

    _announced = -1

    def _run(self) -> None:
        from websockets.sync.client import connect

        delay = 0.1
        while not self._stop.is_set():
            try:
                ws = connect(self.url, compression=None, open_timeout=3, close_timeout=1)
            except Exception:
                self._take_all()  # keep the Status current and the buffer small while away
                self._stop.wait(delay)
                delay = min(delay * 2, self._backoff_max)
                continue
            delay = 0.1
            self._serve(ws)
            if not self._stop.is_set():
                self._deadmen.lost()

    def _serve(self, ws: Any) -> None:
        """One connection: send events and answers until it is lost or the publisher stops."""
        self.connects += 1
        connection = self.connects
        lost = threading.Event()
        self._deadmen.back(forget=True)  # the server says its leases again
        if self._worker is None:
            self._worker = threading.Thread(target=self._work, name="fsmscope-publisher-controls", daemon=True)
            self._worker.start()
        try:
            with ws:
                self._handoff.busy = True
                ws.send(self._hello())
                snapshots = self._snapshots()
                if snapshots:
                    ws.send(dumps(snapshots).decode())
                self.connected.set()
                threading.Thread(target=self._receive, args=(ws, connection, lost), name="fsmscope-publisher-receiver",
                                 daemon=True).start()
                while not self._stop.is_set() and not lost.is_set():
                    if self._announced != self._handles_changed:
                        ws.send(self._hello())
                    batch = self._take()
                    if batch:
                        ws.send(dumps(batch).decode())
                        self.sent += len(batch)
                        self._send_answers(ws, connection, every=False)
                        continue
                    self._send_answers(ws, connection, every=True)
                    self._handoff.busy = False
                    self._wake.clear()
                    if not self._buf and not self._answers:
                        self._wake.wait(0.5)
                    self._handoff.busy = True
        except Exception:
            pass  # the server went away: reconnect
        finally:
            self._handoff.busy = False
            self.connected.clear()

    def _send_answers(self, ws: Any, connection: int, every: bool) -> None:
        """Send the answers whose control events were sent (``every``: all of them, the buffer is
        empty), so a page that reads the machine right after its answer finds them there."""
        answers = self._answers
        while answers:
            asked_on, machine, due, frame = answers[0]
            status = self._statuses.get(machine)
            if asked_on == connection and not every and status is not None and status.last_seq < due:
                return
            answers.popleft()
            if asked_on == connection:  # one asked on a connection since lost has nobody to go to
                ws.send(dumps(frame).decode())

    def _take_all(self) -> None:
        while self._buf:
            self._take()

    # The receiver thread (one per connection): what the server sends.
    def _receive(self, ws: Any, connection: int, lost: threading.Event) -> None:
        try:
            for message in ws:
                self._received(message, connection)
        except Exception:
            pass  # lost: the sender reconnects
        finally:
            lost.set()
            self._wake.set()

    def _received(self, message: str | bytes, connection: int) -> None:
        """One frame from the server; one that is not JSON, or of no known type, is ignored."""
        try:
            frame = loads(message)
        except (ValueError, RecursionError):
            return
        if type(frame) is not dict:
            return
        kind = frame.get("type")
        if kind == "rejected":
            self.rejected += 1
            sys.stderr.write("fsmscope publisher: the server refused event %s of %s: %s\n"
                             % (frame.get("seq"), frame.get("machine"), frame.get("reason")))
        elif kind == "control":
            self._controls.put((connection, frame))
        elif kind == "lease" and connection == self.connects:  # not a late frame of a connection since lost
            self._deadmen.said(frame)

    # The control worker: applies controls in the order they came, off the sender and the machine.
    def _work(self) -> None:
        while True:
            item = self._controls.get()
            if item is None:
                return
            connection, frame = item
            answered = answer(dict(self._handles), frame)
            if answered is None:
                continue
            machine, reply = answered
            handle = self._handles.get(machine)
            due = handle.reporter.last_seq if handle is not None else 0
            self._answers.append((connection, machine, due, reply))
            self._wake.set()
