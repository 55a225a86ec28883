"""The user callbacks of smach_ros states (request_cb, goal_cb, result_cb, ...).

Each sees userdata through a Remapper limited to its keys: those of its ``cb_interface``,
which are also registered on the state, or else the state's constructor keys. A callback
that raises, or returns an outcome the state does not have, makes the state abort.
"""

import traceback
from typing import Any, Callable, Iterable

from ..core import log
from ..core.exceptions import InvalidStateError
from ..core.state import State
from ..core.user_data import Remapper
from ..core.util import has_smach_interface

# What ``UserCallback.run`` returns when the state must abort (already logged).
FAILED = object()


class UserCallback:
    """One optional callback ``cb(ud, *leading, *args, **kwargs)`` of a smach_ros state."""

    def __init__(self, state: State, owner: str, role: str, cb: Callable[..., Any] | None, args: Iterable[Any],
                 kwargs: dict[str, Any], input_keys: Iterable[str], output_keys: Iterable[str],
                 returns_outcome: bool = False) -> None:
        """``owner`` ("action move") and ``role`` ("goal", "result", ...) name the callback in
        messages. With ``returns_outcome`` its interface outcomes are registered on the state
        and its return value is checked against the state's outcomes."""
        if cb is not None and not callable(cb):
            raise InvalidStateError("%s callback object given to %s that IS NOT a function object"
                                    % (role.capitalize(), type(state).__name__))
        self._state = state
        self._owner = owner
        self._role = role
        self._cb = cb
        self._args = list(args)
        self._kwargs = dict(kwargs)
        self._returns_outcome = returns_outcome
        if has_smach_interface(cb):
            self._input_keys = tuple(cb.get_registered_input_keys())
            self._output_keys = tuple(cb.get_registered_output_keys())
            state.register_input_keys(self._input_keys)
            state.register_output_keys(self._output_keys)
            if returns_outcome:
                state.register_outcomes(cb.get_registered_outcomes())
        else:
            self._input_keys = tuple(input_keys)
            self._output_keys = tuple(output_keys)

    def update(self, ud: Any, msg: Any) -> Any:
        """``msg`` as the callback rewrote it: its non-None return replaces it. FAILED if it raised."""
        value = self.run(ud, msg)
        return msg if value is None else value

    def run(self, ud: Any, *leading: Any) -> Any:
        """The callback's return value (None without a callback), or FAILED (logged) if it raised
        or returned a foreign outcome."""
        if self._cb is None:
            return None
        try:
            value = self._cb(Remapper(ud, self._input_keys, self._output_keys), *leading,
                             *self._args, **self._kwargs)
        except Exception:
            log.logerr("Could not execute %s callback: %s" % (self._role, traceback.format_exc()))
            return FAILED
        outcomes = self._state.get_registered_outcomes()
        if self._returns_outcome and value is not None and value not in outcomes:
            log.logerr("Result callback for %s, %s was not registered with the %s_cb_outcomes argument. The %s "
                       "callback returned '%s' but the only registered outcomes are: %s"
                       % (self._owner, self._cb, self._role, self._role, value, outcomes))
            return FAILED
        return value
