"""The debugger of one machine: pause, resume, step, breakpoints and forced outcomes, at transition
boundaries, each an event of the schema (kind ``debug``).

Containers call two gates, and only while the debugger is ``armed`` (paused, stepping, a breakpoint
set or an outcome forced): only then are the containers bound to it (their ``_debugger``), so a
machine with an idle debugger pays what one with none does, an attribute test per gate.

- ``before(container, label, state)``: the child is about to run. A breakpoint before it holds here.
  Returns an outcome forced on it before it ran (it is then not run), else None.
- ``after(container, label, state, outcome)``: the child returned. A pause, the end of a step and a
  breakpoint after it hold here, before the container takes the transition. Returns the outcome to
  take: a forced one replaces what the state returned.

A hold waits with the container's locks released, so a preempt still reaches a paused machine: a
preempt of the holding container ends the hold (and a machine being preempted never holds again
until the preempt is over). A state's own code is never interrupted: "paused" means no new
transition, the running state runs on until it returns.

One piece because the gates and the controls share one lock and one set of holds.
"""

from __future__ import annotations

import functools
import threading
import weakref
from dataclasses import dataclass
from typing import Any, Iterable

from ..observation import introspection, original, runtimes, structure
from ..observation.schema import build
from .breakpoint import Breakpoint, BreakpointError
from .condition import ConditionError

POLL = 0.05  # s between looks at a preempt or a shutdown while holding
_attached: "weakref.WeakKeyDictionary[Any, Debugger]" = weakref.WeakKeyDictionary()


class DebugError(ValueError):
    """A control the machine cannot take; ``problem`` says which kind: unknown-state, unknown-outcome,
    bad-breakpoint, not-active, not-paused, not-gated."""

    def __init__(self, problem: str, message: str) -> None:
        super().__init__(message)
        self.problem = problem
        self.message = message


@dataclass
class Hold:
    """A container holding one transition (``at="after"``: ``outcome`` is the one it will take) or
    a child's start (``at="before"``)."""

    path: str
    state: str
    at: str
    outcome: str | None
    reason: str
    detail: str
    released_by: str | None = None
    forced: tuple[str, str | None] | None = None  # (outcome, by) given while holding

    def to_dict(self) -> dict:
        return {"path": self.path, "state": self.state, "at": self.at, "outcome": self.outcome,
                "reason": self.reason, "detail": self.detail}


