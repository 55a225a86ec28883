"""A minimal in-process actionlib: SimpleActionServer and SimpleActionClient over fsm.ros.bus.

Semantics follow ROS's simple action server and client: the server runs one goal at a
time in its own worker thread and a new goal preempts the active one; the client tracks
only its latest goal. Client callbacks run in the thread that changes the goal's status
(usually the server's worker thread); a raising callback is logged and does not stop it.
"""

import threading
import traceback
from typing import Any, Callable

from ..core import log
from .bus import Bus, call_logged, get_bus


class GoalStatus:
    """The goal states a simple action client can report (ROS's numbering)."""

    PENDING = 0
    ACTIVE = 1
    PREEMPTED = 2
    SUCCEEDED = 3
    ABORTED = 4

    TERMINAL = frozenset((PREEMPTED, SUCCEEDED, ABORTED))
    _NAMES = ("PENDING", "ACTIVE", "PREEMPTED", "SUCCEEDED", "ABORTED")

    @staticmethod
    def name(status: int) -> str:
        """``'SUCCEEDED'`` for 3, and so on; ``'UNKNOWN (n)'`` otherwise."""
        if 0 <= status < len(GoalStatus._NAMES):
            return GoalStatus._NAMES[status]
        return "UNKNOWN (%s)" % status


class _Goal:
    """One goal shared by the client that sent it and the server that runs it."""

    def __init__(self, goal: Any, server: "SimpleActionServer | None", done_cb: Callable | None,
                 active_cb: Callable | None, feedback_cb: Callable | None) -> None:
        self.goal = goal
        self.server = server
        self.status = GoalStatus.PENDING
        self.result: Any = None
        self.text = ""
        self.cancel_requested = False
        self.done = threading.Event()
        self._lock = threading.Lock()
        self._done_cb = done_cb
        self._active_cb = active_cb
        self._feedback_cb = feedback_cb

    def detach(self) -> None:
        """The client stopped tracking this goal: no more callbacks."""
        self._done_cb = self._active_cb = self._feedback_cb = None

    def activate(self) -> bool:
        with self._lock:
            if self.status != GoalStatus.PENDING:
                return False
            self.status = GoalStatus.ACTIVE
        cb = self._active_cb
        if cb is not None:
            call_logged("action active callback", cb)
        return True

    def finish(self, status: int, result: Any, text: str) -> bool:
        """Move to a terminal status once; False if the goal had already ended."""
        with self._lock:
            if self.status in GoalStatus.TERMINAL:
                return False
            self.status, self.result, self.text = status, result, text
        cb = self._done_cb
        if cb is not None:
            call_logged("action done callback", cb, status, result)
        self.done.set()
        return True

    def feedback(self, fb: Any) -> None:
        cb = self._feedback_cb
        if cb is not None and self.status == GoalStatus.ACTIVE:
            call_logged("action feedback callback", cb, fb)


