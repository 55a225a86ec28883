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
machines (fsmscope/fleet/joins.py): it sends their state queries without waiting for them, and asks a
machine's history once its state answered, without the lock: a machine that answers slowly, or a
stranger's token that nobody answers for, never holds up the events or the joins of the others.
Events of a
machine whose token was never seen are skipped (anyone on the network can put on these keys: asking
for each would let one put a second stop the dashboard for five); those of a machine alive but not
joined yet ask its join again, at most once per ``JOIN_AGAIN``, and are asked for from its history
once it is joined (they may be its run's last: nothing would follow them to show the gap). A new
process's events wait for its join too: its seqs count from 1 again.

Only what proves the robot's token is taken (fsmscope/fleet/proofs.py): a batch whose proof is not that of
the token this dashboard holds for its robot (``tokens``: by robot, None for any robot's) is refused
and counted in ``refusals``, and so is every answer to a query; a robot for which the dashboard has
no token is not shown, and that is said. A batch's proof covers the robot's process, so a new
process's batches ask its join, and a batch's seqs must follow each other: not even a robot's
batch moves the dashboard's idea of its sequence by more than the events it holds.

What each robot said of a machine's controls with its snapshot is kept in ``controls``; ``ask``
sends a control to the machine's robot (fsmscope/fleet/control.py). While it leases a robot's machine, the
watcher beats for it (fsmscope/fleet/beats.py).

One piece over 300 lines: its readers and its joins share one lock and one idea of each machine
(the last seq delivered, the robot's process, the events skipped), which a split would pass around.
"""

from __future__ import annotations

import itertools
import sys
import threading
from time import monotonic
from typing import Any, Callable, Mapping, Sequence

import zenoh

from fsm.observation import closing
from fsm.observation.encoding import loads

from . import control, keys, proofs
from .beats import Heartbeats
from .config import open_session
from .joins import QUERY_TIMEOUT, Joins
from .query import first_reply

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
                 settled: Callable[[], None] = lambda: None, tokens: Mapping[str | None, str] = {}) -> None:
        self.deliver = deliver
        self.tokens = dict(tokens)
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
        self._counter = itertools.count(1)  # of this dashboard's controls: a robot takes each once
        self.gaps_filled = 0
        self.snapshots = 0
        self.backfilled = 0  # machines taken from their first event
        self.rejections = proofs.Tally("fsmscope")  # proven samples and answers that were not what a robot sends
        self.refusals = proofs.Tally("fsmscope")  # batches that do not prove their robot's token
        self._untrusted: set[str] = set()  # robots this dashboard has no token for (said once each)
        self.unannounced = 0  # event samples skipped: their machine's token was never seen
        self.id = str(self.session.zid())
        self.beats = Heartbeats(self.session, self.id)
        self._joins = Joins(self.session, self._token, lambda item: self._handle(self._join, item), self.settled)
        # Channels read by threads of ours (daemons: a callback's thread of Zenoh's would keep the
        # process from ending); the events' channel drops the oldest when full (the gap is filled after).
        self._events = self.session.declare_subscriber(keys.ALL_EVENTS, zenoh.handlers.RingChannel(QUEUE))
        self._tokens = self.session.liveliness().declare_subscriber(
            keys.ALL_MACHINES, zenoh.handlers.FifoChannel(QUEUE), history=True)
        for name, subscriber, read in (("events", self._events, self._on_events),
                                       ("tokens", self._tokens, self._on_token)):
            threading.Thread(target=self._read, args=(subscriber, read), name="fsmscope-fleet-" + name,
                             daemon=True).start()
        closing.close_at_exit(self)

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self._joins.close()
        self.beats.close()
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

    @property
    def rejected(self) -> int:
        """Samples and answers that proved their robot's token but were not what a robot sends."""
        return self.rejections.count

    def _token(self, robot: str) -> str | None:
        """The token this dashboard holds for ``robot``'s proofs."""
        return self.tokens.get(robot, self.tokens.get(None))

    def _handle(self, handle: Callable[[Any], None], item: Any) -> None:
        """One sample (or a machine to join); what is not what a robot puts or answers (anyone on the
        network can put on these keys) is counted and said, and the thread goes on with the next."""
        try:
            handle(item)
        except zenoh.ZError:
            raise
        except Exception as exc:
            where = item[0] if type(item) is tuple else getattr(item, "key_expr", item)
            self.rejections.refused("what came on %s, which is not a robot's (%s: %s)" % (
                where, type(exc).__name__, str(exc)[:200]))

    def _ask_join(self, name: str, key: str) -> None:
        """Under the lock: have the joins' thread join the machine."""
        self._asked[name] = monotonic()
        self._joins.ask(key)

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
        key = str(sample.key_expr)
        robot, machine = keys.split(key)
        name = fleet_name(robot, machine)
        payload = sample.payload.to_bytes()
        attachment = sample.attachment.to_bytes() if sample.attachment is not None else b""
        proof, origin = attachment[:proofs.SIZE], attachment[proofs.SIZE:]
        if not self._proven(robot, key, proof, origin, payload):
            return
        with self._lock:
            if name not in self._last or origin.decode() != self._origins.get(name):
                # Not joined (yet: its token came, its join is on its way), or a new process of its robot.
                if name not in self._alive:
                    self.unannounced += 1
                    return
                self._skipped.add(name)  # asked for once the join is done: they may be the run's last
                if monotonic() - self._asked.get(name, 0.0) >= JOIN_AGAIN:  # its state did not answer
                    self._ask_join(name, keys.machine_key(robot, machine))
                return
            events = consecutive(loads(payload))
            if events[0]["seq"] > self._last[name] + 1:
                self._fill(robot, machine, self._last[name] + 1)
                if events[0]["seq"] > self._last[name] + 1:  # the robot did not answer in time: never past a gap
                    self._skipped.add(name)
                    if monotonic() - self._asked.get(name, 0.0) >= JOIN_AGAIN:  # its join asks again, unlocked
                        self._ask_join(name, keys.machine_key(robot, machine))
                    return
            self._deliver(name, events)

    def _proven(self, robot: str, key: str, proof: bytes, origin: bytes, payload: bytes) -> bool:
        """Whether a batch proves its robot's token; refused, counted and said when not."""
        token = self._token(robot)
        if token is None:
            if robot not in self._untrusted:
                self._untrusted.add(robot)
                print("fsmscope: the machines of robot %r are not shown: this dashboard has no token for it "
                      "(serve --zenoh-token %s=TOKEN)" % (robot, robot), file=sys.stderr, flush=True)
            self.refusals.count += 1
            return False
        if proofs.proven(token, proof, b"events", key, origin, payload):
            return True
        self.refusals.refused("a batch on %s that does not prove the token of robot %r" % (key, robot))
        return False

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
        answer = first_reply(self.session, keys.state_key(robot, machine), self._token(robot), QUERY_TIMEOUT)
        return None if answer is None else loads(answer)

    def _history(self, robot: str, machine: str, since: int) -> dict | None:
        """The robot's answer of the machine's events from ``since`` on; None when none came."""
        reply = first_reply(self.session, keys.history_key(robot, machine), self._token(robot), QUERY_TIMEOUT,
                            "since=%d" % since)
        if reply is None:
            return None
        history = loads(reply)
        if history["events"]:
            consecutive(history["events"])
        return history

    def _join(self, item: tuple[str, bytes]) -> None:
        """In the joins' thread, with a machine's state answer; its history asked without the lock: a
        machine seen alive, new, or back after a drop (what it missed), or from a new process (taken
        again)."""
        key, said = item
        robot, machine = keys.split(key)
        name = fleet_name(robot, machine)
        answer = loads(said)
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
        """A control for ``robot``'s ``machine``, proven with ``token``: its robot's proven answer,
        None when none came in time. A lease the robot took has this watcher beat for it."""
        fields = {"action": action, "params": params, "client": client, "dashboard": self.id,
                  "counter": next(self._counter), "origin": self._origins.get(fleet_name(robot, machine), "")}
        answer = control.ask(self.session, keys.control_key(robot, machine), token, fields, QUERY_TIMEOUT)
        if action == "lease" and answer is not None and answer.get("status") == 200:
            self.beats.keep(robot, token)
        return answer


def consecutive(events: list[dict]) -> list[dict]:
    """A robot's batch, whose seqs follow each other; ValueError when they do not."""
    first = events[0]["seq"]
    if type(first) is not int or any(event["seq"] != first + i for i, event in enumerate(events)):
        raise ValueError("a batch's seqs do not follow each other")
    return events
