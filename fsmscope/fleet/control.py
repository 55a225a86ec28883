"""Controls across the network: a dashboard asks a robot's machine for a control (preempt, hold,
initial state, start, the debugger's) as a Zenoh query on ``fsmscope/<robot>/<machine>/control``
whose payload is the control's request and whose attachment is the request's proof of the robot's
token (fsmscope/fleet/proofs.py): the token itself never leaves the processes that hold it. The request names
the robot's process it is for (its session id, which the robot's state answer carries) and the
dashboard's session with a counter, so the robot takes each request once, and only in the process
it was made for. The robot applies the frame to its own machine (``fsm.control.frames``: what the
websocket publisher applies too), which records a ``control`` event in its stream and its log, and
answers with the result, ``{"status": 2xx, "seq": ...}`` or ``{"status": 4xx, "detail": why}``, and
its proof over the request's: a stranger's answer is refused by the dashboard (``ask`` returns None:
no authenticated answer), and so is a robot's answer to another request.

A request without the proof (a wrong token, a replay, a stranger) is refused where it arrives, before
it is queued for the robot's worker, with an error reply that proves nothing (a dashboard could
trust none) and a line on stderr at each doubling of the count (``proofs.Tally``). A robot started with ``controls=False``
refuses every control (403, with its proof).

A dashboard whose operator holds a machine's lease says so with a ``lease`` control; from then on
it puts a heartbeat for the robot every ``BEAT`` seconds (fsmscope/fleet/beats.py), proven with the robot's
token and counted. The robot applies the deadman itself (``fsm.control.deadman``) when no fresh
beat of that dashboard came for ``BEAT_LOST`` and then the lease's ``after``, as the websocket
publisher does when its connection is lost. A stranger's beats, or a dead dashboard's beats played
again, do not keep a lease alive.
"""

from __future__ import annotations

import queue
import threading
from time import monotonic
from typing import Any, Callable

import zenoh

from fsm.control.deadman import Deadmen
from fsm.control.frames import answer
from fsm.control.handle import MachineHandle
from fsm.observation.encoding import dumps, loads

from . import keys, proofs
from .query import first_reply, reply

QUEUE = 256  # proven control queries waiting for the robot's worker before new ones are refused (503)
DEADMAN_CLIENT = "robot"  # the client of what the robot does on its own
BEAT = 0.5  # seconds between a leasing dashboard's heartbeats
BEAT_LOST = 1.5  # seconds without a fresh beat before the dashboard is taken as lost (its deadmen armed)


def request(token: str, key: str, fields: dict) -> tuple[bytes, bytes]:
    """A control query's payload and its proof."""
    payload = dumps(fields)
    return payload, proofs.sign(token, b"control", key, payload)


class _Dashboard:
    """A dashboard that holds leases here: its deadmen, and when its last fresh beat came."""

    def __init__(self, deadmen: Deadmen) -> None:
        self.deadmen = deadmen
        self.beat = monotonic()  # the lease told counts as a beat
        self.counter = 0  # of its last fresh beat
        self.lost = False


