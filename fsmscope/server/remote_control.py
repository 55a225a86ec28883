"""Controls of a machine that another process publishes (``server.publisher.Publisher``): its
``fsm.control.Controls``, each call sent as a frame over that process's ingest websocket and answered
by it (docs/api.md, "Ingest"), or asked of its robot over Zenoh (fsmscope/server/cli/fleet_bridge.py's link).
The publishing process applies them to its machine and emits the control events in its own stream,
so they reach this server, its log and the pages like its other events.

A call waits for the publisher's answer (at most ``ANSWER_TIMEOUT``): like a local control, it runs
in a worker thread, never on the event loop.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import itertools
import time
from typing import TYPE_CHECKING, Any, Awaitable, Callable, Protocol

from pydantic import ValidationError

from fsm.control.controls import Capabilities, Refused
from fsm.observation import schema
from fsm.observation.encoding import dumps

from .models import BreakpointSpec

if TYPE_CHECKING:
    from .hub import Hub, MachineEntry

ANSWER_TIMEOUT = 5.0  # seconds a control waits for the publishing process's answer (then 504)
# The fields of the publisher's frames read here, as their definitions (schema/messages.py) name them.
_CONTROLLABLE, _CAN_START = schema.field_names("hello")
_ANSWER_ID = schema.field_names("answer")[0]  # its first field: the control's id


NOT_CONNECTED = "the publishing process of %r is not connected: its controls are unavailable"


def not_connected(name: str) -> Refused:
    return Refused(409, NOT_CONNECTED % name)


class IngestLink:
    """One publisher's ingest connection, on the server's side: the machines it feeds, those it said
    take controls (its ``hello``), and the controls waiting for its answer."""

    def __init__(self, hub: Hub, send_text: Callable[[str], Awaitable[None]],
                 loop: asyncio.AbstractEventLoop) -> None:
        self.hub = hub
        self.loop = loop
        self.closed = False
        self.fed: set[str] = set()  # the machines it feeds: shown disconnected when it leaves
        self.controllable: dict[str, bool] = {}  # name: can_start, as its last hello said
        self._send_text = send_text
        self._send_lock = asyncio.Lock()
        self._ids = itertools.count(1)
        self._pending: dict[int, tuple[str, concurrent.futures.Future]] = {}

    # On the loop.
    async def send(self, frame: dict) -> None:
        async with self._send_lock:  # one frame at a time: the route's answers and the controls share the socket
            await self._send_text(dumps(frame).decode())

    def feeds(self, entry: MachineEntry) -> None:
        """An event of ``entry``'s machine came through this connection."""
        entry.origin.connected = True
        if entry.name not in self.fed:
            self.fed.add(entry.name)
            self._bind(entry)

    def hello(self, frame: dict) -> str | None:
        """The publisher says which of its machines take controls; returns what is wrong with the frame."""
        names, can_start = frame.get(_CONTROLLABLE), frame.get(_CAN_START, {})
        if type(names) is not list or any(type(name) is not str for name in names):
            return "hello.%s must be a list of machine names" % _CONTROLLABLE
        if type(can_start) is not dict:
            return "hello.%s must be an object" % _CAN_START
        self.controllable = {name: can_start.get(name) is True for name in names}
        for name in self.fed:
            self._bind(self.hub.get(name))
        return None

    def answer(self, frame: dict) -> str | None:
        """The publisher's answer to a control; one nobody waits for any more (too late) is dropped."""
        answer_id = frame.get(_ANSWER_ID)
        if type(answer_id) is not int:
            return "answer.%s must be an integer" % _ANSWER_ID
        waiting = self._pending.get(answer_id)
        if waiting is not None and not waiting[1].done():
            waiting[1].set_result(frame)
        return None

    def close(self) -> None:
        """The connection ended: its machines are shown disconnected, their controls answer 409."""
        self.closed = True
        for name in self.fed:
            entry = self.hub.get(name)
            if entry is None or entry.origin.source != "ingest":
                continue
            entry.origin.connected = False
            controls = entry.controls
            if isinstance(controls, RemoteHandle) and controls.link is self:
                controls.link = None
        for name, future in list(self._pending.values()):
            if not future.done():
                future.set_exception(not_connected(name))

    def _bind(self, entry: MachineEntry | None) -> None:
        if entry is None or entry.origin.source != "ingest" or entry.name not in self.controllable:
            return
        remote_controls(entry).bind(self)

    # From any thread.
    def post(self, frame: dict) -> None:
        """Send ``frame`` without waiting (from the loop's thread too); a socket or loop already gone
        has nobody to tell."""
        if self.closed:
            return
        try:
            asyncio.run_coroutine_threadsafe(self.send(frame), self.loop)
        except RuntimeError:  # the loop is closed: the server is stopping
            pass

    # In a worker thread.
    def ask(self, machine: str, action: str, params: dict, client: str) -> dict:
        """Send a control and wait for its answer: the answer's frame when it took it (2xx), else
        Refused with the publisher's status and message (or 409/502/504 saying what failed)."""
        answer_id = next(self._ids)
        future: concurrent.futures.Future = concurrent.futures.Future()
        self._pending[answer_id] = (machine, future)
        deadline = time.monotonic() + ANSWER_TIMEOUT
        try:
            if self.closed:
                raise not_connected(machine)
            frame = schema.frame.control(answer_id, machine, action, params, client)
            try:
                asyncio.run_coroutine_threadsafe(self.send(frame), self.loop).result(ANSWER_TIMEOUT)
            except TimeoutError:
                raise self._late(machine) from None
            except Exception:  # the socket or the loop is gone
                raise not_connected(machine) from None
            try:
                answer = future.result(max(0.0, deadline - time.monotonic()))
            except TimeoutError:
                raise self._late(machine) from None
        finally:
            self._pending.pop(answer_id, None)
        return taken(machine, answer)

    @staticmethod
    def _late(machine: str) -> Refused:
        return Refused(504, "the publishing process of %r did not answer within %g s" % (machine, ANSWER_TIMEOUT))


