"""The publishing process's side of remote control (fsmscope/server/remote_control.py is the server's): a
control frame applied to a machine of this process through the same ``Controls`` (its
``MachineHandle``) a local machine's requests go through, and the deadman a publisher applies itself
when its connection to the dashboard is gone while an operator holds the machine's lease. The
websocket publisher (fsmscope/server/publisher.py) and the Zenoh robot (fsmscope/fleet/robot.py) both apply frames here.
"""

from __future__ import annotations

from typing import Any, Callable

from fsm.observation import schema

from .controls import Controls, Refused

DEADMAN_ACTIONS = schema.DEADMAN_ACTIONS  # what a deadman does when its lease lapses
MAX_AFTER = 86400.0  # a deadman's delay longer than a day is not one (and would overflow a timer's wait)
# The fields of the server's frames read here, as their definitions (schema/messages.py) name them.
_ID, _MACHINE, _ACTION, _PARAMS, _CLIENT = schema.field_names("control")
_LEASE_MACHINE, _HELD, _AFTER, _DEADMAN_ACTION = schema.field_names("lease")


class Params:
    """A control frame's ``params``, each read with its type checked: 422 saying which is wrong."""

    def __init__(self, params: Any) -> None:
        if type(params) is not dict:
            raise Refused(422, "%s must be an object" % _PARAMS)
        self.params = params

    def text(self, key: str) -> str:
        value = self.params.get(key)
        if type(value) is not str:
            raise Refused(422, "%s.%s must be a string" % (_PARAMS, key))
        return value

    def optional_text(self, key: str) -> str | None:
        value = self.params.get(key)
        if value is not None and type(value) is not str:
            raise Refused(422, "%s.%s must be a string or null" % (_PARAMS, key))
        return value

    def texts(self, key: str) -> list[str]:
        value = self.params.get(key, [])
        if type(value) is not list or any(type(item) is not str for item in value):
            raise Refused(422, "%s.%s must be a list of strings" % (_PARAMS, key))
        return value

    def object(self, key: str) -> dict:
        value = self.params.get(key) or {}
        if type(value) is not dict:
            raise Refused(422, "%s.%s must be an object" % (_PARAMS, key))
        return value

    def items(self, key: str) -> list:
        value = self.params.get(key, [])
        if type(value) is not list:
            raise Refused(422, "%s.%s must be a list" % (_PARAMS, key))
        return value


def _seq(status: int, call: Callable[[], int]) -> dict:
    return {"status": status, "seq": call()}


# What each action does, and the 2xx its answer has (docs/api.md: the statuses of the REST controls).
CONTROLS: dict[str, Callable[[Controls, Params, str], dict]] = {
    "preempt": lambda h, p, c: _seq(202, lambda: h.preempt(p.optional_text("reason"), c)),
    "hold": lambda h, p, c: _seq(202, lambda: h.hold(p.optional_text("reason"), c)),
    "initial-state": lambda h, p, c: _seq(200, lambda: h.set_initial_state(p.optional_text("path"), p.texts("states"),
                                                                            p.object("userdata"), c)),
    "start": lambda h, p, c: _seq(202, lambda: h.start(c)),
    "record": lambda h, p, c: _seq(200, lambda: h.emit_control(p.text("action"), c, p.text("result"),
                                                               p.optional_text("reason"), p.object("params"),
                                                               p.optional_text("path"))),
    "pause": lambda h, p, c: _seq(202, lambda: h.pause(c)),
    "resume": lambda h, p, c: _seq(202, lambda: h.resume(c)),
    "step": lambda h, p, c: _seq(202, lambda: h.step(p.optional_text("level"), c)),
    "force": lambda h, p, c: _seq(202, lambda: h.force(p.text("state"), p.text("outcome"), c)),
    "breakpoints": lambda h, p, c: {"status": 200,
                                    "breakpoints": h.set_breakpoints(p.items("breakpoints"), c)},
    "get-breakpoints": lambda h, p, c: {"status": 200, "breakpoints": h.breakpoints()},
}


def answer(handles: dict[str, Controls], frame: dict) -> tuple[str, dict] | None:
    """The answer to a control frame, with the machine it named (None: a frame with no id to answer).
    Never raises: what the request or the machine refused is the answer's 4xx and ``detail``."""
    answer_id = frame.get(_ID)
    if type(answer_id) is not int:
        return None
    machine, action, client = frame.get(_MACHINE), frame.get(_ACTION), frame.get(_CLIENT, "")
    handle = handles.get(machine) if type(machine) is str else None
    try:
        if handle is None:
            raise Refused(404, "no machine named %r publishes from this process" % (machine,))
        if type(client) is not str:
            raise Refused(422, "%s must be a string" % _CLIENT)
        control = CONTROLS.get(action) if type(action) is str else None
        if control is None:
            raise Refused(422, "unknown action %r (one of %s)" % (action, ", ".join(CONTROLS)))
        fields = control(handle, Params(frame.get(_PARAMS, {})), client)
    except Refused as err:
        fields = {"status": err.status, "detail": err.message}
    except Exception as exc:  # the machine's own code failed: say so, keep publishing
        fields = {"status": 409, "detail": "the publishing process failed: %s: %s" % (type(exc).__name__, exc)}
    return (machine if type(machine) is str else ""), schema.frame.answer(answer_id, **fields)


def lease_of(frame: dict) -> tuple[str, tuple[float, str] | None] | None:
    """What a ``lease`` frame says of its machine: (after, action) of the deadman to arm while the
    lease is held, or None to disarm it (released, or action none); None for a malformed frame."""
    machine, held, after, action = (frame.get(_LEASE_MACHINE), frame.get(_HELD), frame.get(_AFTER),
                                    frame.get(_DEADMAN_ACTION))
    if type(machine) is not str or type(held) is not bool or action not in DEADMAN_ACTIONS:
        return None
    if type(after) not in (int, float) or not 0 <= after <= MAX_AFTER:  # NaN fails the comparison too
        return None
    return machine, ((float(after), action) if held and action != "none" else None)


def apply_deadman(handle: Controls, action: str, client: str, reason: str, params: dict) -> None:
    """A deadman's ``action`` (pause or preempt), recorded first as a ``control`` event of the machine
    (action "deadman"); a pause or preempt refused (not running) is said by its own control event."""
    handle.emit_control("deadman", client, "accepted", reason=reason, params=dict(params, then=action))
    try:
        if action == "pause":
            handle.pause(client)
        elif action == "preempt":
            handle.preempt(reason, client)
    except Refused:
        pass
