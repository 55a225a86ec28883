"""One container of a machine of the original SMACH, watched: its callbacks and its children's calls
made into the events an fsm container reports (docs/events.md).

One piece because a container's callbacks and its children's wrapped calls share one record of the
run (the last outcome, the failure, the outcomes of a Concurrence's children).

The original tells a container's start, transitions and termination through the callbacks it offers
(``register_start_cb``, ``register_transition_cb``, ``register_termination_cb``, as smach_ros's
IntrospectionServer uses them); not which outcome caused a transition, what a child raised, nor
when a preempt was serviced. Those only the calls themselves tell: ``Watched`` stands for a state's
``execute`` (an attribute of the instance, calling the method it replaces with the same arguments
and returning what it returns), ``PreemptWatched`` for its ``request_preempt`` or
``service_preempt``. A leaf of a StateMachine whose outcome the container's edges tell (exactly
one of its outcomes leads to each place it leads to: the transition or termination callback says
the place) is called through ``Watched.leaf``, which watches only what the edges cannot tell: an
exception, and an armed debugger's gates. Nothing here changes what the machine does: every hook
calls through, returns the same value or lets the same exception out, and what goes wrong in
observing is said once on stderr (``Reporter._failed``).

The debugger's gates (fsm/debugging/debugger.py) are called as fsm's containers call them: before
and after a child's ``execute``, when the container has a ``_debugger``.
"""

from __future__ import annotations

import threading
import traceback
from typing import Any

from ..core import reporting
from .introspection import _words
from .original_userdata import UserdataWatch
from .schema import ABSENT, build
from .structure import is_concurrence


Leads = dict[str, tuple[dict[str, "str | None"], dict[str, "str | None"]]]


def _leads(container: Any) -> tuple[Leads, frozenset[str]]:
    """Where each child's outcomes lead: per child, {next child: outcome} and, in a StateMachine of
    the original, {machine's outcome: outcome} (as its ``_update_once`` takes an outcome out of the
    machine: to the target if it is one of the machine's outcomes, else to the outcome itself), None
    where two of its outcomes lead there; and the children of a StateMachine whose outcome these
    tell, each place they lead to being led to by one outcome. None of either for a Concurrence."""
    if is_concurrence(container):
        return {}, frozenset()
    machine = callable(getattr(container, "_update_once", None))
    below = {str(label) for label in container.get_children()}
    ends = {str(o) for o in container.get_registered_outcomes()}
    leads: Leads = {}
    for outcome, frm, to in container.get_internal_edges():
        outcome, to = str(outcome), None if to is None else str(to)
        to_child, to_end = leads.setdefault(str(frm), ({}, {}))
        if to in below:
            to_child[to] = None if to in to_child else outcome
        elif machine:
            end = to if to in ends else outcome
            if end in ends:
                to_end[end] = None if end in to_end else outcome
    told = frozenset(label for label, (to_child, to_end) in leads.items()
                     if machine and None not in to_child.values() and None not in to_end.values())
    return leads, told


def _labels(states: Any) -> list[str]:
    """A callback's states as a list of strings (the original's Iterator gives one label, not a list)."""
    if states is None:
        return []
    if isinstance(states, str):
        return [states]
    return [str(s) for s in states]


