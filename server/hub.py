"""The Hub: one per server. Machines by name, each with its Status, a ring of recent events and its clients.

Threads: a machine's observer runs in the machine's thread. It applies the event to the
entry's Status there (under the entry's lock, so the Status is never behind the machine and
never depends on the loop keeping up), encodes it, and appends the encoded event to the entry's
bounded hand-off buffer, waking the event loop with ``call_soon_threadsafe`` when no wake-up
is pending. When the loop does not drain fast enough and the buffer holds ``HANDOFF_LIMIT``
events, the buffered events are dropped (counted): the ring then has a gap, and every client
behind it is sent ``missed`` and a snapshot, taken from the Status, which is always complete.
The loop owns the ring and the clients; it reads the Status under the entry's lock.

Every event is encoded once, into the machine's ring of recent events; a client is a cursor into
that ring, so the per-event work on the loop does not depend on how many clients there are, and
a client whose sender is blocked (a stalled browser) costs nothing per event. A client more than
``CLIENT_QUEUE`` events behind, or behind what the ring keeps, is sent one ``missed`` marker and
a fresh snapshot instead (coalesced state; the snapshot frame is built once per state and shared).
A sender blocked for ``send_timeout`` seconds gets the client evicted: its sender is cancelled
and its socket aborted (a clean close would wait for the unsent data of a stalled peer).
"""

from __future__ import annotations

import asyncio
import collections
import hashlib
import threading
import time
from typing import Any, Callable

from fsm import introspection, schema
from fsm.observation import structure
from fsm.observation.encoding import dumps
from fsm.observation.status import Status

RING_SIZE = 20000          # recent events kept per machine for since=SEQ
CLIENT_QUEUE = 4000        # events a client may lag behind before it is sent a snapshot instead
MAX_BATCH = 1000           # events per frame at most
HISTORY = 5000             # events of the current run a new client is sent for its log, at most
SEND_TIMEOUT = 5.0         # a send that does not complete in this many seconds evicts the client
HANDOFF_LIMIT = 20000      # encoded events waiting for the loop, per machine, before they are dropped

_FRAME_HEAD = b'{"type":"events","events":['
_FRAME_TAIL = b"]}"


def structure_hash(root: dict | None) -> str:
    return hashlib.blake2b(dumps(root), digest_size=12).hexdigest() if root is not None else ""


class Client:
    """One websocket subscriber of one machine: a cursor into the machine's ring, and its sender's bookkeeping.

    A client holds no events of its own: every event is encoded once into the machine's ring and each
    sender reads from there at its own cursor. So an event costs the loop the same with any number of
    clients, and nothing at all per client that is not idle (a stalled one is blocked in its send).
    """

    __slots__ = ("entry", "cursor", "need_snapshot", "wake", "send_started", "task", "abort", "evicted",
                 "address")

    def __init__(self, entry: MachineEntry, abort: Callable[[], None] | None, address: str) -> None:
        self.entry = entry
        self.cursor = 0  # the seq of the next event to send
        self.need_snapshot = False
        self.wake = asyncio.Event()
        self.send_started: float | None = None
        self.task: asyncio.Task | None = None
        self.abort = abort
        self.evicted = False
        self.address = address

    def take_frames(self) -> list[str]:
        """What to send next (called on the loop): events from the ring, or missed + a snapshot."""
        entry = self.entry
        if not self.need_snapshot:
            last = entry.loop_seq
            if self.cursor > last:
                return []
            batch = None
            if last - self.cursor < CLIENT_QUEUE:
                batch = entry.encoded_from(self.cursor, MAX_BATCH)
            if batch:
                self.cursor += len(batch)
                if len(batch) == 1:
                    return [(_FRAME_HEAD + batch[0] + _FRAME_TAIL).decode()]
                return [(_FRAME_HEAD + b",".join(batch) + _FRAME_TAIL).decode()]
            # Too far behind, or what it needs is no longer kept: coalesce into a snapshot.
        seq, frame = entry.snapshot()
        frames = []
        missed = seq - self.cursor + 1 if self.cursor else 0
        if missed > 0:
            frames.append('{"type":"missed","count":%d}' % missed)
        if not self.cursor:  # a new client: the snapshot also carries the current run's events so far
            frame = frame[:-1] + ',"history":' + entry.history(seq) + "}"
        frames.append(frame)
        self.need_snapshot = False
        self.cursor = seq + 1
        return frames