def taken(machine: str, answer: dict) -> dict:
    """``answer`` when it says the control was taken (2xx); else Refused with the machine's status
    and message for a refusal (4xx), or 502 for an answer that says neither."""
    status = answer.get("status")
    if type(status) is int and 400 <= status < 500:
        detail = answer.get("detail")
        raise Refused(status, detail if type(detail) is str else "refused by the publishing process")
    if status not in (200, 202):
        raise malformed(machine, "status %r" % (status,))
    return answer


def malformed(machine: str, what: str) -> Refused:
    return Refused(502, "the publishing process of %r answered with a malformed %s" % (machine, what))


def remote_controls(entry: MachineEntry) -> RemoteHandle:
    """The entry's RemoteHandle, made its controls the first time its door binds a link."""
    if not isinstance(entry.controls, RemoteHandle):
        entry.controls = RemoteHandle(entry.name)
    return entry.controls


class Link(Protocol):
    """How a RemoteHandle reaches the machine's process: an ``IngestLink``, or a fleet_bridge.FleetLink."""

    @property
    def closed(self) -> bool: ...

    @property
    def controllable(self) -> dict[str, bool]: ...

    def ask(self, machine: str, action: str, params: dict, client: str) -> dict: ...

    def post(self, frame: dict) -> None: ...


class RemoteHandle:
    """The ``Controls`` of an ingested machine whose publisher takes them, each answered by the
    publishing process. Kept as the machine's entry's controls across reconnections (``link``: the
    connection now, None while its publisher is away)."""

    held = False  # its publisher holds it: the page is not told (can_hold is false)

    def __init__(self, name: str) -> None:
        self.name = name
        self.link: Link | None = None
        self._lease: dict | None = None  # the last lease frame: said again when the publisher comes back

    def bind(self, link: Link) -> None:
        self.link = link
        if self._lease is not None:
            link.post(self._lease)

    def capabilities(self) -> Capabilities:
        link = self.link
        if link is None or link.closed:
            return Capabilities(unavailable=NOT_CONNECTED % self.name)
        cannot = {"hold": "the publishing process of %r does not say whether it runs the machine in a loop"
                          % self.name}
        if not link.controllable.get(self.name, False):
            cannot["start"] = "the publishing process of %r cannot re-run the machine" % self.name
        return Capabilities(cannot=cannot)

    def lease_changed(self, held: bool, after: float, action: str) -> None:
        """Tell the publisher (fsmscope/server/lease.py calls this): while a lease is held, it applies ``action``
        itself when its connection to this server is gone for ``after`` seconds."""
        self._lease = schema.frame.lease(self.name, bool(held), float(after), action)
        link = self.link
        if link is not None:
            link.post(self._lease)

    # The controls (docs/api.md): each the seq of the control event it caused in the publisher's stream.
    def preempt(self, reason: str | None, client: str) -> int:
        return self._seq("preempt", {"reason": reason}, client)

    def hold(self, reason: str | None, client: str) -> int:
        return self._seq("hold", {"reason": reason}, client)

    def set_initial_state(self, path: str | None, states: list[str], userdata: dict | None, client: str) -> int:
        return self._seq("initial-state", {"path": path, "states": states, "userdata": userdata or {}}, client)

    def start(self, client: str) -> int:
        return self._seq("start", {}, client)

    def emit_control(self, action: str, client: str, result: str, reason: str | None = None,
                     params: dict | None = None, path: str | None = None) -> int:
        """A control event in the machine's stream, written by its publishing process (its seqs are its own)."""
        return self._seq("record", {"action": action, "result": result, "reason": reason, "params": params or {},
                                    "path": path}, client)

    def pause(self, client: str) -> int:
        return self._seq("pause", {}, client)

    def resume(self, client: str) -> int:
        return self._seq("resume", {}, client)

    def step(self, level: str | None, client: str) -> int:
        return self._seq("step", {"level": level}, client)

    def force(self, state: str, outcome: str, client: str) -> int:
        return self._seq("force", {"state": state, "outcome": outcome}, client)

    def set_breakpoints(self, breakpoints: list[Any], client: str) -> list[dict]:
        return self._breakpoints(self._ask("breakpoints", {"breakpoints": breakpoints}, client))

    def breakpoints(self) -> list[dict]:
        return self._breakpoints(self._ask("get-breakpoints", {}, ""))

    def _ask(self, action: str, params: dict, client: str) -> dict:
        link = self.link
        if link is None or link.closed:
            raise not_connected(self.name)
        return link.ask(self.name, action, params, client)

    def _seq(self, action: str, params: dict, client: str) -> int:
        seq = self._ask(action, params, client).get("seq")
        if type(seq) is not int or seq < 0:
            raise malformed(self.name, "seq")
        return seq

    def _breakpoints(self, answer: dict) -> list[dict]:
        listed = answer.get("breakpoints")
        if type(listed) is not list:
            raise malformed(self.name, "breakpoints list")
        try:
            return [BreakpointSpec.model_validate(bp).model_dump() for bp in listed]
        except ValidationError:
            raise malformed(self.name, "breakpoint") from None
