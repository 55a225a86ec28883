"""The Hub, one per server: the machines it shows, by name, and the fan-out that streams their events.

A machine is local (observed in this process: ``add_local`` attaches a ``fanout.Observer`` to its
reporter), ingested (another process publishes its events to /api/ingest) or replayed (from a log).
Each ``MachineEntry`` is the machine's ``fanout.Feed`` plus what the routes need to show and
control it. How events reach the browsers is server/fanout.py.
"""

from __future__ import annotations

import asyncio
import hashlib
import threading
import time
from typing import TYPE_CHECKING, Any, Callable

from fsm.control.handle import MachineHandle
from fsm.observation import introspection, names, schema
from fsm.observation import structure
from fsm.observation.encoding import dumps
from fsm.observation.status import Status

from .fanout import Fanout, Feed, Observer
from .history import History, LogHistory
from .state_stats import StateStats

if TYPE_CHECKING:
    from .remote_control import RemoteHandle


def structure_hash(root: dict | None) -> str:
    return hashlib.blake2b(dumps(root), digest_size=12).hexdigest() if root is not None else ""


class MachineEntry(Feed):
    """A machine known to the hub: its feed, where it comes from, and (local ones) its control handle."""

    def __init__(self, name: str, source: str) -> None:
        super().__init__(name)
        self.name = name
        self.source = source
        self.rejected = 0  # events refused at the door (ingest) for not fitting the schema
        self.connected: bool | None = None  # ingest: whether its publisher is connected (None: not ingested)
        self.robot: str | None = None  # a fleet machine's robot (its name is "<robot>:<machine>")
        self.handle: MachineHandle | None = None  # local machines only
        self.remote: RemoteHandle | None = None  # ingested ones whose publisher takes controls (remote_control.py)
        self.replay: dict | None = None  # replayed from a log: {"speed": the page's initial play speed}
        self.reporter: introspection.Reporter | None = None
        self.observer: Observer | None = None
        self.history = History(self)  # its past (server/history.py): the ring, and a recording when it has one
        self.stats = StateStats(name)  # its states' statistics, counted when asked (server/state_stats.py)
        self._structure_id: int | None = None
        self._structure_hash = ""
        self._n_states = 0

    def structure_info(self) -> tuple[str, int]:
        """(a hash of the structure, its number of states), computed once per structure."""
        root = self.status.structure
        if id(root) != self._structure_id:
            self._structure_id = id(root)
            self._structure_hash = structure_hash(root)
            self._n_states = structure.count(root)
        return self._structure_hash, self._n_states

    def running(self) -> bool:
        """Running as far as anyone can tell: a machine whose publisher left is not shown running."""
        if self.handle is not None:
            return self.handle.is_running()
        return self.status.running and self.connected is not False


class Hub:
    """Machines by name; served on the event loop given to ``bind_loop``."""

    def __init__(self) -> None:
        self.fanout = Fanout()
        self._machines: dict[str, MachineEntry] = {}
        self._lock = threading.Lock()

    @property
    def loop(self) -> asyncio.AbstractEventLoop | None:
        return self.fanout.loop

    # Lifecycle (the app's lifespan calls these on the loop).
    def bind_loop(self, loop: asyncio.AbstractEventLoop) -> None:
        self.fanout.bind_loop(loop)

    async def close(self) -> None:
        await self.fanout.close()

    # Machines.
    def machines(self) -> list[MachineEntry]:
        with self._lock:
            return list(self._machines.values())

    def get(self, name: str) -> MachineEntry | None:
        return self._machines.get(name)

    def unique_name(self, name: str) -> str:
        """A valid name made of ``name`` that no machine of the hub has (fsm/observation/names.py)."""
        with self._lock:
            return names.unique(name, self._machines)

    def add_local(self, machine: Any, name: str | None = None, path: str = introspection.DEFAULT_ROOT_PATH,
                  can_start: bool = True, starter: Callable[[], Any] | None = None,
                  holder: Callable[[], Any] | None = None, recording: str | None = None) -> MachineEntry:
        """Observe ``machine`` (any thread). A machine already observed keeps its reporter's name.

        ``starter``: what POST .../start calls (in a worker thread) instead of executing the machine
        in a new thread, for a host that runs the machine in its own loop (see control.MachineHandle).
        ``recording``: the log a Recorder writes its events to, where its history older than the ring is read.
        """
        rep = introspection.reporter_of(machine)
        with self._lock:
            for entry in self._machines.values():
                if entry.reporter is not None and entry.reporter is rep:
                    return entry
        if rep is None:
            rep = introspection.attach(machine, None, self.unique_name(name or path.rsplit("/", 1)[-1] or "SM_ROOT"),
                                       path)
        entry = MachineEntry(rep.machine, "local")
        entry.reporter = rep
        entry.handle = MachineHandle(machine, rep, can_start, starter, holder)
        entry.status.apply(schema.event(rep.last_seq, time.time(), rep.run, rep.machine, "structure", rep.root_path,
                                        {"root": rep.structure()}))
        entry.loop_seq = rep.last_seq
        entry.observer = Observer(entry, self.fanout)
        if recording is not None:
            entry.history = History(entry, LogHistory(recording, entry.name))
        with self._lock:
            if entry.name in self._machines:
                raise ValueError("a machine named %r is already served" % entry.name)
            self._machines[entry.name] = entry
        rep.add_observer(entry.observer)
        return entry

    def remove(self, name: str) -> None:
        with self._lock:
            entry = self._machines.pop(name, None)
        if entry is not None and entry.reporter is not None:
            entry.reporter.remove_observer(entry.observer)

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
                entry = self._machines[name] = MachineEntry(name, source)
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
