"""Iterator: runs one contained state once per item, until the items run out or an outcome breaks."""

import traceback
from typing import Any, Callable, Iterable

from . import log, reporting
from .container import Container
from .exceptions import InvalidUserCodeError
from .state import State


class Iterator(Container):
    _kind_name = "Iterator"

    def __init__(self, outcomes: list[str], input_keys: list[str], output_keys: list[str],
                 it: Iterable | Callable[[], Iterable] = [], it_label: str = "it_data",
                 exhausted_outcome: str = "exhausted") -> None:
        if exhausted_outcome not in outcomes:
            outcomes.append(exhausted_outcome)
        Container.__init__(self, outcomes, input_keys, output_keys)
        self._items = it
        self._items_label = it_label
        self._is_running = False
        self._state_label: Any = ""
        self._state: State | None = None
        self._loop_outcomes: list[str] = []
        self._break_outcomes: list[str] = []
        self._final_outcome_map: dict = {}
        self._exhausted_outcome = exhausted_outcome

    @staticmethod
    def set_iteritems(it: Iterable | Callable[[], Iterable], it_label: str = "it_data") -> None:
        self = Iterator._currently_opened_container()
        self._items = it
        self._items_label = it_label

    @staticmethod
    def set_contained_state(label: str, state: State, loop_outcomes: list[str] = [], break_outcomes: list[str] = [],
                            final_outcome_map: dict = {}) -> State:
        """Outcomes not listed as loop (or break) outcomes do the opposite.

        ``final_outcome_map`` maps the ending outcome, the exhausted outcome included, as in SMACH.
        """
        self = Iterator._currently_opened_container()
        if loop_outcomes and break_outcomes:
            log.logwarn("Both loop_outcomes and break_outcomes were specified when constructing SMACH iterator container.")
        outcomes = state.get_registered_outcomes()
        if break_outcomes:  # as SMACH: the break outcomes decide, loop_outcomes given with them are ignored
            break_outcomes = list(break_outcomes)
            loop_outcomes = [o for o in outcomes if o not in break_outcomes]
        else:
            loop_outcomes = list(loop_outcomes)
            break_outcomes = [o for o in outcomes if o not in loop_outcomes]
        self._loop_outcomes = loop_outcomes
        self._break_outcomes = break_outcomes
        self._final_outcome_map = final_outcome_map
        self._state = state
        self._state_label = label
        return state

    def _on_failure(self) -> Any:
        self._is_running = False
        return self._state_label

    def _execute(self, parent_ud: Any) -> Any:
        self._is_running = True
        self._copy_input_keys(parent_ud, self.userdata)
        self._report_started()
        self.call_start_cbs()
        items = self._items
        it = iter(items() if callable(items) else items)
        outcome = self._exhausted_outcome
        state_outcome = None
        rep = self._reporter
        while not log.is_shutdown():
            try:
                item = next(it)
            except Exception:  # any failure of the iterable counts as exhaustion, as in SMACH
                break
            log.loginfo("Iterating %s of %s" % (str(item), str(items)))
            self.userdata[self._items_label] = item
            dbg = self._debugger
            state_outcome = dbg.before(self, self._state_label, self._state) if dbg is not None else None
            if state_outcome is None:
                state_outcome = self._run_state()
            dbg = self._debugger
            if dbg is not None:
                state_outcome = dbg.after(self, self._state_label, self._state, state_outcome)
            if self._preempt_requested:
                self.service_preempt()
                outcome = state_outcome
                break
            if state_outcome in self._break_outcomes or (self._loop_outcomes and state_outcome not in self._loop_outcomes):
                outcome = state_outcome
                break
            if rep is not None:  # the keys the step wrote ride on its transition (or its terminate, below)
                rep.transition(self._path, str(self._state_label), str(state_outcome), str(self._state_label),
                               [str(self._state_label)], self.userdata.take_written())
            self.call_transition_cbs()
        # As in SMACH, every ending is mapped: a break by the state's outcome, exhaustion by the exhausted outcome.
        outcome = self._final_outcome_map.get(outcome, outcome)
        self._copy_output_keys(self.userdata, parent_ud)
        self._is_running = False
        if rep is not None:
            rep.terminate(self._path, [str(self._state_label)], None if outcome is None else str(outcome), [],
                          state_outcome=None if state_outcome is None else str(state_outcome),
                          changes=self.userdata.take_written())
        self.call_termination_cbs(self._state_label, outcome)
        return outcome

    def _run_state(self) -> Any:
        try:
            return self._state.execute(self.userdata)
        except InvalidUserCodeError:
            log.logerr("Could not execute Iterator state '%s'" % self._state_label)
            raise
        except Exception as exc:
            raise reporting.carry_reported(InvalidUserCodeError(
                "Could not execute iterator state '%s' of type '%s': " % (self._state_label, self._state)
                + traceback.format_exc()), exc) from exc

    def request_preempt(self) -> None:
        State.request_preempt(self)
        self._report_preempt_requested()
        if self._is_running and self._state is not None:
            self._state.request_preempt()

    def get_children(self) -> dict:
        return {self._state_label: self._state} if self._state is not None else {}

    def __getitem__(self, key: str) -> State:
        """SMACH's own wording for its one contained state (singular, unlike the other containers)."""
        if self._state is None or key != self._state_label:
            log.logerr("Attempting to get state '%s' from Iterator container. The only available state is '%s'."
                       % (key, self._state_label))
            raise KeyError()
        return self._state

    def set_initial_state(self, initial_states: list[str], userdata: Any = None) -> None:
        """Fixed against SMACH (a TypeError for several states): takes the first, merges the userdata."""
        if len(initial_states) > 1:
            log.logwarn("Attempting to set initial state to include more than one state, but the Iterator container can only have one initial state. Taking the first one.")
        if initial_states and initial_states[0] != self._state_label:
            log.logwarn("Attempting to set state '%s' as initial state in Iterator container. The only available state is '%s'."
                        % (initial_states[0], self._state_label))
            raise KeyError()
        if userdata is not None:
            self.userdata.update(userdata)

    def get_initial_states(self) -> list[str]:
        return [str(self._state_label)]

    def get_active_states(self) -> list[str]:
        return [str(self._state_label)] if self._is_running else []

    def get_internal_edges(self) -> list:
        edges: list = [[o, self._state_label, self._state_label] for o in self._loop_outcomes]
        for o in self._break_outcomes:  # as SMACH: a break that keeps its own name falls through (None)
            mapped = self._final_outcome_map.get(o, o)
            edges.append((o, self._state_label, None if mapped == o else mapped))
        return edges

    def _introspection_info(self) -> dict:
        return {"exhausted_outcome": self._exhausted_outcome}

    def check_consistency(self) -> None:
        pass

    def is_running(self) -> bool:
        return self._is_running
