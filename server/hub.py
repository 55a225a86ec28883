"""The Hub: one per server. Machines by name, each with its Status, a ring of recent events and its clients.

Threads: a machine's observer runs in the machine's thread and only appends the event to a
buffer, waking the event loop with ``call_soon_threadsafe`` when no wake-up is pending.
Everything else (Status updates, the ring, fan-out to clients) happens on the loop, so the
loop is the only thread that touches a machine's Status, ring and clients.

Per client a bounded queue of encoded events; a client that falls behind has its queue
dropped and is sent one ``missed`` marker and a fresh snapshot instead (coalesced state).
A sender blocked for ``send_timeout`` seconds, or a queue that stays full that long, gets
the client evicted: its sender is cancelled and its socket aborted (a clean close would wait
for the unsent data of a stalled peer).
"""

from __future__ import annotations

import asyncio
import collections
import hashlib
import threading
import time
from typing import Any, Callable

from fsm import introspection
from fsm.encoding import dumps
from fsm.status import Status

RING_SIZE = 20000          # recent events kept per machine for since=SEQ
CLIENT_QUEUE = 4000        # events queued per client before it is sent a snapshot instead
MAX_BATCH = 1000           # events per frame at most
SEND_TIMEOUT = 5.0         # a send that does not complete in this many seconds evicts the client

_FRAME_HEAD = b'{"type":"events","events":['
_FRAME_TAIL = b"]}"


def structure_hash(root: dict | None) -> str:
    return hashlib.blake2b(dumps(root), digest_size=12).hexdigest() if root is not None else ""


def count_states(node: dict | None) -> int:
    if not node:
        return 0
    return 1 + sum(count_states(c) for c in node.get("children", ()))


class Client:
    """One websocket subscriber of one machine: its bounded queue and its sender's bookkeeping."""

    __slots__ = ("entry", "pending", "need_snapshot", "missed", "wake", "overflow_since", "send_started",
                 "task", "abort", "evicted", "address")

    def __init__(self, entry: MachineEntry, abort: Callable[[], None] | None, address: str) -> None:
        self.entry = entry
        self.pending: collections.deque[bytes] = collections.deque()
        self.need_snapshot = False
        self.missed = 0
        self.wake = asyncio.Event()
        self.overflow_since: float | None = None
        self.send_started: float | None = None
        self.task: asyncio.Task | None = None
        self.abort = abort
        self.evicted = False
        self.address = address

    def push(self, encoded: bytes) -> None:
        if self.need_snapshot:
            self.missed += 1
            return
        if len(self.pending) >= CLIENT_QUEUE:
            self.missed += len(self.pending) + 1
            self.pending.clear()
            self.need_snapshot = True
            self.overflow_since = time.monotonic()
            return
        self.pending.append(encoded)

    def take_frames(self) -> list[str]:
        """What to send next (called on the loop; the snapshot is taken here, atomically)."""
        if self.need_snapshot:
            frames = []
            if self.missed:
                frames.append('{"type":"missed","count":%d}' % self.missed)
            frames.append(self.entry.snapshot_frame())
            self.need_snapshot = False
            self.missed = 0
            self.overflow_since = None
            self.pending.clear()
            return frames
        if not self.pending:
            return []
        pending = self.pending
        if len(pending) == 1:
            batch = [pending.popleft()]
        else:
            n = min(len(pending), MAX_BATCH)
            batch = [pending.popleft() for _ in range(n)]
        return [(_FRAME_HEAD + b",".join(batch) + _FRAME_TAIL).decode()]


