"""Publish a machine's events to a standalone server (``fsmscope serve``) from another process.

    from server.publisher import Publisher
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

Imports only the standard library, ``websockets`` and ``fsm`` (no FastAPI).
"""

from __future__ import annotations

import collections
import sys
import threading
import time
import urllib.parse
from typing import Any

from fsm.observation import closing, schema
from fsm.observation.encoding import dumps, loads
from fsm.observation.status import Status

BUFFER = 100_000      # events held for the sender before the oldest are dropped
MAX_BATCH = 2000      # events per frame


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
    """An observer (``fsm.attach(sm, Publisher(url, token))``) that forwards events to a server."""

    def __init__(self, url: str, token: str | None = None, buffer: int = BUFFER, backoff_max: float = 5.0,
                 start: bool = True) -> None:
        self.url = ingest_url(url, token)
        self._buf: collections.deque[dict] = collections.deque(maxlen=buffer)
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._statuses: dict[str, Status] = {}
        self._backoff_max = backoff_max
        self.connected = threading.Event()
        self.sent = 0
        self.connects = 0
        self.dropped = 0
        self.rejected = 0  # events the server refused (see stderr for why)
        self._thread: threading.Thread | None = None
        closing.close_at_exit(self)
        if start:
            self.start()

    # The observer: runs in the machine's thread.
    def __call__(self, event: dict) -> None:
        buf = self._buf
        if len(buf) == buf.maxlen:
            self.dropped += 1
        buf.append(event)
        if not self._wake.is_set():
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
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(max(0.1, deadline - time.monotonic()))
        closing.closed(self)

    def flush(self, timeout: float = 5.0) -> bool:
        """Wait until every buffered event was handed to the socket; False on timeout."""
        deadline = time.monotonic() + timeout
        while (self._buf or self._busy) and time.monotonic() < deadline:
            time.sleep(0.005)
        return not self._buf

    def __enter__(self) -> Publisher:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    _busy = False

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
        return [schema.event(status.last_seq, time.time(), status.run, name, "snapshot",
                             status.root_path or "/SM_ROOT", {"status": status.to_dict()})
                for name, status in self._statuses.items() if status.last_seq]

    def _read_answers(self, ws: Any) -> None:
        """Count the server's ``rejected`` frames (it sends nothing else) without waiting."""
        while True:
            try:
                frame = loads(ws.recv(timeout=0))
            except TimeoutError:
                return
            if type(frame) is dict and frame.get("type") == "rejected":
                self.rejected += 1
                sys.stderr.write("fsmscope publisher: the server refused event %s of %s: %s\n"
                                 % (frame.get("seq"), frame.get("machine"), frame.get("reason")))

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
            self.connects += 1
            try:
                with ws:
                    self._busy = True
                    snapshots = self._snapshots()
                    if snapshots:
                        ws.send(dumps(snapshots).decode())
                    self.connected.set()
                    while not self._stop.is_set():
                        batch = self._take()
                        if batch:
                            ws.send(dumps(batch).decode())
                            self.sent += len(batch)
                            continue
                        self._read_answers(ws)
                        self._busy = False
                        self._wake.clear()
                        if not self._buf:
                            self._wake.wait(0.5)
                        self._busy = True
            except Exception:
                pass  # the server went away: reconnect
            finally:
                self._busy = False
                self.connected.clear()

    def _take_all(self) -> None:
        while self._buf:
            self._take()
