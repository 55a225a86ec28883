"""Controls across the network: a dashboard asks a robot's machine for a control (preempt, hold,
initial state, start, the debugger's) as a Zenoh query on ``fsmscope/<robot>/<machine>/control``
whose payload is the control frame and the operator's token; the robot's process checks the token
itself, applies the frame to its own machine (``fsm.control.frames``: what the websocket publisher
applies too), which records a ``control`` event in its stream and its log, and answers with the
result: ``{"status": 2xx, "seq": ...}`` or ``{"status": 4xx, "detail": why}``.

Nothing on the network controls a machine without its robot's token: a robot started without one
refuses every control (403), and a wrong token is refused (403) before the frame is read further.

A dashboard whose operator holds a machine's lease says so with a ``lease`` control naming the
dashboard's session; the robot then watches that dashboard's liveliness token and, when it is gone
for the lease's ``after``, applies the deadman itself (``fsm.control.deadman``), as the websocket
publisher does when its connection is lost.
Tokens travel in the clear on ``tcp/`` endpoints: across networks you do not trust, use Zenoh's
``tls/`` endpoints (docs/fleet.md).
"""

from __future__ import annotations

import hmac
import queue
import sys
import threading
from typing import Any, Callable

import zenoh

from fsm.control.deadman import Deadmen
from fsm.control.frames import answer
from fsm.control.handle import MachineHandle
from fsm.observation.encoding import dumps, loads

from . import keys
from .query import first_reply

QUEUE = 256  # control queries waiting for the robot's worker before new ones are refused (503)
DEADMAN_CLIENT = "robot"  # the client of what the robot does on its own


def request(token: str, action: str, params: dict, client: str) -> bytes:
    """The query's payload for a control."""
    return dumps({"token": token, "action": action, "params": params, "client": client})


class RobotControls:
    """The robot's side: a queryable per machine feeds one worker thread (a control may block on the
    machine's locks, and a start waits for the last run to end: never in Zenoh's own threads)."""

    def __init__(self, token: str | None, settle: Callable[[], Any]) -> None:
        self.token = token
        self.settle = settle  # waits until the events a control caused are put: its answer comes after them
        self.handles: dict[str, MachineHandle] = {}
        self.refused = 0  # controls refused for their token
        self._session: zenoh.Session | None = None
        self._dashboards: zenoh.Subscriber | None = None  # their liveliness, watched from the first lease
        self._deadmen: dict[str, Deadmen] = {}  # a dashboard's session id: the leases it holds here
        self._lock = threading.Lock()
        self._queries: queue.Queue[tuple[str, zenoh.Query] | None] = queue.Queue(QUEUE)
        self._thread = threading.Thread(target=self._work, name="fsmscope-zenoh-control", daemon=True)
        self._thread.start()

    def declare(self, session: zenoh.Session, key: str, machine: str) -> zenoh.Queryable:
        """The queryable of ``machine``'s controls at ``key``."""
        self._session = session
        return session.declare_queryable(key, lambda query: self._take(machine, query))

    def close(self, timeout: float) -> None:
        """Answer the controls already asked (a preempt that ends the process's script is answered
        before the process ends), then stop."""
        self._queries.put(None)
        if self._thread is not threading.current_thread():
            self._thread.join(timeout)
        with self._lock:
            for deadmen in self._deadmen.values():
                deadmen.back(forget=True)
            if self._dashboards is not None:
                self._dashboards.undeclare()

    def offer(self, machine: str) -> dict | None:
        """What a dashboard is told of ``machine``'s controls: None when it takes none (no token, or
        not attached), else whether a start may run it again."""
        handle = self.handles.get(machine)
        return {"can_start": bool(handle.can_start)} if self.token and handle is not None else None

    def _take(self, machine: str, query: zenoh.Query) -> None:
        try:
            self._queries.put_nowait((machine, query))
        except queue.Full:
            self._reply(query, {"status": 503, "detail": "the robot has too many controls waiting"})

    def _work(self) -> None:
        while True:
            item = self._queries.get()
            if item is None:
                return
            machine, query = item
            self._reply(query, self.apply(machine, query.payload.to_bytes() if query.payload is not None else b""))

    def apply(self, machine: str, payload: bytes) -> dict:
        """The answer to a control query's payload: the token checked first, then the frame applied."""
        try:
            frame = loads(payload)
        except ValueError:
            frame = None
        if type(frame) is not dict:
            return {"status": 422, "detail": "a control query's payload must be a JSON object"}
        if not self._token_ok(frame.get("token")):
            self.refused += 1
            print("fsmscope: refused a control of %r over Zenoh: %s" % (machine, "wrong token" if self.token
                                                                         else "this robot has no control token"),
                  file=sys.stderr, flush=True)
            return {"status": 403, "detail": "wrong token for this robot's controls" if self.token
                    else "this robot was started without a control token: it takes no control"}
        if frame.get("action") == "lease":
            return self._lease(machine, frame.get("params"))
        fields = answer(self.handles, {"id": 0, "machine": machine, "action": frame.get("action"),
                                       "params": frame.get("params", {}), "client": frame.get("client", "")})[1]
        self.settle()
        return {key: value for key, value in fields.items() if key not in ("type", "id")}

    def _lease(self, machine: str, params: Any) -> dict:
        """A dashboard holds or released ``machine``'s lease: its deadman is armed while the dashboard's
        liveliness token is gone."""
        dashboard = params.get("dashboard") if type(params) is dict else None
        if type(dashboard) is not str or machine not in self.handles:
            return {"status": 422, "detail": "a lease names the dashboard's session and a machine of this robot"}
        with self._lock:
            deadmen = self._deadmen.get(dashboard)
            if deadmen is None:
                deadmen = self._deadmen[dashboard] = Deadmen(self.handles, DEADMAN_CLIENT, "dashboard " + dashboard)
            if self._dashboards is None and self._session is not None:
                self._dashboards = self._session.liveliness().declare_subscriber(keys.ALL_DASHBOARDS, self._seen)
        if not deadmen.said(dict(params, machine=machine)):
            return {"status": 422, "detail": "a lease says held (a boolean), after (seconds) and action "
                                             "(pause, preempt or none)"}
        return {"status": 200}

    def _seen(self, sample: zenoh.Sample) -> None:
        """A dashboard's liveliness token came or went (in Zenoh's thread: only arms or disarms timers)."""
        with self._lock:
            deadmen = self._deadmen.get(str(sample.key_expr).rsplit("/", 1)[-1])
        if deadmen is not None:
            if sample.kind == zenoh.SampleKind.DELETE:
                deadmen.lost()
            else:
                deadmen.back(forget=False)

    def _token_ok(self, token: Any) -> bool:
        return bool(self.token) and type(token) is str and hmac.compare_digest(token.encode(), self.token.encode())

    @staticmethod
    def _reply(query: zenoh.Query, fields: dict) -> None:
        try:
            query.reply(query.key_expr, dumps(fields))
        finally:
            query.drop()


def ask(session: zenoh.Session, key: str, token: str, action: str, params: dict, client: str,
        timeout: float) -> dict | None:
    """The dashboard's side: the robot's answer to a control (a dict with its ``status``), or None when
    no robot answered within ``timeout`` seconds."""
    reply = first_reply(session, key, timeout, request(token, action, params, client))
    if reply is None:
        return None
    try:
        fields = loads(reply)
    except ValueError:
        fields = None
    return fields if type(fields) is dict else {"status": 502, "detail": "the robot's answer is not a JSON object"}