class Debugger:
    """Attach with ``Debugger(machine)``; controls are thread-safe and return at once."""

    def __init__(self, machine: Any, root_path: str | None = None) -> None:
        rep = introspection.reporter_of(machine)
        self.machine = machine
        self.root_path = root_path or (rep.root_path if rep is not None else introspection.DEFAULT_ROOT_PATH)
        self.armed = False
        self.mode = "run"
        self.level: str | None = None  # a step's container: it ends at that container's next transition
        self._paused_by: str | None = None  # who asked for the pause mode (None: a hold paused the machine)
        self._cond = threading.Condition()
        self._breakpoints: dict[str, tuple[Breakpoint, ...]] = {}
        self._forced: dict[str, tuple[str, str | None]] = {}  # state path: (outcome, by)
        self._holds: list[Hold] = []
        self._is_shutdown = runtimes.shutdown_check(machine)
        self._bind(None)
        _attached[machine] = self
        if original.is_original(machine):  # no global hook runs for it: its own start callback tells a new run
            machine.register_start_cb(self._on_original_start)
        else:
            introspection.add_global_hook(self._on_top_level_start)

    # What the page shows.
    def holds(self) -> list[dict]:
        with self._cond:
            return [h.to_dict() for h in self._holds]

    def breakpoints(self) -> list[dict]:
        return [bp.to_dict() for bps in self._breakpoints.values() for bp in bps]

    # Controls.
    def pause(self, by: str | None = None) -> None:
        """Hold at the next transition boundary anywhere in the machine."""
        with self._cond:
            self._set_mode("pause", None, by)

    def resume(self, by: str | None = None) -> None:
        with self._cond:
            self._set_mode("run", None, by)
            self._release(self._holds, "resume")

    def step(self, level: str | None = None, by: str | None = None) -> None:
        """Let one transition happen, then hold again: the next anywhere, or ``level``'s next (the
        container at that path: stepping over whatever runs inside it)."""
        if level is not None and not structure.is_container(self._state_at(level)):
            raise DebugError("unknown-state", "no container at %r to step at" % level)
        with self._cond:
            if self.mode == "run":
                raise DebugError("not-paused", "the machine is running: pause it before stepping")
            held = [h for h in self._holds if level is None or _within(h.path, level)] or self._holds
            self._set_mode("step", level, by)
            self._release(held[:1], "step")

    def force(self, state_path: str, outcome: str, by: str | None = None) -> None:
        """The state at ``state_path`` (active or holding) ends with ``outcome``: asked to preempt if it
        runs, its container then takes ``outcome`` whatever it returned; taken at once if it holds."""
        state = self._state_at(state_path)
        if state is None or state is self.machine:
            raise DebugError("unknown-state", "no state at %r" % state_path)
        self._check_gated(state, state_path)
        if outcome not in state.get_registered_outcomes():
            raise DebugError("unknown-outcome", "%r is not an outcome of %s (its outcomes: %s)"
                             % (outcome, state_path, sorted(map(str, state.get_registered_outcomes()))))
        parent_path, label = state_path.rsplit("/", 1)
        with self._cond:
            held = [h for h in self._holds if h.path == parent_path and h.state == label]
            if held:
                held[0].forced = (outcome, by)
                self._release(held, "force")
                return
            if label not in self._state_at(parent_path).get_active_states():
                raise DebugError("not-active", "%s is not active: only an active state's outcome can be forced"
                                 % state_path)
            self._forced[state_path] = (outcome, by)
            self._arm()
        preempt = getattr(state, "request_preempt", None)  # SMACH runs a state without one too
        if preempt is not None:
            preempt()

    def set_breakpoints(self, specs: Iterable[Any], by: str | None = None) -> list[dict]:
        """Replace every breakpoint; all or none: raises DebugError for the first that cannot be set."""
        chosen: dict[str, list[Breakpoint]] = {}
        for i, spec in enumerate(specs):
            try:
                bp = spec if isinstance(spec, Breakpoint) else Breakpoint.from_dict(spec)
            except BreakpointError as err:
                raise DebugError("bad-breakpoint", "breakpoint %d: %s" % (i, err)) from None
            state = self._state_at(bp.state)
            if state is None or state is self.machine:
                raise DebugError("unknown-state", "breakpoint %d: no state at %r" % (i, bp.state))
            self._check_gated(state, bp.state, "breakpoint %d: " % i)
            if bp.outcome is not None and bp.outcome not in state.get_registered_outcomes():
                raise DebugError("unknown-outcome", "breakpoint %d: %r is not an outcome of %s (its outcomes: %s)"
                                 % (i, bp.outcome, bp.state, sorted(map(str, state.get_registered_outcomes()))))
            if bp not in chosen.setdefault(bp.state, []):
                chosen[bp.state].append(bp)
        with self._cond:
            self._breakpoints = {path: tuple(bps) for path, bps in chosen.items()}
            self._arm()
            listed = self.breakpoints()
            self._emit(self.root_path, action="breakpoints", breakpoints=listed, by=by)
        return listed

    def detach(self) -> None:
        """Release every hold and stop gating: the machine runs as if no debugger had been attached."""
        introspection.remove_global_hook(self._on_top_level_start)
        if _attached.get(self.machine) is self:
            del _attached[self.machine]
        with self._cond:
            self._breakpoints, self._forced = {}, {}
            self._set_mode("run", None, None)
            self._release(self._holds, "detach")
        self._bind(None)

    # The gates (called by the containers, from the machine's threads).
    def before(self, container: Any, label: str, state: Any) -> str | None:
        path = container._path + "/" + label
        forced = self._forced.pop(path, None) if self._forced else None
        if forced is not None:
            _recall_preempt(state)
            self._emit(container._path, action="forced", state=label, outcome=forced[0], returned=None,
                       by=forced[1])
            return forced[0]
        if container.preempt_requested():
            return None
        hit = self._hit(container, path, "before", None)
        if hit is None:
            return None
        hold = self._hold(container, label, "before", None, "breakpoint", hit)
        return hold.forced[0] if hold.forced else None

    def after(self, container: Any, label: str, state: Any, outcome: str) -> str:
        path = container._path + "/" + label
        forced = self._forced.pop(path, None) if self._forced else None
        if forced is not None:
            _recall_preempt(state)
            self._emit(container._path, action="forced", state=label, outcome=forced[0],
                       returned=None if outcome is None else str(outcome), by=forced[1])
            outcome = forced[0]
        if container.preempt_requested():
            return outcome
        hit = self._hit(container, path, "after", outcome)
        if hit is None and self.mode == "run":  # armed by a breakpoint elsewhere: no lock to take
            return outcome
        with self._cond:
            if hit is not None:
                reason, detail = "breakpoint", hit
            elif self.mode == "step" and (self.level is None or self.level == container._path):
                reason, detail = "step", "stepped"
            elif self.mode == "pause":
                reason, detail = "pause", "paused by %s" % self._paused_by if self._paused_by else "paused"
            else:
                return outcome
        hold = self._hold(container, label, "after", outcome, reason, detail)
        return hold.forced[0] if hold.forced else outcome

    # Inside.
    def _hit(self, container: Any, path: str, at: str, outcome: Any) -> str | None:
        """The words of the first breakpoint at ``path`` that holds now, else None (conditions are
        evaluated outside the lock: a user's ``__eq__`` may take its time)."""
        for bp in self._breakpoints.get(path, ()):
            if bp.at != at or (bp.outcome is not None and bp.outcome != outcome):
                continue
            words = "hit breakpoint " + bp.describe(self.root_path)
            if bp.condition is None:
                return words
            try:
                if bp.condition.evaluate(lambda key: container.userdata[key]):
                    return words
            except ConditionError as err:
                return "%s: %s" % (words, err)
        return None

    def _hold(self, container: Any, label: str, at: str, outcome: Any, reason: str, detail: str) -> Hold:
        hold = Hold(container._path, label, at, None if outcome is None else str(outcome), reason, detail)
        report_changes = getattr(container, "_report_changes", None)  # fsm's: the original reports on its own
        if report_changes is not None:
            report_changes()  # what a hold shows is what its condition saw, not the last transition's
        with self._cond:
            self.mode, self.level = "pause", None  # said by the hold event: a held machine is paused
            self._arm()
            self._holds.append(hold)
        self._emit(container._path, action="hold", **{k: v for k, v in hold.to_dict().items() if k != "path"})
        with self._cond:
            while hold.released_by is None:
                if container.preempt_requested() or self._is_shutdown():
                    self._release([hold], "preempt" if container.preempt_requested() else "shutdown")
                    break
                self._cond.wait(POLL)
        forced = hold.forced
        if forced is not None:
            self._emit(container._path, action="forced", state=label, outcome=forced[0],
                       returned=hold.outcome, by=forced[1])
        self._emit(container._path, action="release", state=label, at=at,
                   outcome=forced[0] if forced else hold.outcome, by=hold.released_by)
        return hold

    def _release(self, holds: list[Hold], by: str) -> None:
        """Under the lock."""
        for hold in list(holds):
            hold.released_by = by
            self._holds.remove(hold)
        self._cond.notify_all()

    def _set_mode(self, mode: str, level: str | None, by: str | None) -> None:
        """Under the lock."""
        if (mode, level) == (self.mode, self.level):
            return
        self.mode, self.level = mode, level
        self._paused_by = by if mode == "pause" else None
        self._arm()
        self._emit(self.root_path, action="mode", mode=mode, level=level, by=by)

    def _arm(self) -> None:
        armed = self.mode != "run" or bool(self._breakpoints) or bool(self._forced)
        if armed != self.armed:
            self.armed = armed
            self._bind(self if armed else None)

    def _emit(self, path: str, **fields: Any) -> None:
        rep = introspection.reporter_of(self.machine)
        if rep is not None:
            rep.send(functools.partial(build.debug, **fields), path)

    def _check_gated(self, state: Any, path: str, prefix: str = "") -> None:
        """The original's containers gate a child through the wrapper of its ``execute``, which a state
        with ``__slots__`` cannot be given (fsm's containers gate every child themselves)."""
        if not hasattr(state, "__dict__") and original.is_original(self.machine):
            raise DebugError("not-gated", "%s%s takes no attribute (__slots__): its execute cannot be wrapped, so "
                                          "nothing can hold it or force its outcome" % (prefix, path))

    def _state_at(self, path: str) -> Any:
        if path == self.root_path:
            return self.machine
        if not isinstance(path, str) or not path.startswith(self.root_path + "/"):
            return None
        return structure.state_at(self.machine, path[len(self.root_path) + 1:].split("/"))

    def _bind(self, debugger: "Debugger | None") -> None:
        """Every container of the tree gates through ``debugger`` and knows its path."""
        stack = [(self.machine, self.root_path)]
        while stack:
            state, path = stack.pop()
            if getattr(state, "_path", None) is None:
                try:
                    state._path = path
                except AttributeError:  # a state with __slots__ (SMACH runs any object with its interface)
                    continue
            if structure.is_container(state):
                state._debugger = debugger
                stack.extend((child, path + "/" + str(label)) for label, child in structure.children(state).items())

    def _on_original_start(self, userdata: Any, initial_states: Any) -> None:
        if _attached.get(self.machine) is self:
            self._on_top_level_start(self.machine)

    def _on_top_level_start(self, container: Any) -> None:
        """A new run: the tree may have grown, and no force of the last run applies any more."""
        if container is self.machine:
            self._bind(self if self.armed else None)
            with self._cond:
                self._forced = {}
                self._arm()


def debugger_of(machine: Any) -> Debugger:
    """The machine's debugger, attached on first use (one per machine)."""
    return _attached.get(machine) or Debugger(machine)


def _recall_preempt(state: Any) -> None:
    """The preempt a force asked of ``state``, recalled; SMACH runs a state without preempt methods too."""
    recall = getattr(state, "recall_preempt", None)
    if recall is not None:
        recall()


def _within(path: str, level: str) -> bool:
    return path == level or path.startswith(level + "/")