class MachineEntry:
    """A machine known to the hub: local (observed in this process) or ingested from another one."""

    def __init__(self, hub: Hub, name: str, source: str) -> None:
        self.hub = hub
        self.name = name
        self.source = source
        self.status = Status(name)
        self.lock = threading.Lock()  # guards the Status (applied in machine threads) and the hand-off
        self.handoff: collections.deque[tuple[int, bytes]] = collections.deque()  # machine thread -> loop
        self.dropped = 0  # events dropped from the hand-off since the loop last drained it
        self.queued = False  # the entry waits in the hub's ready queue
        self.ring: collections.deque[tuple[int, bytes]] = collections.deque(maxlen=RING_SIZE)
        self.loop_seq = 0  # the seq of the newest event the loop has taken (the ring's end, gaps or not)
        self.clients: set[Client] = set()
        self.idle: set[Client] = set()  # clients whose sender waits for the next event
        self.rejected = 0  # events refused at the door (ingest) for not fitting the schema
        self.connected: bool | None = None  # ingest: whether its publisher is connected (None: not ingested)
        self.handle: Any = None  # server.control.MachineHandle for local machines
        self.reporter: introspection.Reporter | None = None
        self._structure_id: int | None = None
        self._structure_hash = ""
        self._n_states = 0
        self._snapshot: tuple[int, int, str] | None = None  # (id(status), last_seq, frame)

    # Read on the loop.
    def structure_info(self) -> tuple[str, int]:
        root = self.status.structure
        if id(root) != self._structure_id:
            self._structure_id = id(root)
            self._structure_hash = structure_hash(root)
            self._n_states = structure.count(root)
        return self._structure_hash, self._n_states

    def status_dict(self) -> dict:
        """``Status.to_dict()``, consistent (machine threads apply events to it concurrently), with the
        states a pending preempt still waits on."""
        with self.lock:
            data = self.status.to_dict()
            data["preempt_waiting_on"] = self.status.preempt_waiting_on()
        return data

    def snapshot(self) -> tuple[int, str]:
        """(last_seq, the snapshot frame): built once per state, shared by every client that needs it."""
        with self.lock:
            status = self.status
            cached = self._snapshot
            if cached is not None and cached[0] == id(status) and cached[1] == status.last_seq:
                return cached[1], cached[2]
            data = status.to_dict()
            key = (id(status), status.last_seq)
        frame = dumps({"type": "snapshot", "status": data, "last_seq": key[1]}).decode()
        self._snapshot = (key[0], key[1], frame)
        return key[1], frame

    def history(self, upto: int) -> str:
        """The current run's events up to ``upto`` (from the ring, the newest ``HISTORY`` at most), as
        JSON ``{"complete", "events"}``; ``complete`` says whether it reaches back to the run's start."""
        with self.lock:
            start = self.status.run_seq
        ring = self.ring
        first = ring[0][0] if ring else upto + 1
        events = [encoded for seq, encoded in ring if start <= seq <= upto]
        complete = first <= start and len(events) <= HISTORY
        return (b'{"complete":%s,"events":[%s]}'
                % (b"true" if complete else b"false", b",".join(events[-HISTORY:]))).decode()

    def running(self) -> bool:
        """Running as far as anyone can tell: a machine whose publisher left is not shown running."""
        if self.handle is not None:
            return self.handle.is_running()
        return self.status.running and self.connected is not False

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

    def events_after(self, since: int) -> list[bytes] | None:
        """Encoded events with seq > since, or None when some of them are no longer kept."""
        if since > self.status.last_seq:
            return None
        return self.encoded_from(since + 1, RING_SIZE)

    def reset(self, status: Status) -> None:
        """A new epoch (an ingesting process restarted, or sent a snapshot): clients start over."""
        with self.lock:
            self.status = status
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

    def apply(self, event: dict) -> None:
        """On the loop (ingest): update the Status, keep the event (encoded once, for every client), wake idle senders."""
        with self.lock:
            self.status.apply(event)
        self.ring.append((event["seq"], dumps(event)))
        self.loop_seq = event["seq"]
        if self.idle:
            self.wake_idle()

    def observe(self, event: dict) -> bool:
        """In the machine's thread: apply, encode, hand over; True when the loop must be told."""
        encoded = dumps(event)
        with self.lock:
            self.status.apply(event)
            handoff = self.handoff
            if len(handoff) >= HANDOFF_LIMIT:  # the loop is not keeping up: drop, clients get a snapshot
                self.dropped += len(handoff)
                handoff.clear()
            handoff.append((event["seq"], encoded))
            if self.queued:
                return False
            self.queued = True
            return True

    def take_handoff(self) -> None:
        """On the loop: move what the machine threads handed over into the ring; wake idle senders."""
        with self.lock:
            items, self.handoff = self.handoff, collections.deque()
            dropped, self.dropped = self.dropped, 0
            self.queued = False
        if not items:
            return
        if dropped:  # a gap: clients whose cursor falls in it are sent missed + a snapshot
            self.ring.clear()
        self.ring.extend(items)
        self.loop_seq = items[-1][0]
        if self.idle:
            self.wake_idle()


