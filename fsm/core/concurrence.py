"""Concurrence: every child runs at once; the outcome comes from an outcome map, a callback or a default.

Each child is offered to a long-lived pool thread; the caller, meanwhile, runs every child no
worker has claimed yet, so quick children never wait for a thread to wake and a blocking child
still gets a thread of its own. A preempt, a child's error, or a truthy ``child_termination_cb``
preempts the unfinished children at once from the thread that caused it.
"""

import copy
import threading
import traceback
from typing import Any, Callable

from . import log, reporting
from .container import Container
from .exceptions import InvalidStateError, InvalidTransitionError, InvalidUserCodeError
from .state import State
from .user_data import Remapper
from .worker_pool import pool


class Concurrence(Container):
    """Runs its children at once; its outcome comes from outcome_map, outcome_cb or default_outcome.

    A preempt that every child serviced ends it with 'preempted' if that is one of its outcomes, and
    otherwise with what that policy gives for the children's outcomes. Fixed against SMACH, which
    returns 'preempted' even when it is not registered, so that its parent StateMachine raises.
    """

    _kind_name = "Concurrence"

    def __init__(self, outcomes: Any, default_outcome: str, input_keys: list[str] = [], output_keys: list[str] = [],
                 outcome_map: dict = {}, outcome_cb: Callable | None = None,
                 child_termination_cb: Callable | None = None) -> None:
        Container.__init__(self, outcomes, input_keys, output_keys)
        self._states: dict[str, State] = {}
        self._remappings: dict[str, dict] = {}
        if not (default_outcome or outcome_map or outcome_cb):
            raise InvalidStateError("Concurrence requires an outcome policy")
        errors = ""
        if default_outcome != str(default_outcome):
            errors += "\n\tDefault outcome '%s' does not appear to be a string." % str(default_outcome)
        if default_outcome not in self._outcomes:
            errors += "\n\tDefault outcome '%s' is unregistered." % str(default_outcome)
        for o in outcome_map:
            if o not in self._outcomes:
                errors += "\n\tUnregistered outcome '%s' in and_outcome_map." % str(o)
        if outcome_cb and not callable(outcome_cb):
            errors += "\n\tOutcome callback '%s' is not callable." % str(outcome_cb)
        if child_termination_cb and not callable(child_termination_cb):
            errors += "\n\tChild termination callback '%s' is not callable." % str(child_termination_cb)
        if errors:
            raise InvalidStateError("Errors specifying outcome policy of concurrence: %s" % errors)
        self._default_outcome = default_outcome
        self._outcome_map = outcome_map
        self._outcome_cb = outcome_cb
        self._child_termination_cb = child_termination_cb
        self._child_outcomes: dict[str, Any] = {}
        self._failed: dict[str, BaseException] = {}
        self._failed_label: str | None = None  # the child whose failure ended the last run
        self._pending = 0
        self._stopping = False  # the run stopped waiting for its children: all done, a preempt or an error
        self._done_cond = threading.Condition()
        self._is_running = False

    @staticmethod
    def add(label: str, state: State, remapping: dict = {}) -> State:
        self = Concurrence._currently_opened_container()
        self._states[label] = state
        self._remappings[label] = remapping
        return state

    def _on_failure(self) -> Any:
        return self._failed_label

    def _execute(self, parent_ud: Any) -> Any:
        if not self._states:
            raise InvalidStateError("No states was added to concurrence")
        states = self._states
        with self._done_cond:
            self._child_outcomes = dict.fromkeys(states)
            self._failed = {}
            self._failed_label = None
            self._pending = len(states)
            self._stopping = False
        self._copy_input_keys(parent_ud, self.userdata)
        log.info_quiet("Concurrence starting with userdata: \n\t%s" % str(list(self.userdata.keys())))
        self._is_running = True
        self._report_started()
        self.call_start_cbs()
        if self._preempt_requested:  # requested while idle: the children start preempted
            for state in states.values():
                state.request_preempt()
        items = list(states.items())
        jobs = [pool.submit(self._run_child, label, state) for label, state in items[1:]]
        self._run_child(*items[0])
        for job, (label, state) in zip(jobs, items[1:]):
            if pool.take(job):
                self._run_child(label, state)
        with self._done_cond:
            while self._pending and not log.is_shutdown():
                self._done_cond.wait(0.1)
            self._is_running = False
        if self._failed:
            return self._raise_failure()

        if self._preempt_requested:
            serviced = True
            for label, state in states.items():
                if state.preempt_requested():
                    serviced = False
                    log.logwarn("State '%s' in concurrence did not service preempt." % label)
                    state.recall_preempt()
            if serviced:
                log.loginfo("Concurrence serviced preempt.")
                self.service_preempt()
                if "preempted" in self._outcomes:
                    return self._terminate("preempted", parent_ud)

        log.info_quiet("Concurrent Outcomes: " + str(self._child_outcomes))
        outcome = self._default_outcome
        best = 0
        log.debug_quiet("SMACH Concurrence determining contained state outcomes.")
        for container_outcome, needed in self._outcome_map.items():
            if all(self._child_outcomes[label] == o for label, o in needed.items()):  # an unknown label: KeyError, as SMACH
                if len(needed) > best:
                    log.debug_quiet("Terminating concurrent split with mapped outcome.")
                    outcome, best = container_outcome, len(needed)
                else:
                    log.debug_quiet("Skipping mapped outcome '%s' with fewer constraints." % container_outcome)
        if self._outcome_cb:
            try:
                cb_outcome = self._outcome_cb(copy.copy(self._child_outcomes))
            except Exception:
                raise InvalidUserCodeError(("Could not execute outcome callback '%s': " % self._outcome_cb)
                                           + traceback.format_exc())
            if cb_outcome:
                if cb_outcome == str(cb_outcome):
                    outcome = cb_outcome
                else:
                    # Fixed against SMACH: the default outcome is used, as the message says.
                    log.logerr("Outcome callback returned a non-string '%s', using default outcome '%s'"
                               % (str(cb_outcome), self._default_outcome))
                    outcome = self._default_outcome
            else:
                log.logwarn("Outcome callback returned None, using outcome '%s'" % outcome)
        return self._terminate(outcome, parent_ud)

    def _terminate(self, outcome: str, parent_ud: Any) -> str:
        rep = self._reporter
        if rep is not None:
            rep.terminate(self._path, list(self._states), outcome, [],
                          outcomes={k: None if v is None else str(v) for k, v in self._child_outcomes.items()})
        self.call_termination_cbs(list(self._states), outcome)
        self._copy_output_keys(self.userdata, parent_ud)
        return outcome

    def _raise_failure(self) -> Any:
        """Fixed against SMACH: a child that raised or returned None, or a raising
        child_termination_cb, ends the Concurrence with an error instead of hanging it."""
        failed = self._failed
        self._failed = {}
        self._child_outcomes = {}
        self._failed_label, first = next(iter(failed.items()))
        if isinstance(first, (InvalidStateError, InvalidUserCodeError)) and getattr(first, "_fsm_own", False):
            raise first
        raise reporting.carry_reported(
            InvalidStateError("A concurrent state raised an exception during execution."), first) from first

    def _run_child(self, label: str, state: State) -> None:
        rep = self._reporter
        prev = reporting.enter(rep, self._path) if rep is not None else reporting.NOT_ENTERED
        try:
            if self._transition_cbs:
                self.call_transition_cbs()
            dbg = self._debugger
            outcome = dbg.before(self, label, state) if dbg is not None else None
            if outcome is None:
                try:
                    outcome = state.execute(Remapper(self.userdata, state.get_registered_input_keys(),
                                                     state.get_registered_output_keys(), self._remappings[label]))
                except BaseException as exc:
                    # As SMACH's _state_runner: the child's error logs itself, traceback and all.
                    InvalidStateError(("Could not execute child state '%s': " % label) + traceback.format_exc())
                    self._fail(label, exc)
                    return
            dbg = self._debugger
            if outcome is not None and dbg is not None:
                outcome = dbg.after(self, label, state, outcome)
            if outcome is None:
                error = InvalidStateError("Concurrent state '%s' returned no outcome on termination." % label)
                error._fsm_own = True
                self._fail(label, error)
                return
            log.info_quiet("Concurrent state '%s' returned outcome '%s' on termination." % (label, outcome))
            with self._done_cond:
                self._child_outcomes[label] = outcome
                if rep is not None:  # the keys written since the last child's: on its transition
                    rep.transition(self._path, str(label), str(outcome), None, self.get_active_states(),
                                   self.userdata.take_written())
                if self._transition_cbs:
                    self.call_transition_cbs()
                if self._child_termination_cb:
                    try:
                        preempt_others = self._child_termination_cb(self._child_outcomes)
                    except Exception:
                        error = InvalidUserCodeError("Could not execute child termination callback: " + traceback.format_exc())
                        error._fsm_own = True
                        self._fail(label, error)
                        return
                    if preempt_others:
                        self._stop_waiting()
                        self._preempt_unfinished()
        finally:
            with self._done_cond:
                self._pending -= 1
                if not self._pending:
                    self._stop_waiting()
                    self._done_cond.notify_all()
            reporting.leave(prev)

    def _report_changes(self) -> None:
        """Under the children's lock: a child's debugger hold reports from that child's thread."""
        with self._done_cond:
            Container._report_changes(self)

    def _fail(self, label: str, error: BaseException) -> None:
        with self._done_cond:
            self._failed.setdefault(label, error)
            self._stop_waiting()
            self._preempt_unfinished()

    def _stop_waiting(self) -> None:
        """With ``_done_cond`` held: SMACH's debug line of the moment its run stops waiting (the first
        of all children done, a preempt, a child's error or a truthy child_termination_cb), once a run."""
        if not self._stopping:
            self._stopping = True
            log.logdebug("SMACH Concurrence preempting running states.")

    def _preempt_unfinished(self) -> None:
        for label, outcome in self._child_outcomes.items():
            if outcome is None and label not in self._failed:
                self._states[label].request_preempt()

    def request_preempt(self) -> None:
        """Thread-safe: flags this Concurrence and preempts every unfinished child."""
        with self._done_cond:
            self._preempt_requested = True
            self._report_preempt_requested()
            if self._is_running:
                rep = self._reporter  # the line is this Concurrence's, whichever thread asked
                prev = reporting.enter(rep, self._path) if rep is not None else reporting.NOT_ENTERED
                try:
                    self._stop_waiting()
                finally:
                    reporting.leave(prev)
                self._preempt_unfinished()

    def get_children(self) -> dict:
        return self._states

    def __getitem__(self, key: str) -> State:
        """As SMACH's: an unknown label is a KeyError naming it, with no log line."""
        return self._states[key]

    def set_initial_state(self, initial_states: list[str], userdata: Any = None) -> None:
        """Every child is initial; fixed against SMACH (a TypeError on Python 3): merges the userdata."""
        unknown = [s for s in initial_states if s not in self._states]
        if unknown:
            raise InvalidStateError("Attempting to set initial states %s of a Concurrence, which only has states: %s"
                                    % (unknown, list(self._states)))
        if userdata is not None:
            self.userdata.update(userdata)

    def get_initial_states(self) -> list[str]:
        return list(self._states.keys())

    def get_active_states(self) -> list[str]:
        return [str(label) for label, outcome in self._child_outcomes.items() if outcome is None]

    def get_internal_edges(self) -> list:
        return [(child_outcome, label, container_outcome)
                for container_outcome, needed in self._outcome_map.items()
                for label, child_outcome in needed.items()]

    def _introspection_info(self) -> dict:
        return {"default_outcome": self._default_outcome,
                "outcome_map": {str(co): {str(k): str(v) for k, v in m.items()} for co, m in self._outcome_map.items()}}

    def check_consistency(self) -> None:
        for container_outcome, needed in self._outcome_map.items():
            for label, outcome in needed.items():
                if outcome not in self._states[label].get_registered_outcomes():
                    raise InvalidTransitionError(
                        "Outcome map in SMACH Concurrence references a state outcome that does not exist. Requested state outcome: '%s', but state '%s' only has outcomes %s"
                        % (outcome, label, str(self._states[label].get_registered_outcomes())))

    def is_running(self) -> bool:
        return self._is_running
