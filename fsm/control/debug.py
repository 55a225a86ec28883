"""The debugger's controls for a machine of this process: what a REST request can ask of
``fsm.debugging`` (docs/debugging.md), each answered with the ``control`` event it caused.

The runtime says what happened (``debug`` events); this says who asked and whether it was
taken (``control`` events), as every other control does. Like the other controls, the calls
may block briefly on the debugger's lock, so the app runs them in a worker thread.
``handle.MachineHandle`` composes it: this module knows only the machine and how to record.
"""

from __future__ import annotations

from typing import Any, Callable

from fsm.debugging import DebugError, debugger_of

from .controls import Refused

# The HTTP status of each kind of refusal: the request's content is wrong (422), or the machine
# is not in a state to take it (409).
STATUS = {"unknown-state": 422, "unknown-outcome": 422, "bad-breakpoint": 422, "not-gated": 422, "not-active": 409,
          "not-paused": 409}

# What records a control: (action, client, result, params=...) -> the control event's seq.
Record = Callable[..., int]


class DebugControl:
    """Pause, resume, step, force and breakpoints of ``machine``; ``record`` writes the control events."""

    def __init__(self, machine: Any, record: Record) -> None:
        self.record = record
        self.debugger = debugger_of(machine)

    def pause(self, client: str) -> int:
        return self._do("pause", client, {}, lambda: self.debugger.pause(by=client))

    def resume(self, client: str) -> int:
        return self._do("resume", client, {}, lambda: self.debugger.resume(by=client))

    def step(self, level: str | None, client: str) -> int:
        return self._do("step", client, {"level": level}, lambda: self.debugger.step(level, by=client))

    def force(self, state: str, outcome: str, client: str) -> int:
        return self._do("force", client, {"state": state, "outcome": outcome},
                        lambda: self.debugger.force(state, outcome, by=client))

    def set_breakpoints(self, breakpoints: list[Any], client: str) -> list[dict]:
        listed: list[dict] = []

        def replace() -> None:
            listed.extend(self.debugger.set_breakpoints(breakpoints, by=client))
        self._do("breakpoints", client, {"breakpoints": breakpoints}, replace)
        return listed

    def breakpoints(self) -> list[dict]:
        return self.debugger.breakpoints()

    def _do(self, action: str, client: str, params: dict, call: Callable[[], None]) -> int:
        """Run ``call``; the control event says it was accepted, or why not (then Refused)."""
        try:
            call()
        except DebugError as err:
            self.record(action, client, err.message, params=params)
            raise Refused(STATUS[err.problem], err.message) from None
        return self.record(action, client, "accepted", params=params)
