"""StateMachine: one active child at a time, outcomes mapped to the next child or to a container outcome.

One piece because it is SMACH's class, method for method: construction and
checks, the transition step, execution, preemption and introspection all read and write the
same current-state fields under one lock."""

import threading
import traceback
from typing import Any

from . import log, reporting
from .container import Container
from .exceptions import InvalidStateError, InvalidTransitionError, InvalidUserCodeError
from .state import State
from .user_data import Remapper


class StateMachine(Container):
    _kind_name = "StateMachine"

    def __init__(self, outcomes: Any, input_keys: list[str] = [], output_keys: list[str] = []) -> None:
        Container.__init__(self, outcomes, input_keys, output_keys)
        self._state_transitioning_lock = threading.Lock()
        self._is_running = False
        self._initial_state_label: Any = None
        self._current_label: Any = None
        self._current_state: State | None = None
        self._current_transitions: dict | None = None
        self._preempted_label: Any = None
        self._preempted_state: State | None = None
        self._failed_label: Any = None  # the state whose failure ended the last run
        self._states: dict[str, State] = {}
        self._transitions: dict[str, dict] = {}
        self._remappings: dict[str, dict] = {}
        self._constants: dict[str, dict] = {}
        self._last_added_label: Any = None
        self._connector_outcomes: list[str] = []
        self._remappers: dict[str, Remapper] = {}

    # Construction.
    @staticmethod
    def add(label: str, state: State, transitions: dict | None = None, remapping: dict | None = None,
            constants: dict | None = None) -> State:
        """Add a state to the open machine; the caller's ``transitions`` dict is completed in place."""
        self = StateMachine._currently_opened_container()
        log.logdebug("Adding state (%s, %s, %s)" % (label, str(state), str(transitions)))
        if self._initial_state_label is None:
            self._initial_state_label = label
        if transitions is None:
            transitions = {}
        if remapping is None:
            remapping = {}
        if constants is None:
            constants = {}
        self.check_state_spec(label, state, transitions)
        if label in self._states:
            raise InvalidStateError('Attempting to add state with label "' + str(label)
                                    + '" to state machine, but this label is already being used.')
        log.logdebug("Adding state '" + str(label) + "' to the state machine.")
        registered_outcomes = state.get_registered_outcomes()
        missing_transitions = {o: None for o in registered_outcomes if o not in transitions}
        transitions.update(missing_transitions)
        log.logdebug("State '%s' is missing transitions: %s" % (label, str(missing_transitions)))
        self._states[label] = state
        self._transitions[label] = transitions
        self._remappings[label] = remapping
        self._constants[label] = constants
        log.logdebug("TRANSITIONS FOR %s: %s" % (label, str(self._transitions[label])))
        if self._connector_outcomes and self._last_added_label is not None:
            for connector_outcome in self._connector_outcomes:
                self._transitions[self._last_added_label][connector_outcome] = label
            self._connector_outcomes = []
            self._last_added_label = None
        return state

    @staticmethod
    def add_auto(label: str, state: State, connector_outcomes: list[str], transitions: dict | None = None,
                 remapping: dict | None = None, constants: dict | None = None) -> State:
        """Add a state whose ``connector_outcomes`` lead to the next state added."""
        self = StateMachine._currently_opened_container()
        StateMachine.add(label, state, transitions, remapping, constants)
        self._last_added_label = label
        registered_outcomes = state.get_registered_outcomes()
        if not all(co in registered_outcomes for co in connector_outcomes):
            raise InvalidStateError("Attempting to auto-connect states with outcomes %s, but state '%s' only has registerd outcomes: %s"
                                    % (str(connector_outcomes), str(label), str(registered_outcomes)))
        self._connector_outcomes = connector_outcomes
        return state

    # Execution.
    def _set_current_state(self, label: Any) -> None:
        if label is None:
            self._current_label = None
            self._current_state = None
            self._current_transitions = None
        else:
            self._current_label = label
            self._current_state = self._states[label]
            self._current_transitions = self._transitions[label]

    def _remapper(self, label: str, state: State) -> Remapper:
        remapper = self._remappers.get(label)
        if remapper is None:
            remapper = self._remappers[label] = Remapper(
                self.userdata, state.get_registered_input_keys(), state.get_registered_output_keys(),
                self._remappings[label])
        return remapper

    def _update_once(self) -> Any:
        if self._preempt_requested or self._preempted_state is not None:
            log.loginfo("Preempt requested on state machine before executing the next state.")
            if self._preempted_state is not None:
                if self._preempted_state.preempt_requested():
                    log.loginfo("Last state '%s' did not service preempt. Preempting next state '%s' before executing..."
                                % (self._preempted_label, self._current_label))
                    self._preempt_current_state()
                else:
                    self._preempt_requested = False
                    self._preempted_state = None
            else:
                self._preempt_current_state()

        last_state_label = self._current_label
        state = self._current_state
        constants = self._constants[last_state_label]
        if constants:
            for k, v in constants.items():
                self.userdata[k] = v
        remapper = self._remapper(last_state_label, state)
        lock = self._state_transitioning_lock
        lock.release()
        try:  # the debugger's gates hold with the lock released: a preempt still comes in
            dbg = self._debugger
            outcome = dbg.before(self, last_state_label, state) if dbg is not None else None
            if outcome is None:
                try:  # inline, not a call of its own: this is every step
                    outcome = state.execute(remapper)
                except InvalidUserCodeError as ex:
                    log.logerr("State '%s' failed to execute." % last_state_label)
                    raise ex
                except Exception as exc:
                    raise reporting.carry_reported(InvalidUserCodeError(
                        "Could not execute state '%s' of type '%s': " % (last_state_label, state)
                        + traceback.format_exc()), exc) from exc
            dbg = self._debugger
            if dbg is not None:
                outcome = dbg.after(self, last_state_label, state, outcome)
        finally:
            lock.acquire()

        if outcome not in state._outcomes and outcome not in state.get_registered_outcomes():
            raise InvalidTransitionError("Attempted to return outcome '%s' from state '%s' of type '%s' which only has registered outcomes: %s"
                                         % (str(outcome), str(last_state_label), str(state), str(state.get_registered_outcomes())))
        transitions = self._current_transitions
        if outcome not in transitions:
            raise InvalidTransitionError("Outcome '%s' of state '%s' is not bound to any transition target. Bound transitions include: %s"
                                         % (str(outcome), str(last_state_label), str(transitions)))
        target = transitions[outcome]
        rep = self._reporter

        if target in self._states:
            self._set_current_state(target)
            log.info_quiet("State machine transitioning '%s':'%s'-->'%s'" % (last_state_label, outcome, target))
            if rep is not None:  # the keys the step wrote ride on its transition: one event per step
                ud = self.userdata
                rep.transition(self._path, str(last_state_label), str(outcome), str(target), [str(target)],
                               ud.take_written() if ud._dirty else None)
            if self._transition_cbs:
                self.call_transition_cbs()
            return None

        if self._preempt_requested and self._preempted_state is not None:
            if not self._current_state.preempt_requested():
                self.service_preempt()
        outcomes = self.get_registered_outcomes()
        if target not in outcomes:
            target = outcome
        if target in outcomes:
            self._set_current_state(None)
            log.info_quiet("State machine terminating '%s':'%s':'%s'" % (last_state_label, outcome, target))
            if rep is not None:
                rep.terminate(self._path, [str(last_state_label)], str(target), [], state_outcome=str(outcome),
                              changes=self.userdata.take_written())
            self.call_termination_cbs([last_state_label], target)
            return target
        if rep is not None:
            self._report_changes()  # the step's writes: no transition or terminate of this machine carries them
        raise InvalidTransitionError("Outcome '%s' of state '%s' with transition target '%s' is neither a registered state nor a registered container outcome."
                                     % (str(outcome), str(last_state_label), str(target)))

    def _on_failure(self) -> Any:
        return self._failed_label

    def _execute(self, parent_ud: Any) -> Any:
        """Run to a container outcome; None after a failed consistency check or a shutdown."""
        with self._state_transitioning_lock:
            self._failed_label = None
            try:
                self.check_consistency()
            except (InvalidStateError, InvalidTransitionError):
                log.logerr("Container consistency check failed.")
                self._report_ended("consistency check failed")
                return None
            self._is_running = True
            self._preempted_label = None
            self._preempted_state = None
            self._remappers = {}
            self._set_current_state(self._initial_state_label)
            self._copy_input_keys(parent_ud, self.userdata)
            log.info_quiet("State machine starting in initial state '%s' with userdata: \n\t%s"
                           % (self._current_label, list(self.userdata.keys())))
            self._report_started()
            self.call_start_cbs()
            container_outcome = None
            try:
                while container_outcome is None and self._is_running and not log.is_shutdown():
                    container_outcome = self._update_once()
            except BaseException:
                self._failed_label = self._current_label
                raise
            finally:
                # Fixed against SMACH: after an error no state is reported active.
                self._is_running = False
                self._set_current_state(None)
            if container_outcome is None:
                self._report_ended("shutdown")
            self._copy_output_keys(self.userdata, parent_ud)
            return container_outcome

    def _preempt_current_state(self) -> None:
        if self._preempted_state is not self._current_state:
            if self._preempted_state is not None:
                self._preempted_state.recall_preempt()
            self._preempted_state = self._current_state
            self._preempted_label = self._current_label
            try:
                self._preempted_state.request_preempt()
            except Exception:
                log.logerr("Failed to preempt contained state '%s': %s" % (self._preempted_label, traceback.format_exc()))

    def request_preempt(self) -> None:
        """Thread-safe: flags this machine and forwards the request to the running child."""
        with self._state_transitioning_lock:
            self._preempt_requested = True
            self._report_preempt_requested()
            if self._current_state is not None:
                self._preempt_current_state()

    # Introspection.
    def get_children(self) -> dict:
        return self._states

    def set_initial_state(self, initial_states: list[str], userdata: Any = None) -> None:
        log.logdebug("Setting initial states to " + str(initial_states))
        if len(initial_states) > 1:
            log.logwarn("Attempting to set initial state to include more than one state, but the StateMachine container can only have one initial state. Taking the first one.")
        if len(initial_states) > 0:
            self._initial_state_label = initial_states[0]
            reporting.structure_changed()
        if userdata is not None:
            self.userdata.update(userdata)

    def get_initial_states(self) -> list[str]:
        return [str(self._initial_state_label)]

    def get_active_states(self) -> list[str]:
        return [str(self._current_label)]

    def get_internal_edges(self) -> list:
        return [(outcome, label, target)
                for label, transitions in self._transitions.items()
                for outcome, target in transitions.items()]

    def check_state_spec(self, label: str, state: State, transitions: dict) -> None:
        registered_outcomes = state.get_registered_outcomes()
        for outcome in transitions:
            if outcome not in registered_outcomes:
                raise InvalidTransitionError("Specified outcome '" + str(outcome) + "' on state '" + str(label)
                                             + "', which only has available registered outcomes: " + str(registered_outcomes))

    def check_consistency(self) -> None:
        """Gather every construction error into one InvalidTransitionError (SMACH's format)."""
        registered_sm_outcomes = self.get_registered_outcomes()
        available_states = set(list(self._states.keys()) + list(registered_sm_outcomes))
        errors = ""
        if self._initial_state_label is None:
            errors += "\n\tNo initial state set."
        elif self._initial_state_label not in self._states:
            errors += "\n\tInitial state label: '" + str(self._initial_state_label) + "' is not in the state machine."
        for label in self._states:
            transitions = self._transitions[label]
            targets = set(transitions.values()) - {None, ""}
            missing_targets = targets - available_states
            terminal_outcomes = {o for o, t in transitions.items() if t is None or t == ""}
            missing_outcomes = terminal_outcomes - set(registered_sm_outcomes)
            if missing_targets:
                errors += "\n\tState '" + str(label) + "' references unknown states: " + str(list(missing_targets))
            if missing_outcomes:
                errors += "\n\tState '" + str(label) + "' references unregistered outcomes: " + str(list(missing_outcomes))
        if errors:
            raise InvalidTransitionError("State machine failed consistency check: " + errors
                                         + "\n\n\tAvailable states: " + str(list(available_states)))

    def is_running(self) -> bool:
        return self._is_running

    def __getstate__(self) -> dict:
        return {k: v for k, v in self.__dict__.items() if k not in ("_state_transitioning_lock", "_reporter", "_remappers")}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._state_transitioning_lock = threading.Lock()
        self._remappers = {}