class ContainerWatch:
    """The events of one container: made from its callbacks and its children's wrapped calls."""

    def __init__(self, container: Any) -> None:
        self.container = container
        self.rep: Any = None  # the reporter and path it reports for (set by each description)
        self.path = ""
        self.context: tuple[Any, str] | None = None  # (rep, path): the thread's context inside it
        self.is_root = False
        self.concurrent = is_concurrence(container)
        self.userdata = UserdataWatch()
        self._lock = threading.RLock()  # a Concurrence's children call in from their threads
        self.active = [s for s in _labels(container.get_active_states()) if s != "None"]  # it may be running
        self.entered = False  # its execute (wrapped) runs: whether it runs, for its controls (runtimes.is_running)
        self.started = False  # its start callback came in this run
        self.ended = False  # its terminate event was sent in this run
        self.last: tuple[str, str] | None = None  # the (label, outcome) a child returned last
        self.failure: tuple[str, BaseException] | None = None  # the first child that raised in this run
        self.finished: list[str] = []  # a Concurrence's children in the order they returned
        self.outcomes: dict[str, str | None] = {}  # a Concurrence's children's outcomes, reported
        self.leads, self.told = _leads(container)  # where its children's outcomes lead; whose the edges tell
        container.register_start_cb(self._on_start)
        container.register_transition_cb(self._on_transition)
        container.register_termination_cb(self._on_termination)

    def bind(self, rep: Any, path: str, is_root: bool) -> None:
        self.rep, self.path, self.is_root = rep, path, is_root
        self.context = (rep, path)
        self.leads, self.told = _leads(self.container)

    def _listening(self) -> Any:
        """The reporter, when it still reports this container and somebody observes it; else None."""
        rep = self.rep
        if rep is None or not rep.listening or getattr(self.container, "_reporter", None) is not rep:
            return None
        return rep

    # The container's callbacks (called by the original, with its locks held; never raising).
    def _on_start(self, userdata: Any, initial_states: Any, *args: Any) -> None:
        try:
            with self._lock:
                if self.is_root and self.rep is not None:
                    self.rep.root_started()
                self.started, self.ended, self.last, self.failure = True, False, None, None
                self.finished, self.outcomes = [], {}
                initial = _labels(initial_states)
                self.active = list(initial) if self.concurrent else _labels(self.container.get_active_states())
                rep = self._listening()
                if rep is None:
                    self.userdata.forget()
                    return
                rep.send(build.start, self.path, initial, list(self.active), self.userdata.snapshot(userdata))
        except Exception:
            self._failed("start")

    def _on_transition(self, userdata: Any, active_states: Any, *args: Any) -> None:
        try:
            if self.concurrent:
                with self._lock:
                    rep = self._listening()
                    self._children_returned(rep, self._changes(rep, userdata))
                return
            # A StateMachine's (or an Iterator's) callbacks and its children's calls all come from
            # its own thread: no lock taken at every step.
            rep = self._listening()
            changes = self._changes(rep, userdata)
            active = _labels(active_states)
            last, self.last = self.last, None
            to = active[0] if active else None
            if last is None:  # a child whose outcome the edges tell, or that ran before this machine was watched
                frm = self.active[0] if self.active else "None"
                last = (frm, self._outcome_to(frm, to))
            self.active = active
            if rep is not None:
                rep.send(build.transition, self.path, last[0], last[1], to, active, changes)
        except Exception:
            self._failed("transition")

    def _on_termination(self, userdata: Any, terminal_states: Any, outcome: Any, *args: Any) -> None:
        try:
            with self._lock:
                rep = self._listening()
                last = _labels(terminal_states)
                self.active, self.ended = [], True
                if rep is None:
                    return
                changes = self._changes(rep, userdata)
                outcome = None if outcome is None else str(outcome)
                if self.concurrent:
                    rep.send(build.terminate, self.path, last, outcome, [], ABSENT,
                             {label: self.outcomes.get(label) for label in self._children()}, ABSENT, changes)
                    return
                returned = self.last
                if not self.started:
                    state_outcome = ABSENT
                elif returned is not None:
                    state_outcome = returned[1]
                else:  # a child whose outcome the edges tell
                    lead = self.leads.get(last[0]) if last else None
                    state_outcome = lead[1].get(outcome) if lead is not None else None
                rep.send(build.terminate, self.path, last, outcome, [], state_outcome, ABSENT, ABSENT, changes)
        except Exception:
            self._failed("termination")

    # What the children's wrapped calls tell.
    def returned(self, label: str, outcome: Any) -> None:
        """A child returned ``outcome`` (before its container takes the transition)."""
        if self.concurrent:
            with self._lock:
                self.finished.append(label)
        else:  # a machine's children run one at a time, in its thread
            self.last = (label, None if outcome is None else str(outcome))

    def child_failed(self, label: str, exc: BaseException) -> None:
        with self._lock:
            if self.failure is None:
                self.failure = (label, exc)

    def entering(self) -> None:
        """Its own ``execute`` begins (before its start callback, if it gets that far)."""
        self.entered, self.started, self.ended = True, False, False

    def left(self, exc: BaseException | None) -> None:
        """Its own ``execute`` ended: raising ``exc``, or without a terminate (no outcome)."""
        self.entered = False
        if self.ended:
            return
        self.ended = True
        try:
            rep = self._listening()
            if rep is None:
                return
            if exc is None:  # a consistency check that failed, or a shutdown
                rep.terminate(self.path, [], None, [],
                              error="shutdown" if self.started else "consistency check failed")
                return
            label, cause = self.failure if self.failure is not None else (self._current_label(), None)
            self._report_error(rep, label, exc, cause)
            rep.terminate(self.path, [] if label is None else [label], None, [],
                          error="%s: %s" % (type(exc).__name__, _words(exc)))
        except Exception:
            self._failed("error")

    def report_changes(self) -> None:
        """A ``userdata`` event of the keys changed since the last (the debugger's hold shows them)."""
        try:
            with self._lock:
                rep = self._listening()
                changes = self._changes(rep, self.container.userdata)
                if changes is not ABSENT:
                    rep.send(build.userdata, self.path, changes)
        except Exception:
            self._failed("userdata")

    # Inside.
    def _changes(self, rep: Any, userdata: Any) -> Any:
        """The keys changed since they were last reported, encoded: the ``changes`` of the event the
        callback sends (ABSENT when none, or nobody listens)."""
        if rep is None:
            return ABSENT
        changes = self.userdata.changes(userdata)
        return changes if changes else ABSENT

    def _children(self) -> list[str]:
        return [str(label) for label in self.container.get_children()]

    def _children_returned(self, rep: Any, changes: Any) -> None:
        """A Concurrence's transition callback (at a child's start and after it returned): a
        ``transition`` for each child whose outcome it has taken since, in the order they returned,
        the first carrying the userdata's ``changes`` (a ``userdata`` event when no child returned)."""
        taken = {str(k): v for k, v in dict(self.container._child_outcomes).items()}
        new = [label for label in self.finished if label not in self.outcomes and taken.get(label) is not None]
        new += [label for label, o in taken.items() if o is not None and label not in self.outcomes and label not in new]
        for i, label in enumerate(new):
            self.outcomes[label] = str(taken[label])
            later = set(new[i + 1:])
            active = [lbl for lbl, o in taken.items() if o is None or lbl in later]
            self.active = active
            if rep is not None:
                rep.send(build.transition, self.path, label, self.outcomes[label], None, active, changes)
                changes = ABSENT
        if changes is not ABSENT:
            rep.send(build.userdata, self.path, changes)

    def _outcome_to(self, frm: str, to: str | None) -> str:
        """The outcome of ``frm`` that leads to ``to`` (its container's edges), for a child whose
        outcome they tell or that returned before the machine was watched; '?' when they do not say."""
        lead = self.leads.get(frm)
        outcome = lead[0].get(to) if lead is not None else None
        return "?" if outcome is None else outcome

    def _current_label(self) -> str | None:
        label = getattr(self.container, "_current_label", None)
        return None if label is None else str(label)

    def _report_error(self, rep: Any, label: str | None, exc: BaseException, cause: BaseException | None) -> None:
        """An ``error`` event, once per exception, from the innermost container that saw it: the root
        cause is the child's exception (the original wraps it without chaining it as a cause)."""
        if cause is not None:
            first = reporting.mark_reported(cause)
            reporting.mark_reported(exc)
            if not first:
                return
            root = cause
        else:
            if not reporting.mark_reported(exc):
                return
            root = exc
        while root.__cause__ is not None:
            root = root.__cause__
        chain = traceback.format_exception(type(exc), exc, exc.__traceback__)
        if cause is not None and cause is not exc.__context__ and cause is not exc.__cause__:
            chain = traceback.format_exception(type(cause), cause, cause.__traceback__) + chain
        rep.send(build.error, self.path, label, type(root).__name__, _words(root), "".join(chain),
                 type(exc).__name__ if root is not exc else ABSENT)

    def _failed(self, what: str) -> None:
        rep = self.rep
        if rep is not None:
            rep._failed(self, "observing (%s of %s)" % (what, self.path))


