"""A robot's machines on Zenoh, with one call:

    from fleet.robot import ZenohRobot
    fsm.attach(sm, ZenohRobot("r1", connect=["tcp/192.168.1.10:7447"]), name="picker")

The observer only appends to a bounded buffer (the machine's thread never waits for the network).
A background thread applies the events to its own ``Status`` per machine (unless its host shares
one it keeps anyway: ``share_status``), keeps the newest ``RING`` of them, and puts them in
batches on ``fsmscope/<robot>/<machine>/events``. Per machine
it also declares, on the machine's first event:

- a liveliness token on ``fsmscope/<robot>/<machine>``: dashboards see the machine appear, and
  see it gone within Zenoh's lease when the process dies or drops off the network;
- a queryable ``.../state``: the machine's snapshot event (its whole state now), for a dashboard
  that joins late, and what controls it takes;
- a queryable ``.../history?since=SEQ``: the events from SEQ on that the ring still holds (a
  dashboard whose connection dropped fills its gap; older than the ring: it takes the snapshot);
- a queryable ``.../control``: a dashboard's control, carrying the robot's token, applied to the
  machine and answered (fleet/control.py).

When nobody listens or the network is gone, puts go nowhere and the machine runs on; memory stays
bounded by the buffer and the rings. Imports only the standard library, ``zenoh`` and ``fsm``.
"""

from __future__ import annotations

import collections
import threading
import time
from typing import Any, Callable, Sequence

import zenoh

from fsm.control.handle import MachineHandle
from fsm.observation import closing, introspection, schema
from fsm.observation.encoding import dumps
from fsm.observation.handoff import Handoff
from fsm.observation.status import Status

from . import keys
from .config import session_config
from .control import RobotControls

BUFFER = 100_000  # events waiting for the sender before the oldest are dropped
RING = 10_000  # events of each machine kept for history queries
MAX_BATCH = 2000  # events per put
LINGER = 0.005  # seconds the sender lets events gather after the first (fewer, larger puts: a dashboard
                # following a fleet pays per put received, not per event)
CONTROL_SETTLE = 1.0  # seconds a control's answer waits for the events it caused to be put


class _Machine:
    """What the robot keeps of one machine, and its Zenoh entities."""

    def __init__(self, session: zenoh.Session, robot: str, name: str, controls: RobotControls,
                 shared: dict[str, tuple[Any, Callable[[], Status]]]) -> None:
        self.name = name
        self.status = Status(name)
        self.shared = shared  # the robot's: a host's Status read instead of this one (ZenohRobot.share_status)
        self.ring: collections.deque[dict] = collections.deque(maxlen=RING)
        self.lock = threading.Lock()  # queries come from Zenoh's threads
        self.controls = controls
        self.origin = str(session.zid())  # a new process is a new session: its seqs start again
        self.publisher = session.declare_publisher(keys.events_key(robot, name),
                                                   congestion_control=zenoh.CongestionControl.DROP)
        self.state = session.declare_queryable(keys.state_key(robot, name), self._state)
        self.history = session.declare_queryable(keys.history_key(robot, name), self._history)
        self.control = controls.declare(session, keys.control_key(robot, name), name)
        self.token = session.liveliness().declare_token(keys.machine_key(robot, name))  # last: all is there

    def _state(self, query: zenoh.Query) -> None:
        lock, current = self.shared.get(self.name) or (self.lock, lambda: self.status)
        with lock:
            status = current()
            snapshot = schema.event(status.last_seq, time.time(), status.run, self.name, "snapshot",
                                    status.root_path or "/SM_ROOT", {"status": dict(status.to_dict(), machine=self.name)})
        query.reply(query.key_expr, dumps({"snapshot": snapshot, "controls": self.controls.offer(self.name),
                                           "origin": self.origin}))

    def _history(self, query: zenoh.Query) -> None:
        try:
            since = int(query.parameters.get("since") or 0)
        except ValueError:
            query.reply_err(b"since must be an integer")
            return
        with self.lock:
            kept = list(self.ring)
        first = kept[0]["seq"] if kept else None
        events = [e for e in kept if e["seq"] >= since]
        query.reply(query.key_expr, dumps({"complete": first is not None and first <= since, "events": events}))

    def close(self) -> None:
        for entity in (self.token, self.control, self.history, self.state, self.publisher):
            entity.undeclare()


