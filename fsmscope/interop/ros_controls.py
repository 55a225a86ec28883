"""The controls of a machine followed on a live ROS graph (fsmscope/interop/ros_watcher.py), the ROS
way: what a robot running smach_ros's own IntrospectionServer takes from outside, and nothing more.

- Set initial state publishes smach_msgs' ``SmachContainerInitialStatusCmd`` on
  ``<server>/smach/container_init``; the robot's server sets the container's initial states and
  userdata, which its next run starts from. The userdata travels as a protocol 2 pickle (base64 of it
  on ROS 1), which this module makes only from plain values (dict, list, tuple, str, numbers, bools,
  None): what the robot unpickles is never anything else.
- Preempt publishes ``std_msgs/Empty`` on the machine's stop topic (``/sm_stop`` unless told:
  ``RosWatcher``'s ``stop_topic``),
  which a MonitorState of the robot's machine listens to, as smach_viewer's users wire it.

Pause, step, breakpoints, forced outcomes, hold and start need the machine's own process: smach_ros
takes none of them. Each says so (``capabilities``), and its call is refused with those words and
recorded. Each control, taken or refused, is a ``control`` event in the machine's stream, as for any
machine, so the audit and the page say who asked what.
"""

from __future__ import annotations

import base64
import math
import pickle
from typing import Any

from fsm.control.controls import Capabilities, Refused
from fsm.observation.schema import build

from .ros_watcher import INIT_SUFFIX, RosWatcher, Unheard

IN_PROCESS_ONLY = ("hold", "start", "pause", "resume", "step", "force", "breakpoints")
NEEDS_IN_PROCESS = ("smach_ros's IntrospectionServer takes only Set initial state, and Preempt through the machine's "
                    "MonitorState: pause, step, breakpoints, forced outcomes and start need fsmscope's "
                    "IntrospectionServer in the robot's process (where smach_ros's stands; docs/ros.md)")


def plain(value: Any, where: str = "userdata") -> Any:
    """``value`` when it is made of plain values only (what a protocol 2 pickle of it can hold without
    naming a class); ValueError saying where it is not."""
    if value is None or type(value) in (bool, int, str):
        return value
    if type(value) is float:
        if not math.isfinite(value):
            raise ValueError("%s is %r: only finite numbers are sent" % (where, value))
        return value
    if type(value) in (list, tuple):
        return type(value)(plain(v, "%s[%d]" % (where, i)) for i, v in enumerate(value))
    if type(value) is dict:
        for key in value:
            if type(key) is not str:
                raise ValueError("%s has a key %r that is not a string" % (where, key))
        return {k: plain(v, "%s.%s" % (where, k)) for k, v in value.items()}
    raise ValueError("%s is a %s: only dict, list, str, numbers, bools and None are sent"
                     % (where, type(value).__name__))


def _in_process_only(action: str) -> Any:
    """A control smach_ros does not take: recorded, then refused (its last argument is the client)."""
    def refused(self: RosControls, *args: Any) -> int:
        return self._refuse(action, args[-1], 409, NEEDS_IN_PROCESS)
    refused.__name__ = action
    return refused


class RosControls:
    """One followed machine's ``fsm.control.Controls``: its robot reached through ``watcher``'s node."""

    held = False

    def __init__(self, watcher: RosWatcher, name: str) -> None:
        self.watcher = watcher
        self.name = name

    def _machine(self) -> Any:
        machine = self.watcher.machine(self.name)
        if machine is None:
            raise Refused(404, "machine %r is not followed on the ROS graph" % self.name)
        return machine

    def capabilities(self) -> Capabilities:
        machine = self.watcher.machine(self.name)
        if machine is None or not machine.up:
            return Capabilities(unavailable="machine %r: its robot stopped publishing" % self.name)
        return Capabilities(cannot=dict.fromkeys(IN_PROCESS_ONLY, NEEDS_IN_PROCESS))

    def preempt(self, reason: str | None, client: str) -> int:
        topic = self._up().stop_topic
        params = {"topic": topic}
        try:
            self.watcher.publish(topic, self.watcher.flavour.empty, {})
        except Unheard:
            return self._refuse("preempt", client, 409, "nobody subscribes to %s: no MonitorState of the robot's "
                                "machine listens there now (it is not running, or waits on another topic: "
                                "--stop-topic)" % topic, params)
        return self.emit_control("preempt", client, "accepted", reason, params)

    def set_initial_state(self, path: str | None, states: list[str], userdata: dict | None, client: str) -> int:
        machine = self._up()
        path = path or machine.follower.root
        params = {"path": path, "states": states, "userdata": userdata or {}}
        if not states or any(type(s) is not str for s in states):
            return self._refuse("initial-state", client, 422, "the initial states must be a non-empty list of names",
                                params)
        try:
            data = pickle.dumps(plain(userdata or {}), 2)
        except ValueError as exc:
            return self._refuse("initial-state", client, 422, str(exc), params)
        local_data = base64.b64encode(data).decode("ascii") if self.watcher.flavour.base64_local_data else data
        topic = machine.server + INIT_SUFFIX
        try:
            self.watcher.publish(topic, self.watcher.flavour.init,
                                 {"path": path, "initial_states": list(states), "local_data": local_data})
        except Unheard:
            return self._refuse("initial-state", client, 409, "nobody subscribes to %s: the robot's "
                                "IntrospectionServer does not listen for initial states" % topic, params)
        return self.emit_control("initial-state", client, "accepted", None, params, path)

    def emit_control(self, action: str, client: str, result: str, reason: str | None = None,
                     params: dict | None = None, path: str | None = None) -> int:
        machine = self._machine()
        return self.watcher.emit(self.name, build.control, path or machine.follower.root, action, client, result,
                                 reason, params or {})

    def lease_changed(self, held: bool, after: float, action: str) -> None:
        """Nothing to tell: the robot knows no lease, the server applies the deadman itself."""

    def breakpoints(self) -> list[dict]:
        return []

    def _up(self) -> Any:
        machine = self._machine()
        if not machine.up:
            raise Refused(409, "machine %r: its robot stopped publishing" % self.name)
        return machine

    def _refuse(self, action: str, client: str, status: int, why: str, params: dict | None = None) -> int:
        """Record the refusal in the machine's stream, then refuse."""
        self.emit_control(action, client, why, None, params or {})
        raise Refused(status, why)

    hold = _in_process_only("hold")
    start = _in_process_only("start")
    pause = _in_process_only("pause")
    resume = _in_process_only("resume")
    step = _in_process_only("step")
    force = _in_process_only("force")
    set_breakpoints = _in_process_only("breakpoints")