class Watched:
    """A state's ``execute`` as its container (or the user, for the root) calls it: the same call, with
    the thread's observed container set (for its log lines), the debugger's gates, and what the call
    told (the outcome returned, the exception raised) handed to the container's watch."""

    def __init__(self, state: Any, inner: Any) -> None:
        self.state = state
        self.inner = inner  # the bound method it stands for
        self.parent: ContainerWatch | None = None  # its container's watch (None: the root)
        self.label = ""
        self.own: ContainerWatch | None = None  # its own watch, when it is a container
        self.root = False  # it is the watched machine's root: its call is a run

    @classmethod
    def of(cls, state: Any) -> "Watched":
        """The state's watch (its ``execute`` is the watch, or the watch's ``leaf``), made the first time."""
        execute = state.execute
        if isinstance(execute, Watched):
            return execute
        if isinstance(getattr(execute, "__self__", None), Watched) and execute.__func__ is Watched.leaf:
            return execute.__self__
        return cls(state, execute)

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        parent, own, label, root = self.parent, self.own, self.label, self.root
        watch = own if own is not None else parent
        rep = watch.rep if watch is not None else None
        prev = reporting.enter_once(watch.context) if rep is not None else reporting.NOT_ENTERED
        try:
            if own is not None:
                if root and rep is not None:
                    rep.root_entered()
                own.entering()
            container = parent.container if parent is not None else None
            dbg = getattr(container, "_debugger", None)
            outcome = dbg.before(container, label, self.state) if dbg is not None else None
            if outcome is None:
                try:
                    outcome = self.inner(*args, **kwargs)
                except BaseException as exc:
                    if own is not None:
                        own.left(exc)
                    if parent is not None:
                        parent.child_failed(label, exc)
                    raise
            dbg = getattr(container, "_debugger", None)
            if dbg is not None and outcome is not None:
                outcome = dbg.after(container, label, self.state, outcome)
            if own is not None:
                own.left(None)
            if parent is not None:
                parent.returned(label, outcome)
            return outcome
        finally:
            if root and rep is not None:
                rep.root_left()
            if prev is None and parent is not None and parent.concurrent and rep is not None:
                # A thread the original's Concurrence started for this child, which ends once the
                # child's outcome is taken: the lines it logs until then (SMACH's wrapping of the
                # child's exception, its word of a missing outcome) are the Concurrence's.
                reporting.enter(rep, parent.path)
            else:
                reporting.leave(prev)


    def leaf(self, *args: Any, **kwargs: Any) -> Any:
        """The call of a leaf whose outcome its container's edges tell (``ContainerWatch.told``),
        inside its container's watched run: the call itself, and only what the edges cannot tell (an
        exception; the debugger's gates, once one is armed, and its ``after`` gate when it was armed
        while the leaf ran). Otherwise it is the whole call (``__call__``)."""
        parent = self.parent
        container = parent.container
        if container._debugger is not None or not parent.entered:
            return self(*args, **kwargs)
        try:
            outcome = self.inner(*args, **kwargs)
        except BaseException as exc:
            parent.child_failed(self.label, exc)
            raise
        dbg = container._debugger
        if dbg is not None:  # armed while it ran: its outcome may be held or forced
            if outcome is not None:
                outcome = dbg.after(container, self.label, self.state, outcome)
            parent.returned(self.label, outcome)
        return outcome


class PreemptWatched:
    """A state's ``request_preempt`` (``phase`` 'requested', a container's) or ``service_preempt``
    ('serviced', any state's): the same call, and a ``preempt`` event of the state's path."""

    def __init__(self, state: Any, inner: Any, phase: str) -> None:
        self.state, self.inner, self.phase = state, inner, phase

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        if self.phase == "serviced":
            result = self.inner(*args, **kwargs)
            self._report()
            return result
        self._report()
        return self.inner(*args, **kwargs)

    def _report(self) -> None:
        state = self.state
        rep = getattr(state, "_reporter", None)
        if rep is not None and rep.listening:
            rep.preempt(getattr(state, "_path", rep.root_path), self.phase)
