"""SimpleActionState: run an action goal from a state machine, as smach_ros's does."""

import functools
import time
from typing import Any, Callable, Iterable

from ..core import log
from .actionlib import GoalStatus, SimpleActionClient
from .bus import Bus, get_bus
from ..observation.encoding import encode
from ..observation.schema import build
from ..core.exceptions import InvalidStateError
from .preemptible import PreemptibleState, to_seconds
from .slots import set_slot, store
from .user_callback import FAILED, UserCallback


class SimpleActionState(PreemptibleState):
    """Sends a goal built from userdata and callbacks, waits for the result, stores it.

    Outcomes: succeeded, aborted, preempted, plus ``outcomes`` and a cb_interface
    result_cb's. A preempt cancels the goal; ``exec_timeout`` cancels it and gives
    'aborted'. Durations are seconds (or objects with ``to_sec()``).

    Differences from smach_ros, on purpose: the wait for the server starts at execute
    (not at construction) and can be preempted; ``preempt_timeout`` bounds the wait for a
    cancelled goal to end (as in the ROS 2 branch) instead of being ignored; a default goal
    (``action_spec()``, or an empty dict) is built fresh for every execution.
    """

    def __init__(self, action_name: str, action_spec: Callable[[], Any] | None = None,
                 goal: Any = None, goal_key: str | None = None, goal_slots: list[str] = [],
                 goal_cb: Callable[..., Any] | None = None, goal_cb_args: list = [], goal_cb_kwargs: dict = {},
                 result_key: str | None = None, result_slots: list[str] = [],
                 result_cb: Callable[..., Any] | None = None, result_cb_args: list = [],
                 result_cb_kwargs: dict = {},
                 input_keys: list[str] = [], output_keys: list[str] = [], outcomes: Iterable[str] = [],
                 exec_timeout: Any = None, preempt_timeout: Any = 60.0, server_wait_timeout: Any = 60.0,
                 feedback_cb: Callable[..., Any] | None = None, feedback_cb_args: list = [],
                 feedback_cb_kwargs: dict = {}, bus: Bus | None = None) -> None:
        PreemptibleState.__init__(self, outcomes=["succeeded", "aborted", "preempted"])
        if goal is not None and callable(goal):
            raise InvalidStateError("Goal object given to SimpleActionState that IS a function object")
        self._action_name = action_name
        self._action_spec = action_spec
        self._goal = goal
        self._check_goal_slots(goal_slots)
        self._exec_timeout = to_seconds(exec_timeout)
        self._preempt_timeout = to_seconds(preempt_timeout)
        self._server_wait_timeout = to_seconds(server_wait_timeout)
        self._bus = get_bus(bus)
        self._client = SimpleActionClient(action_name, self._bus)
        self._ud: Any = None

        owner = "action " + action_name
        self._goal_cb = UserCallback(self, owner, "goal", goal_cb, goal_cb_args, goal_cb_kwargs,
                                     input_keys, output_keys)
        self._feedback_cb = UserCallback(self, owner, "feedback", feedback_cb, feedback_cb_args,
                                         feedback_cb_kwargs, input_keys, output_keys)
        self._result_cb = UserCallback(self, owner, "result", result_cb, result_cb_args, result_cb_kwargs,
                                       input_keys, output_keys, returns_outcome=True)
        self._goal_key = goal_key
        self._goal_slots = list(goal_slots)
        self._result_key = result_key
        self._result_slots = list(result_slots)
        self.register_input_keys(input_keys + goal_slots + ([goal_key] if goal_key is not None else []))
        self.register_output_keys(output_keys + result_slots + ([result_key] if result_key is not None else []))
        self.register_outcomes(outcomes)

    def _check_goal_slots(self, goal_slots: list[str]) -> None:
        """A goal type that declares ``__slots__`` (as ROS messages do) must have every goal slot."""
        template = self._goal if self._goal is not None else self._default_goal()
        declared = getattr(type(template), "__slots__", None)
        if declared is not None and not all(s in declared for s in goal_slots):
            raise InvalidStateError("Goal slots specified are not valid slots. Available slots: %s; specified slots: %s"
                                    % (list(declared), goal_slots))

    def _default_goal(self) -> Any:
        return self._action_spec() if self._action_spec is not None else {}

    def request_preempt(self) -> None:
        log.loginfo("Preempt requested on action '%s'" % self._action_name)
        PreemptibleState.request_preempt(self)

    def execute(self, ud: Any) -> str:
        name = self._action_name
        up = self._wait_for(functools.partial(self._bus.wait_for_action_server, name), self._server_wait_timeout,
                            "Still waiting for action server '%s' to start... is it running?" % name)
        if self.preempt_requested():
            log.loginfo("Preempting %s before sending goal." % name)
            self.service_preempt()
            return "preempted"
        if not up:
            log.logerr("Action server for " + name + " is not running.")
            return "aborted"

        goal = self._goal if self._goal is not None else self._default_goal()
        if self._goal_key is not None:
            goal = ud[self._goal_key]
        for key in self._goal_slots:
            set_slot(goal, key, ud[key])
        goal = self._goal_cb.update(ud, goal)
        if goal is FAILED:
            return "aborted"
        if goal is None:
            log.logerr("Attempting to activate action " + name + " with no goal or goal callback set. "
                       "Did you construct the SimpleActionState properly?")
            return "aborted"

        self._ud = ud
        self._client.send_goal(goal, done_cb=self._on_done, feedback_cb=self._on_feedback)
        if not self._wait_for_result(goal):
            return self._give_up()

        status = self._client.get_state()
        result = self._client.get_result()
        outcome = self._result_cb.run(ud, status, result)
        if outcome is FAILED:
            return "aborted"
        store(ud, result, self._result_key, self._result_slots)
        if status == GoalStatus.SUCCEEDED:
            default = "succeeded"
        elif status == GoalStatus.PREEMPTED and self.preempt_requested():
            default = "preempted"
            self.service_preempt()
        else:
            default = "aborted"
        return outcome if outcome is not None else default

    def _wait_for_result(self, goal: Any) -> bool:
        """Wait for the goal to end, cancelling it on preempt or exec timeout; False if a
        cancelled goal outlives ``preempt_timeout``."""
        start = time.monotonic()
        exec_deadline = start + self._exec_timeout if self._exec_timeout else None
        cancelled_at = None
        while True:
            self._wake.clear()
            if self._client.get_state() in GoalStatus.TERMINAL:
                return True
            now = time.monotonic()
            if cancelled_at is None:
                if self.preempt_requested():
                    log.loginfo("Preempt on action '%s' cancelling goal: \n%s" % (self._action_name, goal))
                elif exec_deadline is not None and now >= exec_deadline:
                    log.logwarn("Action %s timed out after %d seconds." % (self._action_name, self._exec_timeout))
                else:
                    self._wake.wait(None if exec_deadline is None else exec_deadline - now)
                    continue
                cancelled_at = now
                self._client.cancel_goal()
            elif self._preempt_timeout is None:
                self._wake.wait()
            elif now - cancelled_at < self._preempt_timeout:
                self._wake.wait(cancelled_at + self._preempt_timeout - now)
            else:
                return False

    def _give_up(self) -> str:
        log.logwarn("Action '%s' did not end within %s seconds of its cancellation; leaving it."
                    % (self._action_name, self._preempt_timeout))
        if self.preempt_requested():
            self.service_preempt()
            return "preempted"
        return "aborted"

    def _on_done(self, status: int, result: Any) -> None:
        log.logdebug("Action %s terminated with result %s." % (self._action_name, GoalStatus.name(status)))
        self._wake.set()

    def _on_feedback(self, feedback: Any) -> None:
        rep = self._reporter
        if rep is not None:
            rep.send(build.feedback, self._path, self._action_name, encode(feedback))
        self._feedback_cb.run(self._ud, feedback)
