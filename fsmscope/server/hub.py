"""The Hub, one per server: the machines it shows, by name, and the fan-out that streams their events.

A machine is local (observed in this process: ``add_local`` attaches a ``fanout.Observer`` to its
reporter), ingested (another process publishes its events to /api/ingest, or a robot on Zenoh) or
replayed (from a log). Each ``MachineEntry`` is composed of parts with one owner each: its stream
(``feed.Feed``, the hub's), its past (``history.History``, with the keyframes it keeps of the feed),
its timeline (``timeline.TimelineIndex``, a sink of the feed), its controls (``fsm.control.Controls``:
the hub's handle for a local machine, a ``RemoteHandle`` its door binds for another process's) and
its origin (``origin.Origin``, the door's). How events reach the browsers is fsmscope/server/fanout.py.
"""

from __future__ import annotations

import asyncio
import hashlib
import threading
import time
from dataclasses import dataclass
from typing import Any, Callable

from fsm.control.controls import Controls, NoControls
from fsm.control.handle import MachineHandle
from fsm.observation import introspection, names, schema
from fsm.observation import structure
from fsm.observation.encoding import dumps
from fsm.observation.status import Status

from .fanout import Fanout, Observer
from .feed import Feed
from .history import History, LogHistory
from .origin import Origin
from .read_cache import Answers
from .state_stats import StateStats
from .timeline import TimelineIndex


def structure_hash(root: dict | None) -> str:
    return hashlib.blake2b(dumps(root), digest_size=12).hexdigest() if root is not None else ""


def uncontrolled(name: str, source: str) -> NoControls:
    """The controls of a machine nothing here controls (until its door binds a RemoteHandle)."""
    if source == "replay":
        return NoControls("machine %r is a recording being replayed: nothing to control" % name)
    return NoControls("machine %r runs in another process: control it there" % name)


@dataclass
class LocalMachine:
    """What the hub keeps of a machine of this process: the reporter it observes, its handle, its observer."""

    reporter: introspection.Reporter
    handle: MachineHandle
    observer: Observer


class MachineEntry:
    """A machine known to the hub: its feed, past, timeline, controls and origin."""

    def __init__(self, name: str, origin: Origin, controls: Controls | None = None,
                 log: LogHistory | None = None) -> None:
        self.name = name
        self.origin = origin
        self.feed = Feed(name)
        self.timeline = TimelineIndex()
        self.feed.add_sink(self.timeline.add_all)
        self.past = History(self.feed, log)  # the ring's recent past, and a recording when it has one
        self.controls: Controls = controls if controls is not None else uncontrolled(name, origin.source)
        self.stats = StateStats(name)  # its states' statistics, counted when asked (fsmscope/server/state_stats.py)
        self.answers = Answers()  # its reads' answers until it has a new event (fsmscope/server/read_cache.py)
        self.local: LocalMachine | None = None  # a machine of this process (add_local)
        self._structure_id: int | None = None
        self._structure_hash = ""
        self._n_states = 0

    def structure_info(self) -> tuple[str, int]:
        """(a hash of the structure, its number of states), computed once per structure."""
        root = self.feed.status.structure
        if id(root) != self._structure_id:
            self._structure_id = id(root)
            self._structure_hash = structure_hash(root)
            self._n_states = structure.count(root)
        return self._structure_hash, self._n_states

    def running(self) -> bool:
        """Running as far as anyone can tell: a machine whose publisher left is not shown running."""
        if self.local is not None:
            return self.local.handle.is_running()
        return self.feed.status.running and not self.origin.gone

    def restart(self, status: Status) -> None:
        """A new epoch of another process's machine (it restarted, or sent a snapshot): the feed starts
        over from ``status``, and so does the timeline when its seqs begin again."""
        if status.last_seq < self.feed.status.last_seq:
            timeline = TimelineIndex()
            self.feed.replace_sink(self.timeline.add_all, timeline.add_all)
            self.timeline = timeline
        self.feed.reset(status)
        self.answers = Answers()  # seqs may begin again: no answer of the old epoch may be taken for a new one

    def read_past_from(self, log: LogHistory) -> None:
        """Its history is read from ``log`` alone from now on (a replay, loaded whole from it)."""
        self.past = History(None, log)
        self.answers = Answers()


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
                  holder: Callable[[], Any] | None = None, recording: str | None = None,
                  script: str | None = None) -> MachineEntry:
        """Observe ``machine`` (any thread). A machine already observed keeps its reporter's name.

        ``starter``: what POST .../start calls (in a worker thread) instead of executing the machine
        in a new thread, for a host that runs the machine in its own loop (see control.MachineHandle).
        ``recording``: the log a Recorder writes its events to, where its history older than the ring is read.
        ``script``: the script that built it (``fsmscope run``): a page follows the newest machine of a script.
        """
        rep = introspection.reporter_of(machine)
        with self._lock:
            for entry in self._machines.values():
                if entry.local is not None and entry.local.reporter is rep:
                    return entry
        if rep is None:
            rep = introspection.attach(machine, None, self.unique_name(name or path.rsplit("/", 1)[-1] or "SM_ROOT"),
                                       path)
        handle = MachineHandle(machine, rep, can_start, starter, holder)
        entry = MachineEntry(rep.machine, Origin("local", script=script), handle,
                             LogHistory(recording, rep.machine) if recording is not None else None)
        feed = entry.feed
        root = rep.structure()
        status, lock = rep.folded_status()  # one fold per event, the recorder's too
        entry.local = LocalMachine(rep, handle, Observer(feed, self.fanout))
        with lock:  # no batch between: the Status is brought up to date, the feed takes the batches after it
            rep.deliver()
            status.apply(schema.build.structure(rep.last_seq, time.time(), rep.run, rep.machine, rep.root_path, root))
            feed.fold_by(status, lock)
            feed.loop_seq = rep.last_seq
            with self._lock:
                if entry.name in self._machines:
                    raise ValueError("a machine named %r is already served" % entry.name)
                self._machines[entry.name] = entry
            rep.add_observer(entry.local.observer)
        return entry

    def remove(self, name: str) -> None:
        with self._lock:
            entry = self._machines.pop(name, None)
        if entry is not None and entry.local is not None:
            entry.local.reporter.remove_observer(entry.local.observer)

    # Ingest (on the loop).
    def ingest(self, event: Any, source: str = "ingest") -> str | None:
        """Apply one event from another process (or, ``source="replay"``, from a log); returns why
        an event was refused. An event that does not fit the schema never reaches the Status."""
        problem = schema.validate(event)
        if problem:
            name = event.get("machine") if type(event) is dict else None
            entry = self._machines.get(name) if type(name) is str else None
            if entry is not None:  # one naming no known machine is only answered, not counted
                entry.origin.rejected += 1
            return problem
        name = event["machine"]
        with self._lock:
            entry = self._machines.get(name)
            if entry is None:
                entry = self._machines[name] = MachineEntry(name, Origin(source))
        if entry.origin.source != source:
            return "machine %r is served by this process as %s" % (name, entry.origin.source)
        if event["kind"] == "snapshot":
            status = Status.from_dict(dict(event["status"], machine=name))
            status.last_seq = event["seq"]
            entry.restart(status)
            return None
        feed = entry.feed
        if event["seq"] <= feed.status.last_seq:
            if event.get("run") == feed.status.run and event["kind"] != "structure":
                return None  # a duplicate
            entry.restart(Status(name))  # the publishing process restarted
        feed.apply(event)
        return None
