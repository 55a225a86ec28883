"""Sequence: a StateMachine whose states are chained by one connector outcome."""

from typing import Any

from . import log
from .state import State
from .state_machine import StateMachine


class Sequence(StateMachine):
    def __init__(self, outcomes: Any, connector_outcome: str, input_keys: list[str] = [],
                 output_keys: list[str] = []) -> None:
        StateMachine.__init__(self, outcomes, input_keys, output_keys)
        self._last_added_seq_label: Any = None
        self._connector_outcome = connector_outcome

    @staticmethod
    def add(label: str, state: State, transitions: dict | None = None, remapping: dict | None = None) -> State:
        """Add a state; the previous one's connector outcome leads here unless it was given explicitly.

        As SMACH: the previous state is linked first, then this one added."""
        self = Sequence._currently_opened_container()
        if transitions is None:
            transitions = {}
        previous = self._last_added_seq_label
        if previous is not None:
            previous_transitions = self._transitions[previous]
            if previous_transitions.get(self._connector_outcome) is None:
                previous_transitions[self._connector_outcome] = label
            try:
                self.check_state_spec(previous, self._states[previous], previous_transitions)
            except Exception:
                log.logerr("Attempting to construct smach state sequence failed.")
        self._last_added_seq_label = label
        return StateMachine.add(label, state, transitions, remapping)