class MachineEntry:
    """A machine known to the hub: local (observed in this process) or ingested from another one."""

    def __init__(self, hub: Hub, name: str, source: str) -> None:
        self.hub = hub
        self.name = name
        self.source = source
        self.status = Status(name)
        self.ring: collections.deque[tuple[int, bytes]] = collections.deque(maxlen=RING_SIZE)
        self.clients: set[Client] = set()
        self.handle: Any = None  # server.control.MachineHandle for local machines
        self.reporter: introspection.Reporter | None = None
        self._structure_id: int | None = None
        self._structure_hash = ""
        self._n_states = 0

    # Read on the loop.
    def structure_info(self) -> tuple[str, int]:
        root = self.status.structure
        if id(root) != self._structure_id:
            self._structure_id = id(root)
            self._structure_hash = structure_hash(root)
            self._n_states = count_states(root)
        return self._structure_hash, self._n_states

    def snapshot_dict(self) -> dict:
        return {"type": "snapshot", "status": self.status.to_dict(), "last_seq": self.status.last_seq}

    def snapshot_frame(self) -> str:
        return dumps(self.snapshot_dict()).decode()

    def running(self) -> bool:
        if self.handle is not None:
            return self.handle.is_running()
        return self.status.running

    def events_after(self, since: int) -> list[bytes] | None:
        """Encoded events with seq > since, or None when some of them are no longer kept."""
        last = self.status.last_seq
        if since == last:
            return []
        if since > last or not self.ring:
            return None
        first = self.ring[0][0]
        if since + 1 < first:
            return None
        idx = since + 1 - first
        ring = self.ring
        if idx < len(ring) and ring[idx][0] == since + 1:
            return [ring[i][1] for i in range(idx, len(ring))]
        return [enc for seq, enc in ring if seq > since]

    def reset(self, status: Status) -> None:
        """A new epoch (an ingesting process restarted, or sent a snapshot): clients start over."""
        self.status = status
        self.ring.clear()
        for client in self.clients:
            client.pending.clear()
            client.need_snapshot = True
            client.wake.set()

    def apply(self, event: dict) -> None:
        """On the loop: update the Status, keep the event, queue it for every client."""
        self.status.apply(event)
        encoded = dumps(event)
        self.ring.append((event["seq"], encoded))
        for client in self.clients:
            client.push(encoded)
            client.wake.set()


class Hub:
    """Machines by name; created with the event loop that serves them (``bind_loop``)."""

    def __init__(self) -> None:
        self.loop: asyncio.AbstractEventLoop | None = None
        self._machines: dict[str, MachineEntry] = {}
        self._lock = threading.Lock()
        self._incoming: collections.deque[tuple[MachineEntry, dict]] = collections.deque()
        self._scheduled = False
        self._watchdog: asyncio.Task | None = None
        self._hook: Callable | None = None
        self.scene_url: str | None = None  # a 3D view served beside the dashboard (the sim demo's viser)

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
                  can_start: bool = True) -> MachineEntry:
        """Observe ``machine`` (any thread). A machine already observed keeps its reporter's name."""
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
        entry.handle = MachineHandle(machine, rep, can_start)
        entry.status.apply({"seq": rep.last_seq, "kind": "structure", "path": rep.root_path, "run": rep.run,
                            "root": rep.structure()})
        incoming = self._incoming
        schedule = self._schedule

        def observer(event: dict) -> None:
            incoming.append((entry, event))
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
            entry, event = incoming.popleft()
            entry.apply(event)

    def flush(self) -> None:
        """On the loop: apply whatever machine threads handed over (before reading a Status)."""
        if self._incoming:
            self._drain()

    # Ingest (on the loop).
    def ingest(self, event: dict) -> str | None:
        """Apply one event from another process; returns an error text for a refused event."""
        name = event["machine"]
        with self._lock:
            entry = self._machines.get(name)
            if entry is None:
                entry = self._machines[name] = MachineEntry(self, name, "ingest")
        if entry.source != "ingest":
            return "machine %r is served by this process" % name
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
            client.pending.extend(after)
        entry.clients.add(client)
        client.wake.set()
        return client

    def unsubscribe(self, client: Client) -> None:
        client.entry.clients.discard(client)

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
                    full = client.overflow_since
                    if (started is not None and now - started > SEND_TIMEOUT) or \
                            (full is not None and now - full > SEND_TIMEOUT):
                        self.evict(client)
