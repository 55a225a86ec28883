"""A robot's machines on Zenoh, with one call:

    from fsmscope.fleet.robot import ZenohRobot
    fsm.attach(sm, ZenohRobot("r1", connect=["tcp/192.168.1.10:7447"]), name="picker")

The observer batches each machine's events in the machine's own thread (their bytes encoded once
for every observer: ``fsm.observation.encoding.encoded``) and puts them on
``fsmscope/<robot>/<machine>/events`` on the robot's clock: at every tick (``LINGER``) the batches
of all its machines go at the same instant, so Zenoh carries them in one message and a dashboard is
woken once for them. A dashboard following 20 machines at 100 events/s took 31-33 % of a core so,
against 45-48 % when each event was put as it came (bench/fleet_dashboard.py); an event waits 2.5 ms
on average for the tick. A busy machine's thread puts its own batches (at the tick, or every
``MAX_BATCH`` events), and no other thread touches its events: a hand-off of every event to a
sender thread cost the two-state loop about three times as much, the GIL and the cache lines moving
between the threads (bench/fleet_cost.py). A flusher thread puts the batches of the machines that
wait for the tick; a machine that handed over events more than once in the tick is left a tick longer
to put its batch itself (the flusher putting it took the GIL from the machine, and the machine's
next batch then waited for the flusher's lock). Puts drop rather than wait when the network is
congested (Zenoh's
``CongestionControl.DROP``), so a machine never waits for the network.

Per machine it also declares, on the machine's first event:

- a liveliness token on ``fsmscope/<robot>/<machine>``: dashboards see the machine appear, and
  see it gone within Zenoh's lease when the process dies or drops off the network;
- a queryable ``.../state``: the machine's snapshot event (its whole state now), for a dashboard
  that joins late, and what controls it takes;
- a queryable ``.../history?since=SEQ``: the events from SEQ on, of the newest ``RING`` (the batches
  put that hold them, then those waiting for the tick): a dashboard whose connection dropped fills
  its gap, one that joins takes the machine from its first event (older than that: the snapshot);
- a queryable ``.../control``: a dashboard's control, proving the robot's token, applied to the
  machine and answered (fsmscope/fleet/control.py).

Every batch and every answer carries its proof of the robot's token (fsmscope/fleet/proofs.py): a dashboard
shows only what proves it, so nobody without the token can pose as the robot. A robot given no
token makes one and says it on stderr: a dashboard needs it to show the robot's machines.

When nobody listens or the network is gone, puts go nowhere and the machine runs on; memory stays
bounded by the batches and the rings. Imports only the standard library, ``zenoh`` and ``fsm``.

One piece because each machine's batches, the ring its queryables answer from and its declarations
are one robot's state, put on one clock (the tick) by one flusher.
"""

from __future__ import annotations

import collections
import secrets
import sys
import threading
import time
from itertools import chain
from operator import itemgetter
from time import monotonic
from typing import Any, Callable, Sequence

import zenoh

from fsm.control.handle import MachineHandle
from fsm.observation import closing, introspection, schema
from fsm.observation.encoding import dumps, encoded
from fsm.observation.status import Status

from . import keys, proofs
from .config import open_session
from .control import RobotControls
from .query import reply

RING = 10_000  # events of each machine kept (as the batches put) for history queries
MAX_BATCH = 512  # events per put at most (a payload of about 100 kB: larger ones cost more per byte to
                 # allocate, as fresh pages)
LINGER = 0.005  # seconds between the robot's puts (a tick of its clock: fewer, larger puts, together; a
                # dashboard following a fleet pays per message received, not per event)
_DATA = itemgetter(1)  # an item's encoded event


