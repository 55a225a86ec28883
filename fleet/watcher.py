"""A dashboard's side of the fleet: every robot's machines discovered on Zenoh and followed without a
gap, whenever the dashboard joins and however often the network drops.

A machine is found by its liveliness token (``fsmscope/<robot>/<machine>``, with Zenoh's history:
those alive before the dashboard came too). On finding one the watcher asks its ``.../state``
and its ``.../history`` from the first event: when the robot still keeps every event of the machine
it delivers them all (a dashboard that joins late, or restarted, sees the whole run), else the
state's snapshot; then it delivers the machine's events from ``.../events`` in seq order. An event
beyond the next one expected (batches were lost while the network was down) makes it ask
``.../history?since=`` for the missing ones first; when the robot no longer keeps them, it takes a
new snapshot instead; when the robot does not answer in time, the batch waits with the others
skipped for the machine's join to be asked again: a gap is filled or snapshotted, never jumped. A token withdrawn (the robot's process ended, or dropped off the network past
Zenoh's lease) is delivered as ``gone``; when it comes back, so does the machine: with the events it
missed when its process is the same (its session's id, which the state answer carries), taken
again (from its first event, or a snapshot) when the process is a new one (its seqs start again).

Each delivered event carries the dashboard's name of the machine, ``<robot>:<machine>``: machines
of different robots may share a name. Two threads of the watcher's read Zenoh's channels (bounded:
the events' drops its oldest batch when full, and the gap is filled from history after) and handle
what they read one at a time, under one lock. The events' reader delivers, and asks a robot it
follows for a gap; no other hop is taken per batch (each costs a fleet's dashboard more than the
batch's events do). A reader handles what its channel holds before it says ``settled``: the robots
put on the same tick, and the dashboard's loop is woken once for them. A third thread joins the
machines, asking their state and history without the lock: a machine that answers slowly, or a
stranger's token that nobody answers for, never holds up the events of the others. Events of a
machine whose token was never seen are skipped (anyone on the network can put on these keys: asking
for each would let one put a second stop the dashboard for five); those of a machine alive but not
joined yet ask its join again, at most once per ``JOIN_AGAIN``, and are asked for from its history
once it is joined (they may be its run's last: nothing would follow them to show the gap). A new
process's events wait for its join too: its seqs count from 1 again.

What each robot said of a machine's controls with its snapshot is kept in ``controls``; ``ask``
sends a control to the machine's robot (fleet/control.py). The watcher's liveliness token
(``fsmscope-dashboards/<session>``) tells robots whose machines it leases that it is there.
"""

from __future__ import annotations

import queue
import sys
import threading
from time import monotonic
from typing import Any, Callable, Sequence

import zenoh

from fsm.observation import closing
from fsm.observation.encoding import loads

from . import control, keys
from .config import open_session
from .query import first_reply

QUERY_TIMEOUT = 5.0  # seconds a state or history query waits for the robot's answer
QUEUE = 10_000  # samples waiting in a channel for the watcher's thread before the oldest are dropped
BURST = 64  # samples handled at most before ``settled`` is called, when they keep coming
JOIN_AGAIN = 1.0  # seconds before the events of a machine alive but not joined ask its join again


def fleet_name(robot: str, machine: str) -> str:
    """The dashboard's name of a robot's machine."""
    return "%s:%s" % (robot, machine)