class RobotControls:
    """The robot's side: a queryable per machine feeds one worker thread (a control may block on the
    machine's locks, and a start waits for the last run to end: never in Zenoh's own threads); the
    worker also watches the beats of the dashboards that hold leases."""

    def __init__(self, robot: str, token: str, takes: bool, settle: Callable[[], Any]) -> None:
        self.robot = robot
        self.token = token
        self.takes = takes  # False: every control refused
        self.settle = settle  # waits until the events a control caused are put: its answer comes after them
        self.origin = ""  # the robot's session id, once declared: a request must name it
        self.handles: dict[str, MachineHandle] = {}
        self.refusals = proofs.Tally("fsmscope: robot %r" % robot)  # controls without the token's proof
        self._window = proofs.ReplayWindow()
        self._session: zenoh.Session | None = None
        self._beats: zenoh.Subscriber | None = None  # the leasing dashboards', subscribed at the first lease
        self._dashboards: dict[str, _Dashboard] = {}  # a dashboard's session id: its leases here
        self._lock = threading.Lock()
        self._queries: queue.Queue[tuple[str, zenoh.Query, dict] | None] = queue.Queue(QUEUE)
        self._thread = threading.Thread(target=self._work, name="fsmscope-zenoh-control", daemon=True)
        self._thread.start()

    @property
    def refused(self) -> int:
        """Controls refused for their proof (a wrong token, a replay, a stranger's)."""
        return self.refusals.count

    def declare(self, session: zenoh.Session, key: str, machine: str) -> zenoh.Queryable:
        """The queryable of ``machine``'s controls at ``key``."""
        self._session = session
        self.origin = str(session.zid())
        return session.declare_queryable(key, lambda query: self._take(machine, query))

    def close(self, timeout: float) -> None:
        """Answer the controls already asked (a preempt that ends the process's script is answered
        before the process ends), then stop."""
        self._queries.put(None)
        if self._thread is not threading.current_thread():
            self._thread.join(timeout)
        with self._lock:
            for dashboard in self._dashboards.values():
                dashboard.deadmen.back(forget=True)
            if self._beats is not None:
                self._beats.undeclare()

    def offer(self, machine: str) -> dict | None:
        """What a dashboard is told of ``machine``'s controls: None when it takes none, else whether a
        start may run it again."""
        handle = self.handles.get(machine)
        return {"can_start": bool(handle.can_start)} if self.takes and handle is not None else None

    def _take(self, machine: str, query: zenoh.Query) -> None:
        """In Zenoh's thread: a request proven and fresh is queued for the worker; any other is
        refused here, unanswered."""
        key = str(query.key_expr)
        payload = query.payload.to_bytes() if query.payload is not None else b""
        proof = query.attachment.to_bytes() if query.attachment is not None else None
        fields = None
        if proofs.proven(self.token, proof, b"control", key, payload):
            try:
                fields = loads(payload)
            except ValueError:
                pass
        if type(fields) is not dict or fields.get("origin") != self.origin:
            self._refuse(query, "a control of %r that does not prove this robot's token" % machine)
            return
        sender, counter = fields.get("dashboard"), fields.get("counter")
        with self._lock:
            fresh = type(sender) is str and type(counter) is int and self._window.take(sender, counter)
        if not fresh:
            self._refuse(query, "a control of %r played again" % machine)
            return
        try:
            self._queries.put_nowait((machine, query, fields))
        except queue.Full:
            self._reply(query, proof, {"status": 503, "detail": "the robot has too many controls waiting"})

    def _refuse(self, query: zenoh.Query, what: str) -> None:
        """A control refused for its proof: counted, and answered with an error that proves nothing
        (the dashboard that sent it stops waiting, and says it had no authenticated answer)."""
        self.refusals.refused(what)
        try:
            query.reply_err(b"refused: the control does not prove this robot's token, or was taken before")
        finally:
            query.drop()

    def _work(self) -> None:
        while True:
            try:
                item = self._queries.get(timeout=BEAT / 2)
            except queue.Empty:
                item = ()
            self._check_beats()
            if item is None:
                return
            if item:
                machine, query, fields = item
                self._reply(query, query.attachment.to_bytes(), self.apply(machine, fields))

    def apply(self, machine: str, fields: dict) -> dict:
        """The answer to a proven request: its frame applied to ``machine``."""
        if not self.takes:
            return {"status": 403, "detail": "this robot was started without controls: it takes none"}
        if fields.get("action") == "lease":
            return self._lease(machine, fields["dashboard"], fields.get("params"))
        result = answer(self.handles, {"id": 0, "machine": machine, "action": fields.get("action"),
                                       "params": fields.get("params", {}), "client": fields.get("client", "")})[1]
        self.settle()
        return {key: value for key, value in result.items() if key not in ("type", "id")}

    def _lease(self, machine: str, dashboard: str, params: Any) -> dict:
        """A dashboard holds or released ``machine``'s lease: its deadman is armed while the dashboard's
        beats have stopped."""
        if type(params) is not dict or machine not in self.handles:
            return {"status": 422, "detail": "a lease names a machine of this robot"}
        with self._lock:
            known = self._dashboards.get(dashboard)
            if known is None:
                known = self._dashboards[dashboard] = _Dashboard(
                    Deadmen(self.handles, DEADMAN_CLIENT, "dashboard " + dashboard))
            known.beat = monotonic()
            if self._beats is None and self._session is not None:
                self._beats = self._session.declare_subscriber(keys.beats_for(self.robot), self._beat)
        if not known.deadmen.said(dict(params, machine=machine)):
            return {"status": 422, "detail": "a lease says held (a boolean), after (seconds) and action "
                                             "(pause, preempt or none)"}
        return {"status": 200}

    def _beat(self, sample: zenoh.Sample) -> None:
        """A dashboard's heartbeat (in Zenoh's thread): taken when proven and newer than its last."""
        key = str(sample.key_expr)
        payload = sample.payload.to_bytes()
        proof = sample.attachment.to_bytes() if sample.attachment is not None else None
        if not proofs.proven(self.token, proof, b"beat", key, payload):
            self.refusals.refused("a heartbeat on %s without this robot's token's proof" % key)
            return
        with self._lock:
            dashboard = self._dashboards.get(keys.beat_sender(key))
            if dashboard is None or not payload.isdigit() or int(payload) <= dashboard.counter:
                return
            dashboard.counter = int(payload)
            dashboard.beat = monotonic()
            back, dashboard.lost = dashboard.lost, False
        if back:
            dashboard.deadmen.back(forget=False)

    def _check_beats(self) -> None:
        """In the worker: arm the deadmen of each dashboard whose beats stopped."""
        now = monotonic()
        with self._lock:
            lost = [dashboard for dashboard in self._dashboards.values()
                    if not dashboard.lost and now - dashboard.beat > BEAT_LOST]
            for dashboard in lost:
                dashboard.lost = True
        for dashboard in lost:
            dashboard.deadmen.lost()

    def _reply(self, query: zenoh.Query, proof: bytes, fields: dict) -> None:
        try:
            reply(query, self.token, dumps(fields), proof.hex())
        finally:
            query.drop()


def ask(session: zenoh.Session, key: str, token: str, fields: dict, timeout: float) -> dict | None:
    """The dashboard's side: the robot's proven answer to a request (``fields``: the action, its
    params and client, the robot's origin, the dashboard and its counter), a dict with its
    ``status``; None when no proven answer came within ``timeout`` seconds."""
    payload, proof = request(token, key, fields)
    answered = first_reply(session, key, token, timeout, payload=payload, attachment=proof,
                           nonce_of=lambda said: proof.hex())
    if answered is None:
        return None
    try:
        result = loads(answered)
    except ValueError:
        result = None
    return result if type(result) is dict else {"status": 502, "detail": "the robot's answer is not a JSON object"}