class _Machine:
    """What the robot keeps of one machine: its pending batch, the batches put, its Zenoh entities."""

    def __init__(self, session: zenoh.Session, robot: str, name: str, controls: RobotControls,
                 shared: dict[str, tuple[Any, Callable[[], Status]]], wake: threading.Event,
                 first: dict | None = None) -> None:
        self.name = name
        self.status = Status(name)
        self.shared = shared  # the robot's: a Status read instead of this one (a reporter's, a host's)
        self.wake = wake  # the flusher's
        self.lock = threading.Lock()  # guards the Status (the machine's thread and Zenoh's queries)
        # The batch gathering, as the host handed the events over ([(seq, encoded event), ...] each):
        # the machine's thread appends without a lock (a deque's append and popleft are atomic), whoever
        # puts takes it holding ``putting``.
        self.pending: collections.deque[Sequence[tuple[int, bytes]]] = collections.deque()
        self.due = 0.0  # when the pending batch is put: the robot's next tick
        self.busy = False  # the pending batch was given events more than once: its machine puts it itself
        self.putting = threading.Lock()  # one put at a time: batches go in order; guards the ring
        self.ring: collections.deque[tuple[int, int, int, bytes]] = collections.deque()  # (first, last, count, payload)
        self.kept = 0  # events in the ring
        self.closed = False
        self.controls = controls
        self.origin = str(session.zid())  # a new process is a new session: its seqs start again
        self.key = keys.events_key(robot, name)
        self.publisher = session.declare_publisher(self.key, congestion_control=zenoh.CongestionControl.DROP)
        self.state = session.declare_queryable(keys.state_key(robot, name), self._state)
        self.history = session.declare_queryable(keys.history_key(robot, name), self._history)
        self.control = controls.declare(session, keys.control_key(robot, name), name)
        if first is not None:
            self.keep(first)
        self.token = session.liveliness().declare_token(keys.machine_key(robot, name))  # last: all is there

    def keep(self, event: dict) -> None:
        """In the machine's thread, as its observer: keep the machine's Status (unless its reporter
        folds it: ``ZenohRobot.attached``), then take the event."""
        if self.name not in self.shared:
            with self.lock:
                self.status.apply(event)
        self.take(((event["seq"], encoded(event)),))

    def take(self, items: Sequence[tuple[int, bytes]]) -> None:
        """In the thread that delivers the machine's events: events, (seq, their JSON), join the
        pending batch, put at the robot's next tick or when full (a busy machine puts its own
        batches, the flusher those of a machine that waits for the tick). The fewest steps: this is
        what publishing costs a machine whose host encodes its events anyway (ZenohRobot.follow),
        once per batch the host delivers."""
        pending = self.pending
        first = not pending
        pending.append(items)
        if first:
            self.due = (monotonic() // LINGER + 1) * LINGER
            self.wake.set()
        elif sum(map(len, pending)) >= MAX_BATCH or monotonic() >= self.due:
            self.flush()
        else:
            self.busy = True

    def flush(self, now: float | None = None) -> float | None:
        """Put the pending batch if it is due at ``now`` (None: whatever its age). Returns when the
        batch still pending is due, None when none is."""
        with self.putting:
            pending = self.pending
            if self.closed:  # the robot left the network: what its machine still does goes nowhere
                pending.clear()
                return None
            if not pending:
                return None
            # A busy machine's batch is left to its own thread a tick longer: the flusher putting it would
            # take the GIL from the machine, whose next batch would then wait for the flusher's lock.
            due = self.due + LINGER if self.busy else self.due
            if now is not None and now < due:
                return due
            self.busy = False
            waiting = list(chain.from_iterable([pending.popleft() for _ in range(len(pending))]))
            for start in range(0, len(waiting), MAX_BATCH):  # a host may hand over more at once
                items = waiting[start:start + MAX_BATCH]
                payload = b",".join(map(_DATA, items)).join((b"[", b"]"))
                self.publisher.put(payload, attachment=batch_attachment(self.controls.token, self.key, self.origin,
                                                                        payload))
                ring = self.ring
                ring.append((items[0][0], items[-1][0], len(items), payload))
                self.kept += len(items)
                while self.kept - ring[0][2] >= RING:  # the oldest batches past RING events let go
                    self.kept -= ring.popleft()[2]
            return None

    def _state(self, query: zenoh.Query) -> None:
        lock, current = self.shared.get(self.name) or (self.lock, lambda: self.status)
        with lock:
            status = current()
            snapshot = schema.build.snapshot(status.last_seq, time.time(), status.run, self.name,
                                             status.root_path or "/SM_ROOT", dict(status.to_dict(), machine=self.name))
        reply(query, self.controls.token, dumps({"snapshot": snapshot, "controls": self.controls.offer(self.name),
                                                 "origin": self.origin}))

    def _history(self, query: zenoh.Query) -> None:
        try:
            since = int(query.parameters.get("since") or 0)
        except ValueError:
            query.reply_err(b"since must be an integer")
            return
        with self.putting:
            waiting = list(chain.from_iterable(self.pending.copy()))  # not put yet (a copy is atomic)
            first = self.ring[0][0] if self.ring else waiting[0][0] if waiting else None
            parts = [payload[1:-1] for _, last, _, payload in self.ring if last >= since]
        parts += [data for seq, data in waiting if seq >= since]
        # The batches holding the events from ``since`` on (the dashboard drops those before it had),
        # and the events waiting for the next tick.
        complete = first is not None and first <= since
        reply(query, self.controls.token, b'{"complete":%s,"events":[%s]}' % (b"true" if complete else b"false",
                                                                             b",".join(parts)))

    def close(self) -> None:
        with self.putting:
            self.closed = True
        for entity in (self.token, self.control, self.history, self.state, self.publisher):
            entity.undeclare()


def batch_attachment(token: str, key: str, origin: str, payload: bytes) -> bytes:
    """A batch's attachment: its proof of the robot's token, then the robot's process (session id)."""
    return proofs.sign(token, b"events", key, origin.encode(), payload) + origin.encode()


class ZenohRobot:
    """An observer (``fsm.attach(sm, ZenohRobot("r1", ...))``) that puts a robot's machines on Zenoh.
    ``connect`` / ``listen``: Zenoh endpoints (``tcp/HOST:PORT``); ``mode``: "peer" or "client";
    ``scouting``: multicast discovery on the LAN (off unless asked); ``config_file``: a Zenoh
    configuration file under those (fsmscope/fleet/config.py). ``token``: what the robot's batches and
    answers prove, and a dashboard's controls must prove (none: one is made, and said on stderr);
    ``controls``: False refuses every control; ``can_start``: whether a start may run a machine again
    (in a new thread)."""

    def __init__(self, robot: str, connect: Sequence[str] = (), listen: Sequence[str] = (), mode: str = "peer",
                 scouting: bool = False, token: str | None = None, can_start: bool = False,
                 config_file: str | None = None, controls: bool = True) -> None:
        self.robot = keys.robot_chunk(robot)
        self.can_start = can_start
        self.session = open_session(connect, listen, mode, scouting, config_file)
        if not token:
            token = secrets.token_urlsafe(24)
            print("fsmscope: robot %r proves its machines with the token %s (a dashboard shows and controls "
                  "them with serve --zenoh-token %s=%s)" % (robot, token, robot, token), file=sys.stderr, flush=True)
        self.controls = RobotControls(self.robot, token, controls, self.flush)
        self._stop = threading.Event()
        self._wake = threading.Event()  # a batch began: the flusher puts it if its machine goes quiet
        self._machines: dict[str, _Machine] = {}
        self._declaring = threading.Lock()
        self._callback_threads: list[threading.Thread] = []  # Zenoh's, running our queryables' callbacks
        self._shared: dict[str, tuple[Any, Callable[[], Status]]] = {}
        self._thread = threading.Thread(target=self._run, name="fsmscope-zenoh", daemon=True)
        self._thread.start()
        closing.close_at_exit(self)

    # The observer: runs in the machine's thread.
    def __call__(self, event: dict) -> None:
        try:
            machine = self._machines[event["machine"]]
        except KeyError:
            if self._stop.is_set():  # closed: the machine runs on, unpublished
                return
            machine = self._declare(event["machine"], event)
            if machine is None:  # declared with this event kept first
                return
        machine.keep(event)

    def _declare(self, name: str, first: dict | None = None) -> _Machine | None:
        """A machine's Zenoh entities (machines of other threads may come at once), with its ``first``
        event kept before its liveliness token is declared: a dashboard that joins at once finds that
        event in the state it asks. None when it kept ``first``, else the machine."""
        with self._declaring:
            if name in self._machines:
                return self._machines[name]
            key = keys.chunk(name, "machine")  # a name Zenoh cannot take fails here, in the machine's thread
            made = threading.Thread(target=self._declare_in_thread, args=(name, key, first), daemon=True)
            made.start()
            made.join()
            return None if first is not None else self._machines[name]

    def _declare_in_thread(self, name: str, key: str, first: dict | None) -> None:
        """In a daemon thread: Zenoh runs a queryable's callbacks in a Python thread that is a daemon
        only when the declaring thread is one, and a thread that is not would keep the process from
        ending (Python waits for those before the exit hook that closes the robot). ``close`` waits
        for those threads to end: one still in Zenoh's code when the interpreter ends aborts it."""
        before = set(threading.enumerate())
        self._machines[name] = _Machine(self.session, self.robot, key, self.controls, self._shared, self._wake, first)
        self._callback_threads += [thread for thread in threading.enumerate()
                                   if thread not in before and thread is not threading.current_thread()]

    def attached(self, reporter: introspection.Reporter) -> None:
        """``fsm.attach`` gave this robot a machine: it takes the dashboards' controls from now on, and
        answers state queries from the Status its reporter folds (one fold of each event for every reader)."""
        self.controls.handles.setdefault(reporter.machine, MachineHandle(reporter.root, reporter, self.can_start))
        status, lock = reporter.folded_status()
        self._shared.setdefault(reporter.machine, (lock, lambda: status))

    def take_controls(self, handle: MachineHandle) -> None:
        """Apply the controls of ``handle``'s machine through ``handle``: a host's own (one that runs the
        machine in its own loop, as the demo does) rather than one of the robot's."""
        self.controls.handles[handle.reporter.machine] = handle

    def follow(self, machine: str, handle: MachineHandle, lock: Any,
               current: Callable[[], Status]) -> Callable[[Sequence[tuple[int, bytes]]], None]:
        """Publish a machine its host observes anyway (the dashboard's hub, as ``run --zenoh`` and
        ``demo --zenoh`` compose them), instead of observing it too: the host gives the returned
        callable each batch of events as [(seq, its JSON), ...], in the thread that delivers it;
        controls are applied through the host's ``handle``; state queries are answered from the
        host's ``Status`` (``current()``, read holding ``lock``). The robot then keeps no Status and
        encodes nothing: publishing costs the machine one call per batch (bench/fleet_cost.py)."""
        self.take_controls(handle)
        self._shared[machine] = (lock, current)
        self._declare(machine)
        return self._machines[machine].take

    def flush(self) -> None:
        """Put every pending batch now (a control's answer comes after the events it caused)."""
        for machine in list(self._machines.values()):
            machine.flush()

    def close(self, timeout: float = 5.0) -> None:
        """Put what is pending, then leave the network (the machines' tokens go: dashboards see them
        gone). Idempotent."""
        if self._stop.is_set():
            return
        self._stop.set()
        self._wake.set()
        if self._thread is not threading.current_thread():
            self._thread.join(timeout)
        self.flush()
        self.controls.close(timeout)
        for machine in self._machines.values():
            machine.close()
        self.session.close()
        for thread in self._callback_threads:
            thread.join(timeout)
        closing.closed(self)

    def __enter__(self) -> ZenohRobot:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def _run(self) -> None:
        """The flusher: puts the batches of machines that went quiet, when they are due."""
        while not self._stop.is_set():
            self._wake.wait(0.5)
            self._wake.clear()
            due = self._flush_due()
            while due is not None and not self._stop.wait(max(0.0, due - monotonic())):
                due = self._flush_due()

    def _flush_due(self) -> float | None:
        """Put the batches due now; when the earliest of those still pending is due."""
        now = monotonic()
        dues = [due for due in (machine.flush(now) for machine in list(self._machines.values())) if due is not None]
        return min(dues, default=None)