class FleetWatcher:
    """Follows every machine of the fleet: ``deliver(events)`` for each snapshot and batch of events
    (renamed, in order: one machine's per call), ``alive(name, bool)`` as machines come and go, and
    ``settled()`` after the calls of the samples that came together (the robots' puts of one tick):
    a consumer that hands the calls to another thread wakes it then, once for them all."""

    def __init__(self, deliver: Callable[[list[dict]], None], alive: Callable[[str, bool], None],
                 connect: Sequence[str] = (), listen: Sequence[str] = (), mode: str = "peer",
                 scouting: bool = False, config_file: str | None = None,
                 settled: Callable[[], None] = lambda: None) -> None:
        self.deliver = deliver
        self.alive = alive
        self.settled = settled
        self.session = open_session(connect, listen, mode, scouting, config_file)
        self._last: dict[str, int] = {}  # machine -> the seq of the last event delivered
        self.controls: dict[str, dict | None] = {}  # machine -> what its robot said of its controls
        self._origins: dict[str, str] = {}  # machine -> the session id of the robot's process
        self._lock = threading.Lock()  # one sample or join applied at a time, by any of the threads
        self._alive: set[str] = set()  # machines whose liveliness token is up
        self._asked: dict[str, float] = {}  # machine -> when its join was last asked for
        self._skipped: set[str] = set()  # machines whose events came while their join was on its way
        self._joins: queue.SimpleQueue[str | None] = queue.SimpleQueue()  # machine keys to join; None: stop
        self.gaps_filled = 0
        self.snapshots = 0
        self.backfilled = 0  # machines taken from their first event
        self.rejected = 0  # samples (and answers) that were not what a robot puts or answers
        self.unannounced = 0  # event samples skipped: their machine's token was never seen
        self.id = str(self.session.zid())
        self._presence = self.session.liveliness().declare_token(keys.dashboard_key(self.id))
        # Channels read by threads of ours (daemons: a callback's thread of Zenoh's would keep the
        # process from ending); the events' channel drops the oldest when full (the gap is filled after).
        self._events = self.session.declare_subscriber(keys.ALL_EVENTS, zenoh.handlers.RingChannel(QUEUE))
        self._tokens = self.session.liveliness().declare_subscriber(
            keys.ALL_MACHINES, zenoh.handlers.FifoChannel(QUEUE), history=True)
        for name, subscriber, read in (("events", self._events, self._on_events),
                                       ("tokens", self._tokens, self._on_token)):
            threading.Thread(target=self._read, args=(subscriber, read), name="fsmscope-fleet-" + name,
                             daemon=True).start()
        threading.Thread(target=self._join_all, name="fsmscope-fleet-joins", daemon=True).start()
        closing.close_at_exit(self)

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self._joins.put(None)
        self._presence.undeclare()
        self._tokens.undeclare()
        self._events.undeclare()
        self.session.close()
        closing.closed(self)

    _closed = False

    def __enter__(self) -> FleetWatcher:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _read(self, subscriber: zenoh.Subscriber, handle: Callable[[zenoh.Sample], None]) -> None:
        """Handle the channel's samples as they come, and call ``settled`` once those that came
        together are handled (every ``BURST`` of a flood, at least)."""
        channel = subscriber.handler  # not the subscriber itself: one borrowed by a wait cannot be undeclared
        try:
            while True:
                self._handle(handle, channel.recv())
                for _ in range(BURST - 1):
                    sample = channel.try_recv()
                    if sample is None:
                        break
                    self._handle(handle, sample)
                self.settled()
        except zenoh.ZError:  # the session closed
            pass

    def _join_all(self) -> None:
        """The joins' thread: each machine key asked for, joined (its queries wait without the lock)."""
        try:
            while (key := self._joins.get()) is not None:
                self._handle(self._join, key)
                self.settled()
        except zenoh.ZError:  # the session closed
            pass

    def _handle(self, handle: Callable[[Any], None], item: Any) -> None:
        """One sample (or a machine to join); what is not what a robot puts or answers (anyone on the
        network can put on these keys) is counted and said, and the thread goes on with the next."""
        try:
            handle(item)
        except zenoh.ZError:
            raise
        except Exception as exc:
            self.rejected += 1
            if self.rejected & (self.rejected - 1) == 0:  # the 1st, 2nd, 4th, 8th...: a flood says little
                print("fsmscope: what came on %s is not a robot's (%s: %s); %d so far" % (
                    getattr(item, "key_expr", item), type(exc).__name__, str(exc)[:200], self.rejected),
                    file=sys.stderr, flush=True)

    def _ask_join(self, name: str, key: str) -> None:
        """Under the lock: have the joins' thread join the machine."""
        self._asked[name] = monotonic()
        self._joins.put(key)

    # The readers' threads.
    def _on_token(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        name = fleet_name(*keys.split(key))
        up = sample.kind == zenoh.SampleKind.PUT
        with self._lock:
            self.alive(name, up)
            if up:
                self._alive.add(name)
                self._ask_join(name, key)
            else:
                self._alive.discard(name)

    def _on_events(self, sample: zenoh.Sample) -> None:
        robot, machine = keys.split(str(sample.key_expr))
        name = fleet_name(robot, machine)
        with self._lock:
            if name not in self._last:  # not joined (yet: its token came, its join is on its way)
                if name not in self._alive:
                    self.unannounced += 1
                    return
                self._skipped.add(name)  # asked for once the join is done: they may be the run's last
                if monotonic() - self._asked.get(name, 0.0) >= JOIN_AGAIN:  # its state did not answer
                    self._ask_join(name, keys.machine_key(robot, machine))
                return
            events = loads(sample.payload.to_bytes())
            if events and events[0]["seq"] > self._last[name] + 1:
                self._fill(robot, machine, self._last[name] + 1)
                if events[0]["seq"] > self._last[name] + 1:  # the robot did not answer in time: never past a gap
                    self._skipped.add(name)
                    if monotonic() - self._asked.get(name, 0.0) >= JOIN_AGAIN:  # its join asks again, unlocked
                        self._ask_join(name, keys.machine_key(robot, machine))
                    return
            self._deliver(name, events)

    def _deliver(self, name: str, events: list[dict]) -> None:
        last = self._last.get(name, 0)
        fresh = [event for event in events if event["seq"] > last]  # not a history answer's overlap
        if not fresh:
            return
        for event in fresh:
            event["machine"] = name
        self.deliver(fresh)
        self._last[name] = fresh[-1]["seq"]

    def _state(self, robot: str, machine: str) -> dict | None:
        """The machine's state answer (its snapshot, controls and origin); None when none came."""
        answer = first_reply(self.session, keys.state_key(robot, machine), QUERY_TIMEOUT)
        return None if answer is None else loads(answer)

    def _history(self, robot: str, machine: str, since: int) -> dict | None:
        """The robot's answer of the machine's events from ``since`` on; None when none came."""
        reply = first_reply(self.session, keys.history_key(robot, machine) + "?since=%d" % since, QUERY_TIMEOUT)
        return None if reply is None else loads(reply)

    def _join(self, key: str) -> None:
        """In the joins' thread, the queries without the lock: a machine seen alive, new, or back after a
        drop (what it missed), or from a new process (taken again)."""
        robot, machine = keys.split(key)
        name = fleet_name(robot, machine)
        answer = self._state(robot, machine)
        if answer is None:
            return  # its next events ask again
        with self._lock:
            back = name in self._last and answer["origin"] == self._origins.get(name)
            since = self._last[name] + 1 if back else 1
            if not back:  # a new process counts from 1 again: its events wait for the join, not the old seq
                self._last.pop(name, None)
        history = self._history(robot, machine, since)
        with self._lock:
            if back:
                self._filled(name, history, lambda: answer)
            else:
                self._take(name, answer, history)
            if name in self._skipped and name in self._last:  # what came after the answers
                self._skipped.discard(name)
                self._fill(robot, machine, self._last[name] + 1)

    def _take(self, name: str, answer: dict, history: dict | None) -> None:
        """A machine new to this watcher (or its robot's process is): every event from its first when
        the robot still keeps them all (``history`` from 1: a dashboard restarted, or late, can look
        back over the whole run), else the state answer's snapshot, from which its events go on."""
        same = answer["origin"] == self._origins.get(name)
        self.controls[name] = answer.get("controls")
        self._origins[name] = answer["origin"]
        if history is not None and history["complete"] and history["events"]:
            self._last.pop(name, None)
            self._deliver(name, history["events"])
            self.backfilled += 1
            return
        snapshot = answer["snapshot"]
        if same and self._last.get(name, 0) >= snapshot["seq"]:
            return  # its events came on past this snapshot while it was asked for
        snapshot["machine"] = name
        snapshot["status"]["machine"] = name
        self.deliver([snapshot])
        self._last[name] = snapshot["seq"]
        self.snapshots += 1

    def _filled(self, name: str, history: dict | None, answer_of: Callable[[], dict | None]) -> None:
        """A gap's events from the robot's ``history``; the snapshot of its state answer (``answer_of``)
        when it no longer has them."""
        if history is None:
            return
        if history["complete"]:
            self._deliver(name, history["events"])
            self.gaps_filled += 1
        elif (answer := answer_of()) is not None:
            self._take(name, answer, None)

    def _fill(self, robot: str, machine: str, since: int) -> None:
        """In the events' reader, under the lock: the events from ``since`` on of a machine it follows."""
        self._filled(fleet_name(robot, machine), self._history(robot, machine, since),
                     lambda: self._state(robot, machine))

    def ask(self, robot: str, machine: str, token: str, action: str, params: dict, client: str) -> dict | None:
        """A control for ``robot``'s ``machine``: its robot's answer, None when none came in time."""
        return control.ask(self.session, keys.control_key(robot, machine), token, action, params, client,
                           QUERY_TIMEOUT)
