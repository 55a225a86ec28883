"""The fan-out: how a machine's events get from its thread to every browser that watches it.

Threads: the machine's reporter gives the machine's ``Observer`` each batch of events in the
delivery's thread (fsm/observation/delivery.py), which gives them to its ``feed.Feed`` (the Status, the hand-off, the ring: fsmscope/server/feed.py); the
``Fanout`` wakes the event loop with ``call_soon_threadsafe`` when no wake-up is pending, and the
loop takes the hand-off into the ring. The loop owns the ring and the clients.

Every event is encoded once, into the machine's ring of recent events; a client is a cursor into
that ring, so the per-event work on the loop does not depend on how many clients there are, and
a client whose sender is blocked (a stalled browser) costs nothing per event. A client more than
``CLIENT_QUEUE`` events behind, or behind what the ring keeps, is sent one ``missed`` marker and
a fresh snapshot instead (coalesced state; the snapshot frame is built once per state and shared).
A sender blocked for ``SEND_TIMEOUT`` seconds gets the client evicted: its sender is cancelled
and its socket aborted (a clean close would wait for the unsent data of a stalled peer). A client
may ask for a pace (``Client.repace``): at most one frame per that many seconds, each with every
event since the last (a page looking back needs only its count of events behind).

The clients' cursors and the sender loop are one piece: they share one invariant, which client
still needs what of the ring.
"""

from __future__ import annotations

import asyncio
import collections
import contextlib
import time
from typing import Any, Callable

from fsm.observation import schema
from fsm.observation.delivery import Batch
from fsm.observation.encoding import dumps

from .feed import Feed

CLIENT_QUEUE = 4000        # events a client may lag behind before it is sent a snapshot instead
MAX_BATCH = 1000           # events per frame at most (a paced client: up to CLIENT_QUEUE)
MAX_PACE = schema.MAX_PACE_MS / 1000  # s: the slowest pace a client may ask for
SEND_TIMEOUT = 5.0         # a send that does not complete in this many seconds evicts the client
DRAIN_INTERVAL = 0.02      # s after a busy drain during which machine threads hand over without waking the loop
BUSY_DRAIN = 64            # events taken in one drain that make it a busy one

_FRAME_HEAD, _FRAME_TAIL = schema.list_frame("events")


class Client:
    """One websocket subscriber of one machine: a cursor into the feed's ring, and its sender's bookkeeping.

    A client holds no events of its own: every event is encoded once into the feed's ring and each
    sender reads from there at its own cursor. So an event costs the loop the same with any number of
    clients, and nothing at all per client that is not idle (a stalled one is blocked in its send).
    """

    __slots__ = ("feed", "cursor", "need_snapshot", "wake", "send_started", "task", "abort", "evicted",
                 "pace", "repaced", "sent_at")

    def __init__(self, feed: Feed, abort: Callable[[], None] | None) -> None:
        self.feed = feed
        self.cursor = 0  # the seq of the next event to send
        self.need_snapshot = False
        self.wake = asyncio.Event()
        self.send_started: float | None = None
        self.task: asyncio.Task | None = None
        self.abort = abort
        self.evicted = False
        self.pace = 0.0  # s between frames at least (0: each as soon as it can go)
        self.repaced = asyncio.Event()  # set when the pace changes, to end a wait for the old one
        self.sent_at = -MAX_PACE  # monotonic time of the last frame sent

    def repace(self, seconds: float) -> None:
        """Send at most one frame per ``seconds`` (0 to ``MAX_PACE``) from now on; 0: as events come."""
        self.pace = seconds
        self.repaced.set()

    async def paced(self) -> None:
        """Wait until the pace lets the next frame go (at once when it changes meanwhile)."""
        wait = self.sent_at + self.pace - time.monotonic()
        if wait <= 0:
            return
        self.repaced.clear()
        with contextlib.suppress(asyncio.TimeoutError):
            await asyncio.wait_for(self.repaced.wait(), wait)

    def take_frames(self) -> list[str]:
        """What to send next (called on the loop): events from the ring, or missed + a snapshot."""
        feed = self.feed
        if not self.need_snapshot:
            last = feed.loop_seq
            if self.cursor > last:
                return []
            batch = None
            if last - self.cursor < CLIENT_QUEUE:
                batch = feed.encoded_from(self.cursor, CLIENT_QUEUE if self.pace else MAX_BATCH)
            if batch:
                self.cursor += len(batch)
                if len(batch) == 1:
                    return [(_FRAME_HEAD + batch[0] + _FRAME_TAIL).decode()]
                return [(_FRAME_HEAD + b",".join(batch) + _FRAME_TAIL).decode()]
            # Too far behind, or what it needs is no longer kept: coalesce into a snapshot.
        seq, frame = feed.snapshot()
        frames = []
        missed = seq - self.cursor + 1 if self.cursor else 0
        if missed > 0:
            frames.append(dumps(schema.frame.missed(missed)).decode())
        if not self.cursor:  # a new client: the snapshot also carries the current run's events so far
            frame = schema.with_history(frame, feed.run_history(seq))
        frames.append(frame)
        self.need_snapshot = False
        self.cursor = seq + 1
        return frames


