"""A machine of this process's ``Controls`` (fsm/control/controls.py): preempt, hold, initial state,
start, and its debugger's (``debug.DebugControl``).

Every call here may block briefly on the machine's own locks, so the app runs them in a
worker thread, never on the event loop.
"""

from __future__ import annotations

import threading
import time
from typing import Any, Callable

from fsm.observation import introspection
from fsm.observation import original
from fsm.observation import runtimes
from fsm.observation import structure
from fsm.observation.schema import build

from .controls import Capabilities, Refused
from .debug import DebugControl

LAST_RUN_GRACE = 1.0  # seconds a start waits for the previous run's execute() to return
CANNOT_START = "this process cannot re-run the machine (can_start is false)"
CANNOT_HOLD = "this machine is not run in a loop: there is no next run to hold"


class MachineHandle:
    """Preempt, set the initial state of, re-run and debug one local machine (``Controls``).

    A re-run executes the machine in a new thread of this handle, unless a ``starter`` is given:
    then a start calls ``starter()`` instead (in the request's worker thread, never on the event
    loop), for a host that runs the machine in its own loop (the sim demo: "next episode").
    A starter should return promptly; one that raises answers 409 with its message.

    Such a host may also give a ``holder``: ``holder()`` asks it to start no further run until
    the next start (the demo: "stop after this episode"). With one, a preempt that arrives
    between two runs is not lost: it holds the loop instead of answering 409.
    """

    def __init__(self, machine: Any, reporter: introspection.Reporter, can_start: bool,
                 starter: Callable[[], Any] | None = None, holder: Callable[[], Any] | None = None) -> None:
        self.machine = machine
        self.reporter = reporter
        self.can_start = can_start
        self.starter = starter
        self.holder = holder
        self.held = False  # a hold was asked and no start has come since
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None
        self._pending: list[tuple[Any, list[str], dict | None]] = []
        self._hook_installed = False
        self._between_runs = False  # an original machine's run has ended (its termination callbacks ran)
        self._debug: DebugControl | None = None

    def capabilities(self) -> Capabilities:
        cannot = {}
        if not self.can_start:
            cannot["start"] = CANNOT_START
        if self.holder is None:
            cannot["hold"] = CANNOT_HOLD
        return Capabilities(cannot=cannot)

    def is_running(self) -> bool:
        if runtimes.is_running(self.machine):
            return True
        thread = self._thread
        return thread is not None and thread.is_alive()

    def emit_control(self, action: str, client: str, result: str, reason: str | None = None,
                     params: dict | None = None, path: str | None = None) -> int:
        event = self.reporter.send(build.control, path or self.reporter.root_path, action, client, result,
                                   reason, params or {})
        return event["seq"] if event is not None else self.reporter.last_seq

    def lease_changed(self, held: bool, after: float, action: str) -> None:
        """Nothing to tell: the server applies the deadman itself to a machine of its own process
        (a remote machine's handle tells its publisher, fsmscope/server/remote_control.py)."""

    # The debugger (attached on the first of these calls: a machine nobody debugs never pays for one).
    @property
    def debug(self) -> DebugControl:
        if self._debug is None:
            self._debug = DebugControl(self.machine, self.emit_control)
        return self._debug

    def pause(self, client: str) -> int:
        return self.debug.pause(client)

    def resume(self, client: str) -> int:
        return self.debug.resume(client)

    def step(self, level: str | None, client: str) -> int:
        return self.debug.step(level, client)

    def force(self, state: str, outcome: str, client: str) -> int:
        return self.debug.force(state, outcome, client)

    def set_breakpoints(self, breakpoints: list[Any], client: str) -> list[dict]:
        return self.debug.set_breakpoints(breakpoints, client)

    def breakpoints(self) -> list[dict]:
        return self.debug.breakpoints()

    # Preempt (the /sm_stop of this world).
    def preempt(self, reason: str | None, client: str) -> int:
        if not self.is_running():
            if self.holder is not None:  # between two runs of a loop: the next one must not start
                return self._hold("preempt", reason, client)
            self.emit_control("preempt", client, "not running", reason)
            raise Refused(409, "machine is not running")
        seq = self.emit_control("preempt", client, "accepted", reason)
        self.machine.request_preempt()
        return seq

    def hold(self, reason: str | None, client: str) -> int:
        """Let the current run finish, then start no other until the next start."""
        if self.holder is None:
            self.emit_control("hold", client, "no loop to hold", reason)
            raise Refused(409, CANNOT_HOLD)
        return self._hold("hold", reason, client)

    def _hold(self, action: str, reason: str | None, client: str) -> int:
        self.held = True
        self.holder()
        return self.emit_control(action, client, "accepted", reason, params={"until": "start"})

    # Initial state ('Set as Initial State').
    def container_at(self, path: str) -> Any:
        root_path = self.reporter.root_path
        if path == root_path:
            return self.machine
        if not path.startswith(root_path + "/"):
            return None
        return structure.state_at(self.machine, path[len(root_path) + 1:].split("/"))

    def set_initial_state(self, path: str | None, states: list[str], userdata: dict | None, client: str) -> int:
        path = path or self.reporter.root_path
        params = {"path": path, "states": states, "userdata_keys": sorted(userdata or {})}
        try:
            container = self.container_at(path)
            if container is None:
                raise Refused(404, "no state at path %r" % path)
            if not structure.is_container(container):
                raise Refused(422, "%r is a state, not a container" % path)
            self._check_settable(container)
            self._check_states(container, states)
        except Refused as err:
            self.emit_control("initial-state", client, err.message, params=params, path=path)
            raise
        with self._lock:
            deferred = self.is_running() and not self._between_runs
            if deferred:
                self._pending.append((container, states, userdata))
                self._install_hook()
            else:
                self._apply(container, states, userdata)
        return self.emit_control("initial-state", client, "accepted", params=dict(params, deferred=deferred),
                                 path=path)

    @staticmethod
    def _check_states(container: Any, states: list[str]) -> None:
        kind = type(container).__name__
        children = container.get_children()
        unknown = [s for s in states if s not in children]
        if unknown:
            raise Refused(422, "unknown states %s in %s (states: %s)" % (unknown, kind, sorted(children)))
        if not states:
            return
        if structure.is_concurrence(container):
            raise Refused(422, "a Concurrence starts all its children; it takes no initial states")
        if len(states) > 1:
            raise Refused(422, "a %s has exactly one initial state" % kind)

    @staticmethod
    def _check_settable(container: Any) -> None:
        """SMACH's Container leaves set_initial_state unimplemented: a user's own container class may too."""
        if getattr(type(container).set_initial_state, "__qualname__", "") == "Container.set_initial_state":
            raise Refused(422, "a %s takes no initial state: its class does not implement set_initial_state"
                          % type(container).__name__)

    @staticmethod
    def _apply(container: Any, states: list[str], userdata: dict | None) -> None:
        runtimes.set_initial_state(container, states, userdata or {})

    def _install_hook(self) -> None:
        if self._hook_installed:
            return
        self._hook_installed = True
        if original.is_original(self.machine):
            # The original takes its initial state before its start callbacks run: a deferred one is
            # applied as the run ends instead, when the run reads none of it again.
            self.machine.register_start_cb(self._on_original_start)
            self.machine.register_termination_cb(self._on_original_end)
        else:
            introspection.add_global_hook(self._on_top_level_start)

    def _on_top_level_start(self, container: Any) -> None:
        """A deferred initial state takes effect as the machine starts its next run."""
        if container is self.machine:
            self._apply_pending()

    def _on_original_start(self, userdata: Any, initial_states: Any) -> None:
        with self._lock:
            self._between_runs = False

    def _on_original_end(self, userdata: Any, terminal_states: Any, outcome: Any) -> None:
        with self._lock:
            self._between_runs = True
        self._apply_pending()

    def _apply_pending(self) -> None:
        with self._lock:
            pending, self._pending = self._pending, []
            for target, states, userdata in pending:
                self._apply(target, states, userdata)

    # Re-run.
    def start(self, client: str) -> int:
        with self._lock:
            if not self.can_start:
                self.emit_control("start", client, "this process cannot re-run the machine")
                raise Refused(409, CANNOT_START)
            # The last run's outcome is out (a page can ask for the next run at once) a moment before
            # its execute() has returned, in our thread or the process's own: give it that long.
            self._wait_until_stopped(LAST_RUN_GRACE)
            if self.is_running():
                self.emit_control("start", client, "already running")
                raise Refused(409, "machine is running")
            pending, self._pending = self._pending, []
            for target, states, userdata in pending:
                self._apply(target, states, userdata)
            self.held = False
            recall_every_preempt(self.machine)
            seq = self.emit_control("start", client, "accepted")
            if self.starter is not None:
                try:
                    self.starter()
                except Exception as exc:
                    message = "the starter failed: %s: %s" % (type(exc).__name__, exc)
                    self.emit_control("start", client, message)
                    raise Refused(409, message) from exc
                return seq
            thread = threading.Thread(target=self._run, name="fsmscope-run-%s" % self.reporter.machine, daemon=True)
            self._thread = thread
            thread.start()
        return seq

    def _wait_until_stopped(self, timeout: float) -> None:
        deadline = time.monotonic() + timeout
        self.join(timeout)
        while self.is_running() and time.monotonic() < deadline:
            time.sleep(0.01)

    def _run(self) -> None:
        try:
            self.machine.execute()
        except BaseException:  # reported as error and terminate events by the runtime
            pass

    def join(self, timeout: float | None = None) -> None:
        thread = self._thread
        if thread is not None:
            thread.join(timeout)


def recall_every_preempt(state: Any) -> None:
    """Clear the preempts a run left behind: one asked of a state just as it returned is never serviced
    (SMACH keeps it), and the next run Start begins would end 'preempted' at that state at once. A
    container (SMACH's API: ``get_children``) and each of its states, all the way down; a state
    without preempt methods (SMACH runs any object with ``execute`` and outcomes) has none to clear."""
    recall = getattr(state, "recall_preempt", None)
    if recall is not None:
        recall()
    for child in state.get_children().values() if hasattr(state, "get_children") else ():
        recall_every_preempt(child)
