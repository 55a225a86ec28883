"""The controls every kind of machine takes, and the one way each says no.

A dashboard's routes, the lease's deadman and the control frames call a machine only through
``Controls``: a machine of this process (``handle.MachineHandle``), one another process publishes
(fsmscope/server/remote_control.py's ``RemoteHandle``, over its websocket or Zenoh), and whatever kind comes
next implements the same calls. Each control returns the seq of the ``control`` event it caused
in the machine's stream, or raises ``Refused`` with the HTTP status a server answers it with and
the message the operator reads; a server maps ``Refused`` to HTTP in one place.

A kind of machine that cannot do something says so in its ``capabilities()`` (with why, the
message its refusal carries), so a page can grey the button out before anyone presses it; the
call itself still refuses (``Refused(409, why)``), and records that it did when it can.
tests/unit/test_controls.py checks that every kind has every call with the protocol's parameters.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping, Protocol

# The controls a page can ask for, as capabilities (and the control frames) name them.
ACTIONS = ("preempt", "hold", "initial-state", "start", "pause", "resume", "step", "force", "breakpoints")


class Refused(Exception):
    """A request a machine (or its history) does not take now: ``status`` is the HTTP status to answer
    (404 nothing there, 409 not now, 410 no longer kept, 416 not yet, 422 the request is wrong, 502/504
    its publishing process answered wrongly or not at all), ``message`` says why in words."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status
        self.message = message


@dataclass(frozen=True)
class Capabilities:
    """What a machine's controls take now: ``unavailable`` says why none is (None: they are), ``cannot``
    why each action it never takes is not taken."""

    unavailable: str | None = None
    cannot: Mapping[str, str] = field(default_factory=dict)

    def can(self, action: str) -> bool:
        return self.unavailable is None and action not in self.cannot


class Controls(Protocol):
    """What a control request can ask of a machine. The calls may block (on the machine's locks, or
    waiting for its publishing process), so a server runs them in a worker thread, never on its loop.
    ``client`` says who asked, as the control event records it."""

    @property
    def held(self) -> bool:
        """A hold was asked and no start has come since."""

    def capabilities(self) -> Capabilities: ...

    def preempt(self, reason: str | None, client: str) -> int: ...

    def hold(self, reason: str | None, client: str) -> int:
        """Let the current run finish, then start no other until the next start."""

    def set_initial_state(self, path: str | None, states: list[str], userdata: dict | None, client: str) -> int: ...

    def start(self, client: str) -> int: ...

    def pause(self, client: str) -> int: ...

    def resume(self, client: str) -> int: ...

    def step(self, level: str | None, client: str) -> int: ...

    def force(self, state: str, outcome: str, client: str) -> int: ...

    def breakpoints(self) -> list[dict]: ...

    def set_breakpoints(self, breakpoints: list[Any], client: str) -> list[dict]:
        """Replace the whole set, all or none; the set as the debugger holds it."""

    def emit_control(self, action: str, client: str, result: str, reason: str | None = None,
                     params: dict | None = None, path: str | None = None) -> int:
        """A ``control`` event in the machine's stream (what the lease and the bus record)."""

    def lease_changed(self, held: bool, after: float, action: str) -> None:
        """A page took (``held``) or gave up its lease: a machine whose process applies the deadman
        itself is told its ``after`` and ``action``."""


class NoControls:
    """The controls of a machine nothing here can control (a replay, another process's machine that
    takes none): every call is refused with ``why``, 409."""

    held = False

    def __init__(self, why: str) -> None:
        self.why = why

    def capabilities(self) -> Capabilities:
        return Capabilities(unavailable=self.why)

    def _refuse(self, *args: Any, **kwargs: Any) -> Any:
        raise Refused(409, self.why)

    preempt = hold = set_initial_state = start = pause = resume = step = force = _refuse
    breakpoints = set_breakpoints = emit_control = _refuse

    def lease_changed(self, held: bool, after: float, action: str) -> None:
        """Nobody to tell."""
