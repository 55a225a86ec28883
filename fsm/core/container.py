"""What every container shares: construction with ``with``, callbacks, key copying, reporting."""

import threading
import traceback
from contextlib import contextmanager
from typing import Any, Callable, Iterator as TypingIterator

from . import log, reporting
from .exceptions import InvalidConstructionError, InvalidStateError, InvalidTransitionError
from .state import State
from .user_data import UserData


class Container(State):
    """Base of StateMachine, Concurrence and Iterator; holds the children's userdata scope."""

    _construction_stack: list["Container"] = []
    _construction_lock = threading.RLock()
    _context_kwargs: list[dict] = []

    def __init__(self, outcomes: Any = [], input_keys: list[str] = [], output_keys: list[str] = []) -> None:
        State.__init__(self, outcomes, input_keys, output_keys)
        self.userdata = UserData()
        self._start_cbs: list[tuple] = []
        self._transition_cbs: list[tuple] = []
        self._termination_cbs: list[tuple] = []
        self._debugger = None  # read at every step: an attribute of its own is found faster than State's

    # What SMACH's error messages call this kind of container.
    _kind_name = "Container"

    def execute(self, parent_ud: Any = None) -> Any:
        """Run ``_execute`` between the introspection bookkeeping of a start and an end."""
        ctx = self._report_start(parent_ud)
        try:
            return self._execute(parent_ud)
        except BaseException as exc:
            self._report_error(self._on_failure(), exc)
            raise
        finally:
            reporting.leave(ctx)

    def _execute(self, parent_ud: Any) -> Any:
        raise NotImplementedError()

    def _on_failure(self) -> Any:
        """A run raised: undo what the run set; returns the label of the child that failed, if known."""
        return None

    # The interface every container implements.
    def __getitem__(self, key: str) -> State:
        children = self.get_children()
        if key not in children:
            log.logerr("Attempting to get state '%s' from %s container. The only available states are: %s"
                       % (key, self._kind_name, str(list(children.keys()))))
            raise KeyError()
        return children[key]

    def get_children(self) -> dict:
        raise NotImplementedError()

    def set_initial_state(self, initial_states: list[str], userdata: Any = None) -> None:
        raise NotImplementedError()

    def get_initial_states(self) -> list[str]:
        raise NotImplementedError()

    def get_active_states(self) -> list[str]:
        raise NotImplementedError()

    def get_internal_edges(self) -> list:
        raise NotImplementedError()

    def check_consistency(self) -> None:
        raise NotImplementedError()

    def _introspection_info(self) -> dict:
        """Type-specific fields of this container's structure node."""
        return {}

    # Userdata passing.
    def _copy_input_keys(self, parent_ud: Any, ud: UserData) -> None:
        if parent_ud is not None:
            for ik in self.get_registered_input_keys():
                try:
                    ud[ik] = parent_ud[ik]
                except KeyError:
                    log.logwarn("Attempting to copy input key '%s', but this key does not exist." % ik)

    def _copy_output_keys(self, ud: UserData, parent_ud: Any) -> None:
        if parent_ud is not None:
            for ok in self.get_registered_output_keys():
                try:
                    parent_ud[ok] = ud[ok]
                except KeyError:
                    log.logwarn("Attempting to copy output key '%s', but this key does not exist." % ok)

    # Callbacks.
    def register_start_cb(self, start_cb: Callable, cb_args: list = []) -> None:
        self._start_cbs.append((start_cb, cb_args))

    def register_transition_cb(self, transition_cb: Callable, cb_args: list = []) -> None:
        self._transition_cbs.append((transition_cb, cb_args))

    def register_termination_cb(self, termination_cb: Callable, cb_args: list = []) -> None:
        self._termination_cbs.append((termination_cb, cb_args))

    def call_start_cbs(self) -> None:
        try:
            for cb, args in self._start_cbs:
                cb(self.userdata, self.get_initial_states(), *args)
        except Exception:
            log.logerr("Could not execute start callback: " + traceback.format_exc())

    def call_transition_cbs(self) -> None:
        try:
            for cb, args in self._transition_cbs:
                cb(self.userdata, self.get_active_states(), *args)
        except Exception:
            log.logerr("Could not execute transition callback: " + traceback.format_exc())

    def call_termination_cbs(self, terminal_states: Any, outcome: Any) -> None:
        try:
            for cb, args in self._termination_cbs:
                cb(self.userdata, terminal_states, outcome, *args)
        except Exception:
            log.logerr("Could not execute termination callback: " + traceback.format_exc())

    # Reporting (fsm/core/reporting.py): each a no-op unless a tool observes this machine.
    def _report_start(self, parent_ud: Any) -> Any:
        """Run the global hooks for a top-level start; returns the thread context to restore."""
        if parent_ud is None and reporting.top_level_hooks:
            reporting.on_top_level_start(self)
        rep = self._reporter
        if rep is None:
            return reporting.NOT_ENTERED
        if rep.root is self:
            rep.begin_run()
        return reporting.enter(rep, self._path)

    def _report_changes(self) -> None:
        """A ``userdata`` event of the keys written since they were last reported, outside a step (a
        debugger's hold shows them): a step's writes ride on its transition or terminate instead."""
        rep = self._reporter
        if rep is not None:
            written = self.userdata.take_written()
            if written:
                rep.userdata(self._path, written)

    def _report_started(self) -> None:
        rep = self._reporter
        if rep is not None:
            self.userdata.track_writes()
            rep.start(self._path, [str(s) for s in self.get_initial_states()],
                      [str(s) for s in self.get_active_states()], self.userdata)

    def _report_error(self, label: Any, exc: BaseException) -> None:
        """An ``error`` event from the innermost container that saw ``exc``, then ``terminate``."""
        rep = self._reporter
        if rep is None:
            return
        if reporting.mark_reported(exc):
            rep.error(self._path, label, exc)
        rep.terminate(self._path, [] if label is None else [str(label)], None, [],
                      error="%s: %s" % (type(exc).__name__, exc))

    def _report_ended(self, error: str) -> None:
        """A run that ended without an outcome (and without an exception): ``error`` says why."""
        rep = self._reporter
        if rep is not None:
            rep.terminate(self._path, [], None, [], error=error)

    def _report_preempt_requested(self) -> None:
        rep = self._reporter
        if rep is not None:
            rep.preempt(self._path, "requested")

    def request_preempt(self) -> None:
        State.request_preempt(self)
        self._report_preempt_requested()

    # Construction.
    def open(self) -> None:
        Container._construction_stack.append(self)
        Container._construction_lock.acquire()

    def close(self) -> None:
        if Container._construction_stack and Container._construction_stack[-1] is not self:
            raise InvalidStateError("Attempting to close a container that is not currently open.")
        Container._construction_stack.pop()
        Container._construction_lock.release()
        try:
            self.check_consistency()
        except (InvalidStateError, InvalidTransitionError):
            log.logerr("Container consistency check failed.")

    def is_opened(self) -> bool:
        return bool(Container._construction_stack) and Container._construction_stack[-1] is self

    def assert_opened(self, msg: str = "") -> None:
        if not self.is_opened():
            raise InvalidConstructionError(msg)

    @staticmethod
    def _any_containers_opened() -> bool:
        return len(Container._construction_stack) > 0

    @classmethod
    def _currently_opened_container(cls) -> "Container":
        """The container every construction call acts on (so also where the structure changes)."""
        reporting.structure_changed()
        if Container._any_containers_opened():
            opened = Container._construction_stack[-1]
            if not isinstance(opened, cls):
                raise InvalidStateError("Attempting to call a %s construction method without having opened a %s." % (cls, cls))
            return opened
        raise InvalidStateError("Attempting to access the currently opened container, but no container is opened.")

    @contextmanager
    def opened(self, **kwargs: Any) -> TypingIterator["Container"]:
        """``with container.opened() as c:`` opens it for construction (binding it, unlike ``with container``)."""
        self.open()
        prev = Container._context_kwargs
        Container._context_kwargs = kwargs
        try:
            yield self
        finally:
            Container._context_kwargs = prev
            self.close()

    def __enter__(self) -> None:
        return self.open()

    def __exit__(self, exc_type: Any, exc_val: Any, exc_tb: Any) -> bool:
        if exc_type is None:
            self.close()
            return False
        if exc_type not in (InvalidStateError, InvalidTransitionError):
            log.logerr("Error raised during SMACH container construction: \n"
                       + "\n".join(traceback.format_exception(exc_type, exc_val, exc_tb)))
        # Fixed against SMACH: the failed container is closed, so the stack and the global lock
        # are not left held; the exception still propagates.
        if self in Container._construction_stack:
            Container._construction_stack.remove(self)
            Container._construction_lock.release()
        return False