class Observer:
    """What a local machine's reporter gives each batch of events, in the delivery's thread
    (fsm/observation/delivery.py): the first hop of a transition on its way to the browser (the
    next is ``Feed.take_handoff``, on the loop)."""

    __slots__ = ("feed", "fanout")

    def __init__(self, feed: Feed, fanout: Fanout) -> None:
        self.feed = feed
        self.fanout = fanout

    def take_batch(self, batch: Batch) -> None:
        if self.feed.take_batch(batch):
            self.fanout.ready(self.feed)

    def next_cut(self, machine: str) -> int:
        return self.feed.next_cut()


class Fanout:
    """The loop's side: takes the feeds' hand-offs into their rings, runs each client's sender, evicts stalled ones."""

    def __init__(self) -> None:
        self.loop: asyncio.AbstractEventLoop | None = None
        self._ready: collections.deque[Feed] = collections.deque()  # feeds with a hand-off to take
        self._scheduled = False
        self._clients: set[Client] = set()
        self._watchdog: asyncio.Task | None = None

    def bind_loop(self, loop: asyncio.AbstractEventLoop) -> None:
        """Start on the loop that serves the clients (the app's lifespan)."""
        self.loop = loop
        self._watchdog = loop.create_task(self._watch())
        if self._ready:
            self._schedule()

    async def close(self) -> None:
        if self._watchdog is not None:
            self._watchdog.cancel()
        for client in list(self._clients):
            self.evict(client)

    # The hand-off from machine threads.
    def ready(self, feed: Feed) -> None:
        """In a machine's thread: ``feed`` has a hand-off for the loop to take."""
        self._ready.append(feed)
        if not self._scheduled:
            self._schedule()

    def _schedule(self) -> None:
        loop = self.loop
        if loop is None:
            return  # drained when the loop binds
        self._scheduled = True
        try:
            loop.call_soon_threadsafe(self._drain)
        except RuntimeError:  # the loop closed: the server stopped, the machine goes on
            self._scheduled = False

    def _drain(self) -> None:
        """Take every hand-off; after a large one (a busy machine), keep machine threads from waking the
        loop for ``DRAIN_INTERVAL``: under a flood the loop (and each client's sender) then runs 50 times
        a second rather than once per batch, each time taking the GIL from the machine's thread
        (bench/live_rewind.py). After a small one the next event wakes the loop at once: a machine that
        steps now and then is seen at once (bench/server.py's latency)."""
        ready = self._ready
        taken = 0
        while ready:
            taken += ready.popleft().take_handoff()
        if taken >= BUSY_DRAIN:
            self.loop.call_later(DRAIN_INTERVAL, self._reopen)
            return
        self._scheduled = False  # before looking: a hand-off that comes after this wakes the loop itself
        if ready:
            self._scheduled = True
            self.loop.call_soon(self._drain)

    def _reopen(self) -> None:
        self._scheduled = False  # before looking: a hand-off that comes after this wakes the loop itself
        if self._ready:
            self._scheduled = True
            self._drain()

    def flush(self) -> None:
        """On the loop: take whatever machine threads handed over into the rings (before reading them)."""
        if self._ready:
            self._drain()

    # Clients (on the loop).
    def subscribe(self, feed: Feed, since: int | None, abort: Callable[[], None] | None) -> Client:
        """A new client of ``feed``: from ``since`` + 1 when the ring still has it, else from a snapshot."""
        self.flush()
        client = Client(feed, abort)
        if since is not None and feed.keeps_after(since):
            client.cursor = since + 1
        else:
            client.need_snapshot = True
        feed.clients.add(client)
        self._clients.add(client)
        client.wake.set()
        return client

    def unsubscribe(self, client: Client) -> None:
        client.feed.clients.discard(client)
        client.feed.idle.discard(client)
        self._clients.discard(client)

    def evict(self, client: Client) -> None:
        if client.evicted:
            return
        client.evicted = True
        self.unsubscribe(client)
        if client.abort is not None:
            try:
                client.abort()
            except Exception:
                pass
        if client.task is not None:
            client.task.cancel()

    async def run_client(self, client: Client, send: Callable[[str], Any]) -> None:
        """The sender: one frame per event when idle, batches when events come faster (or the client's pace)."""
        try:
            while not client.evicted:
                await client.paced()
                frames = client.take_frames()
                if not frames:
                    client.wake.clear()
                    client.feed.idle.add(client)
                    await client.wake.wait()
                    continue
                for frame in frames:
                    client.send_started = client.sent_at = time.monotonic()
                    await send(frame)
                    client.send_started = None
        finally:
            self.unsubscribe(client)

    async def _watch(self) -> None:
        while True:
            await asyncio.sleep(min(1.0, SEND_TIMEOUT / 4))
            now = time.monotonic()
            for client in list(self._clients):
                started = client.send_started
                if started is not None and now - started > SEND_TIMEOUT:
                    self.evict(client)