class SimpleActionServer:
    """Runs ``execute_cb(goal)`` for one goal at a time in its own worker thread."""

    def __init__(self, name: str, execute_cb: Callable[[Any], Any], auto_start: bool = True,
                 bus: Bus | None = None) -> None:
        self._name = name
        self._execute_cb = execute_cb
        self._bus = get_bus(bus)
        self._cond = threading.Condition()
        self._pending: _Goal | None = None
        self._current: _Goal | None = None
        self._running = False
        self._thread: threading.Thread | None = None
        if auto_start:
            self.start()

    def start(self) -> None:
        """Register on the bus and start the worker; raises ValueError if the name is taken."""
        with self._cond:
            if self._running:
                return
            self._bus.register_action_server(self._name, self)
            self._running = True
            self._thread = threading.Thread(target=self._work, name="action:" + self._name, daemon=True)
        self._thread.start()

    def shutdown(self, timeout: float = 5.0) -> bool:
        """Stop taking goals, preempt the active one, abort the pending one.

        Waits up to ``timeout`` s for the running ``execute_cb`` to return; True if it did.
        """
        with self._cond:
            if not self._running:
                return True
            self._running = False
            pending, self._pending = self._pending, None
            if self._current is not None:
                self._current.cancel_requested = True
            self._cond.notify_all()
            thread = self._thread
        self._bus.unregister_action_server(self._name, self)
        if pending is not None:
            pending.finish(GoalStatus.ABORTED, None, "The action server shut down.")
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout)
            return not thread.is_alive()
        return True

    # Called by the client

    def _submit(self, goal: _Goal) -> None:
        with self._cond:
            if not self._running:
                replaced = goal
            else:
                replaced, self._pending = self._pending, goal
                if self._current is not None:
                    self._current.cancel_requested = True
                self._cond.notify_all()
        if replaced is goal:
            goal.finish(GoalStatus.ABORTED, None, "The action server shut down.")
        elif replaced is not None:
            replaced.finish(GoalStatus.PREEMPTED, None,
                            "This goal was canceled because another goal was received by the simple action server")

    def _cancel(self, goal: _Goal) -> None:
        with self._cond:
            recalled = goal is self._pending
            if recalled:
                self._pending = None
            else:
                goal.cancel_requested = True
        if recalled:
            goal.finish(GoalStatus.PREEMPTED, None, "The goal was canceled before it started.")

    # The worker

    def _work(self) -> None:
        while True:
            with self._cond:
                while self._running and self._pending is None:
                    self._cond.wait()
                if not self._running:
                    return
                goal, self._pending = self._pending, None
                self._current = goal
            if goal.activate():
                self._run(goal)
            with self._cond:
                self._current = None

    def _run(self, goal: _Goal) -> None:
        try:
            self._execute_cb(goal.goal)
        except Exception:
            tb = traceback.format_exc()
            log.logerr("Exception in your execute callback: " + tb)
            goal.finish(GoalStatus.ABORTED, None, tb)
            return
        if goal.finish(GoalStatus.ABORTED, None, "This goal was aborted by the simple action server. "
                       "The user should have set a terminal status on this goal and did not"):
            log.logwarn("Your executeCallback did not set the goal to a terminal status. This is a bug in "
                        "your ActionServer implementation. Fix your code! For now, the ActionServer will "
                        "set this goal to aborted")

    # For execute_cb

    def _active_goal(self) -> _Goal | None:
        goal = self._current
        return goal if goal is not None and goal.status == GoalStatus.ACTIVE else None

    def is_active(self) -> bool:
        return self._active_goal() is not None

    def is_preempt_requested(self) -> bool:
        """True once the client cancelled the active goal, a newer goal arrived, or the server shuts down."""
        goal = self._active_goal()
        return goal is not None and goal.cancel_requested

    def publish_feedback(self, fb: Any) -> None:
        goal = self._active_goal()
        if goal is not None:
            goal.feedback(fb)

    def set_succeeded(self, result: Any = None, text: str = "") -> None:
        self._set_terminal(GoalStatus.SUCCEEDED, result, text)

    def set_preempted(self, result: Any = None, text: str = "") -> None:
        self._set_terminal(GoalStatus.PREEMPTED, result, text)

    def set_aborted(self, result: Any = None, text: str = "") -> None:
        self._set_terminal(GoalStatus.ABORTED, result, text)

    def _set_terminal(self, status: int, result: Any, text: str) -> None:
        goal = self._active_goal()
        if goal is None or not goal.finish(status, result, text):
            log.logerr("To transition to %s, the goal of action server '%s' must be active."
                       % (GoalStatus.name(status), self._name))


class SimpleActionClient:
    """Sends goals to the server named ``name``; tracks only the latest goal, as ROS's does."""

    def __init__(self, name: str, bus: Bus | None = None) -> None:
        self._name = name
        self._bus = get_bus(bus)
        self._goal: _Goal | None = None

    def wait_for_server(self, timeout: float | None = None) -> bool:
        return self._bus.wait_for_action_server(self._name, timeout)

    def send_goal(self, goal: Any, done_cb: Callable[[int, Any], Any] | None = None,
                  active_cb: Callable[[], Any] | None = None,
                  feedback_cb: Callable[[Any], Any] | None = None) -> None:
        """Send ``goal``; a goal sent while no server runs is aborted at once (ROS would lose it)."""
        server = self._bus.action_server(self._name)
        handle = _Goal(goal, server, done_cb, active_cb, feedback_cb)
        previous, self._goal = self._goal, handle
        if previous is not None:
            previous.detach()
        if server is None:
            log.logerr("Sent a goal to action server '%s', which is not running." % self._name)
            handle.finish(GoalStatus.ABORTED, None, "Action server '%s' is not running." % self._name)
        else:
            server._submit(handle)

    def cancel_goal(self) -> None:
        goal = self._goal
        if goal is not None and goal.server is not None:
            goal.server._cancel(goal)

    def wait_for_result(self, timeout: float | None = None) -> bool:
        """True once the goal has ended; False on timeout or when no goal was sent."""
        goal = self._goal
        if goal is None:
            log.logerr("Called wait_for_result when no goal exists")
            return False
        return goal.done.wait(timeout)

    def get_state(self) -> int:
        goal = self._goal
        if goal is None:
            log.logerr("Called get_state when no goal is running")
            return GoalStatus.PENDING
        return goal.status

    def get_result(self) -> Any:
        goal = self._goal
        return None if goal is None else goal.result

    def get_goal_status_text(self) -> str:
        goal = self._goal
        if goal is None:
            log.logerr("Called get_goal_status_text when no goal is running")
            return ""
        return goal.text
