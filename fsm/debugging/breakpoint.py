"""A breakpoint: where a machine holds (before a state runs, or after it returned, optionally a given
outcome), and on which condition of its container's userdata."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..observation.schema import BREAKPOINT_FIELDS, POSITIONS
from .condition import Condition, ConditionError

FIELDS = tuple(f.name for f in BREAKPOINT_FIELDS)  # its JSON form's (fsm/observation/schema/status.py)


class BreakpointError(ValueError):
    """A breakpoint that cannot be set; ``field`` names the part at fault."""

    def __init__(self, message: str, field: str) -> None:
        super().__init__(message)
        self.field = field


@dataclass(frozen=True)
class Breakpoint:
    """``state`` is the state's path (``/SM_ROOT/PICK/CLOSE``); ``outcome`` only for ``at="after"``;
    ``when`` a condition (fsm.debugging.condition) over the userdata of the state's container;
    a blank one (``""``, spaces) is none, as null is."""

    state: str
    at: str = "before"
    outcome: str | None = None
    when: str | None = None
    condition: Condition | None = field(default=None, compare=False, repr=False)

    @classmethod
    def from_dict(cls, spec: Any) -> "Breakpoint":
        """A breakpoint from its JSON form; raises BreakpointError saying what is wrong."""
        if not isinstance(spec, dict):
            raise BreakpointError("a breakpoint must be an object", "breakpoint")
        unknown = sorted(set(spec) - set(FIELDS))
        if unknown:
            raise BreakpointError("unknown fields %s (a breakpoint has %s)" % (unknown, ", ".join(FIELDS)), unknown[0])
        state, at = spec.get("state"), spec.get("at", "before")
        outcome, when = spec.get("outcome"), spec.get("when")
        if not isinstance(state, str) or not state.startswith("/"):
            raise BreakpointError("state must be a state's path, such as /SM_ROOT/PICK", "state")
        if at not in POSITIONS:
            raise BreakpointError("at must be 'before' or 'after', not %r" % (at,), "at")
        if outcome is not None and (not isinstance(outcome, str) or at != "after"):
            raise BreakpointError("outcome must be a string, and only for a breakpoint after the state", "outcome")
        if when is not None and not isinstance(when, str):
            raise BreakpointError("when must be a condition's text", "when")
        when = (when or "").strip() or None  # blank: no condition, as the page's dialog sends it
        try:
            condition = Condition(when) if when else None
        except ConditionError as err:
            raise BreakpointError("when: %s" % err, "when") from None
        return cls(state, at, outcome, when, condition)

    def to_dict(self) -> dict:
        """Its JSON form, the schema's breakpoint."""
        return {name: getattr(self, name) for name in FIELDS}

    def describe(self, root_path: str) -> str:
        """In words, the state named from below the root: ``before PICK/CLOSE when attempts > 2``."""
        where = self.state[len(root_path) + 1:] if self.state.startswith(root_path + "/") else self.state
        words = "%s %s" % (self.at, where)
        if self.outcome is not None:
            words += " with outcome '%s'" % self.outcome
        if self.when:
            words += " when " + self.when
        return words