class ZenohRobot:
    """An observer (``fsm.attach(sm, ZenohRobot("r1", ...))``) that puts a robot's machines on Zenoh.
    ``connect`` / ``listen``: Zenoh endpoints (``tcp/HOST:PORT``); ``mode``: "peer" or "client";
    ``scouting``: multicast discovery on the LAN (off unless asked). ``token``: what a dashboard's
    control must carry (none: the robot takes no control); ``can_start``: whether a start may run a
    machine again (in a new thread)."""

    def __init__(self, robot: str, connect: Sequence[str] = (), listen: Sequence[str] = (), mode: str = "peer",
                 scouting: bool = False, buffer: int = BUFFER, token: str | None = None,
                 can_start: bool = False) -> None:
        self.robot = keys.chunk(robot, "robot")
        self.can_start = can_start
        self.session = zenoh.open(session_config(connect, listen, mode, scouting))
        self._handoff = Handoff(buffer)
        self._buf = self._handoff.events
        self.controls = RobotControls(token, lambda: self._handoff.drained(CONTROL_SETTLE))
        self._stop = threading.Event()
        self._machines: dict[str, _Machine] = {}
        self._shared: dict[str, tuple[Any, Callable[[], Status]]] = {}
        self.sent = 0
        self._thread = threading.Thread(target=self._run, name="fsmscope-zenoh", daemon=True)
        self._thread.start()
        closing.close_at_exit(self)

    # The observer: runs in the machine's thread.
    def __call__(self, event: dict) -> None:
        self._handoff(event)

    def attached(self, reporter: introspection.Reporter) -> None:
        """``fsm.attach`` gave this robot a machine: it takes the dashboards' controls from now on."""
        self.controls.handles.setdefault(reporter.machine, MachineHandle(reporter.root, reporter, self.can_start))

    def take_controls(self, handle: MachineHandle) -> None:
        """Apply the controls of ``handle``'s machine through ``handle``: a host's own (one that runs the
        machine in its own loop, as the demo does) rather than one of the robot's."""
        self.controls.handles[handle.reporter.machine] = handle

    def share_status(self, machine: str, lock: Any, current: Callable[[], Status]) -> None:
        """Answer ``machine``'s state queries from a ``Status`` its host keeps anyway (``current()``,
        read holding ``lock``): the dashboard's hub in the same process applies every event in the
        machine's thread already. The robot's thread then only keeps and puts the events, which is
        most of what publishing costs the machine (bench/fleet_cost.py)."""
        self._shared[machine] = (lock, current)

    @property
    def dropped(self) -> int:
        """Events dropped because the buffer was full."""
        return self._handoff.dropped

    def flush(self, timeout: float = 5.0) -> bool:
        """Wait until every buffered event was put; False on timeout."""
        return self._handoff.drained(timeout)

    def close(self, timeout: float = 5.0) -> None:
        """Put what is buffered, then leave the network (the machines' tokens go: dashboards see them
        gone). Idempotent."""
        if self._stop.is_set():
            return
        self.flush(timeout)
        self._stop.set()
        self._handoff.wake.set()
        if self._thread is not threading.current_thread():
            self._thread.join(timeout)
        self.controls.close(timeout)
        for machine in self._machines.values():
            machine.close()
        self.session.close()
        closing.closed(self)

    def __enter__(self) -> ZenohRobot:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def _run(self) -> None:
        wake = self._handoff.wake
        while not self._stop.is_set():
            if wake.wait(0.5):
                self._stop.wait(LINGER)  # the events of the next few ms go with this one's
            wake.clear()
            while self._buf:
                self._handoff.busy = True
                self._send(self._take())
            self._handoff.busy = False

    def _take(self) -> dict[str, list[dict]]:
        batches: dict[str, list[dict]] = {}
        taken = 0
        while self._buf and taken < MAX_BATCH:
            event = self._buf.popleft()
            batches.setdefault(event["machine"], []).append(event)
            taken += 1
        return batches

    def _send(self, batches: dict[str, list[dict]]) -> None:
        for name, events in batches.items():
            machine = self._machines.get(name)
            if machine is None:
                machine = self._machines[name] = _Machine(self.session, self.robot, keys.chunk(name, "machine"),
                                                          self.controls, self._shared)
            with machine.lock:
                if name not in self._shared:
                    for event in events:
                        machine.status.apply(event)
                machine.ring.extend(events)
            machine.publisher.put(dumps(events))
            self.sent += len(events)