class Hub:
    """Machines by name; created with the event loop that serves them (``bind_loop``)."""

    def __init__(self) -> None:
        self.loop: asyncio.AbstractEventLoop | None = None
        self._machines: dict[str, MachineEntry] = {}
        self._lock = threading.Lock()
        self._incoming: collections.deque[MachineEntry] = collections.deque()  # entries with a hand-off to take
        self._scheduled = False
        self._watchdog: asyncio.Task | None = None
        self._hook: Callable | None = None

    # Lifecycle (the app's lifespan calls these on the loop).
    def bind_loop(self, loop: asyncio.AbstractEventLoop) -> None:
        self.loop = loop
        self._watchdog = loop.create_task(self._watch())
        if self._incoming:
            self._schedule()

    async def close(self) -> None:
        if self._watchdog is not None:
            self._watchdog.cancel()
        for entry in self.machines():
            for client in list(entry.clients):
                self.evict(client)

    # Machines.
    def machines(self) -> list[MachineEntry]:
        with self._lock:
            return list(self._machines.values())

    def get(self, name: str) -> MachineEntry | None:
        return self._machines.get(name)

    def unique_name(self, name: str) -> str:
        with self._lock:
            if name not in self._machines:
                return name
            i = 2
            while "%s-%d" % (name, i) in self._machines:
                i += 1
            return "%s-%d" % (name, i)

    def add_local(self, machine: Any, name: str | None = None, path: str = introspection.DEFAULT_ROOT_PATH,
                  can_start: bool = True, starter: Callable[[], Any] | None = None,
                  holder: Callable[[], Any] | None = None) -> MachineEntry:
        """Observe ``machine`` (any thread). A machine already observed keeps its reporter's name.

        ``starter``: what POST .../start calls (in a worker thread) instead of executing the machine
        in a new thread, for a host that runs the machine in its own loop (see control.MachineHandle).
        """
        from .control import MachineHandle

        rep = introspection.reporter_of(machine)
        with self._lock:
            for entry in self._machines.values():
                if entry.reporter is not None and entry.reporter is rep:
                    return entry
        if rep is None:
            rep = introspection.attach(machine, None, self.unique_name(name or path.rsplit("/", 1)[-1] or "SM_ROOT"),
                                       path)
        entry = MachineEntry(self, rep.machine, "local")
        entry.reporter = rep
        entry.handle = MachineHandle(machine, rep, can_start, starter, holder)
        entry.status.apply(schema.event(rep.last_seq, time.time(), rep.run, rep.machine, "structure", rep.root_path,
                                        {"root": rep.structure()}))
        entry.loop_seq = rep.last_seq
        incoming = self._incoming
        schedule = self._schedule
        observe = entry.observe

        def observer(event: dict) -> None:
            if observe(event):
                incoming.append(entry)
                if not self._scheduled:
                    schedule()

        entry.handle.observer = observer
        with self._lock:
            if entry.name in self._machines:
                raise ValueError("a machine named %r is already served" % entry.name)
            self._machines[entry.name] = entry
        rep.add_observer(observer)
        return entry

    def remove(self, name: str) -> None:
        with self._lock:
            entry = self._machines.pop(name, None)
        if entry is not None and entry.reporter is not None and entry.handle is not None:
            entry.reporter.remove_observer(entry.handle.observer)

    def observe_all(self, can_start: bool = True) -> None:
        """Serve every top-level machine this process starts from now on (``fsmscope run``)."""
        def hook(container: Any) -> None:
            self.add_local(container, can_start=can_start)
        self._hook = hook
        introspection.add_global_hook(hook)

    def stop_observing_all(self) -> None:
        if self._hook is not None:
            introspection.remove_global_hook(self._hook)
            self._hook = None

    # The hand-off from machine threads.
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
        self._scheduled = False
        incoming = self._incoming
        while incoming:
            incoming.popleft().take_handoff()

    def flush(self) -> None:
        """On the loop: take whatever machine threads handed over into the rings (before reading them)."""
        if self._incoming:
            self._drain()

    # Ingest (on the loop).
    def ingest(self, event: Any, source: str = "ingest") -> str | None:
        """Apply one event from another process (or, ``source="replay"``, from a log); returns why
        an event was refused. An event that does not fit the schema never reaches the Status."""
        problem = schema.validate(event)
        if problem:
            name = event.get("machine") if type(event) is dict else None
            entry = self._machines.get(name) if type(name) is str else None
            if entry is not None:  # one naming no known machine is only answered, not counted
                entry.rejected += 1
            return problem
        name = event["machine"]
        with self._lock:
            entry = self._machines.get(name)
            if entry is None:
                entry = self._machines[name] = MachineEntry(self, name, source)
        if entry.source != source:
            return "machine %r is served by this process as %s" % (name, entry.source)
        if event["kind"] == "snapshot":
            status = Status.from_dict(dict(event["status"], machine=name))
            status.last_seq = event["seq"]
            entry.reset(status)
            return None
        if event["seq"] <= entry.status.last_seq:
            if event.get("run") == entry.status.run and event["kind"] != "structure":
                return None  # a duplicate
            entry.reset(Status(name))  # the publishing process restarted
        entry.apply(event)
        return None

    # Clients (on the loop).
    def subscribe(self, entry: MachineEntry, since: int | None, abort: Callable[[], None] | None,
                  address: str = "") -> Client:
        self.flush()
        client = Client(entry, abort, address)
        after = entry.events_after(since) if since is not None else None
        if after is None:
            client.need_snapshot = True
        else:
            client.cursor = since + 1
        entry.clients.add(client)
        client.wake.set()
        return client

    def unsubscribe(self, client: Client) -> None:
        client.entry.clients.discard(client)
        client.entry.idle.discard(client)

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
        """The sender: one frame per event when idle, batches when events come faster."""
        try:
            while not client.evicted:
                frames = client.take_frames()
                if not frames:
                    client.wake.clear()
                    client.entry.idle.add(client)
                    await client.wake.wait()
                    continue
                for frame in frames:
                    client.send_started = time.monotonic()
                    await send(frame)
                    client.send_started = None
        finally:
            self.unsubscribe(client)

    async def _watch(self) -> None:
        while True:
            await asyncio.sleep(min(1.0, SEND_TIMEOUT / 4))
            now = time.monotonic()
            for entry in self.machines():
                for client in list(entry.clients):
                    started = client.send_started
                    if started is not None and now - started > SEND_TIMEOUT:
                        self.evict(client)
