"""The leaf: a unit of user code that returns one of its registered outcomes."""

from typing import Any, Callable, Iterable

from .util import has_smach_interface


class State:
    """Base class of every state and container.

    ``_reporter`` (a ``fsm.core.reporting.Reporter``) and ``_path`` are set by ``fsm.observation`` when
    a tool observes the machine this state belongs to, and a container's ``_debugger`` by
    ``fsm.debugging`` when one debugs it; they stay None otherwise, which costs nothing.
    """

    _reporter = None
    _path: str | None = None
    _debugger = None

    def __init__(self, outcomes: Iterable[str] = [], input_keys: list[str] = [],
                 output_keys: list[str] = [], io_keys: list[str] = []) -> None:
        self._outcomes = set(outcomes)
        self._input_keys = set(input_keys + io_keys)
        self._output_keys = set(output_keys + io_keys)
        self._preempt_requested = False

    def execute(self, ud: Any) -> str:
        raise NotImplementedError()

    def register_outcomes(self, new_outcomes: Iterable[str]) -> None:
        self._outcomes = self._outcomes.union(new_outcomes)

    def get_registered_outcomes(self) -> tuple:
        return tuple(self._outcomes)

    def register_io_keys(self, keys: Iterable[str]) -> None:
        self._input_keys = self._input_keys.union(keys)
        self._output_keys = self._output_keys.union(keys)

    def register_input_keys(self, keys: Iterable[str]) -> None:
        self._input_keys = self._input_keys.union(keys)

    def register_output_keys(self, keys: Iterable[str]) -> None:
        self._output_keys = self._output_keys.union(keys)

    def get_registered_input_keys(self) -> tuple:
        return tuple(self._input_keys)

    def get_registered_output_keys(self) -> tuple:
        return tuple(self._output_keys)

    def request_preempt(self) -> None:
        self._preempt_requested = True

    def service_preempt(self) -> None:
        self._preempt_requested = False
        rep = self._reporter
        if rep is not None:
            rep.preempt(self._path, "serviced")

    def recall_preempt(self) -> None:
        self._preempt_requested = False

    def preempt_requested(self) -> bool:
        return self._preempt_requested


class CBState(State):
    """A state whose execute is a callback ``cb(ud, *cb_args, **cb_kwargs)``."""

    def __init__(self, cb: Callable[..., Any], cb_args: list = [], cb_kwargs: dict = {},
                 outcomes: Iterable[str] = [], input_keys: list[str] = [], output_keys: list[str] = [],
                 io_keys: list[str] = []) -> None:
        State.__init__(self, outcomes, input_keys, output_keys, io_keys)
        self._cb = cb
        self._cb_args = cb_args
        self._cb_kwargs = cb_kwargs
        if has_smach_interface(cb):
            self._input_keys = self._input_keys.union(cb.get_registered_input_keys())
            self._output_keys = self._output_keys.union(cb.get_registered_output_keys())
            self._outcomes = self._outcomes.union(cb.get_registered_outcomes())

    def execute(self, ud: Any) -> str:
        return self._cb(ud, *self._cb_args, **self._cb_kwargs)
