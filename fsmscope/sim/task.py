"""The fault-tolerant pick-and-place task machine.

```
RUN (Concurrence: first child to finish ends both)
├── TASK (StateMachine)
│   ├── SENSE       CBState: cube pose into userdata
│   ├── PICK        APPROACH → DESCEND → CLOSE → VERIFY → LIFT
│   │               VERIFY 'failed' or LIFT 'aborted' (object lost) → REOPEN
│   │               REOPEN → 'retry' (APPROACH) while attempts <= max_retries, else 'give_up'
│   ├── PLACE       TRANSPORT → LOWER → RELEASE → RETREAT
│   ├── GO_HOME     → succeeded
│   └── SAFE_OPEN → SAFE_HOME → aborted   (grasp given up, or any step aborted)
└── MONITOR (MonitorState on 'sm_stop': any message ends it 'invalid', which preempts TASK)
```

Every arm and gripper step is a ``SimpleActionState`` on the MoveTo / Gripper servers
of :mod:`sim.servers`. Userdata: ``cube_pose`` (dict x, y, z, yaw), ``attempts`` (grasp
attempts made), ``grasp`` (the last Gripper result: ``{"held", "opening"}``).
"""

from __future__ import annotations

import math
from typing import Any, Callable

import fsm as smach
from fsm.ros.actionlib import GoalStatus

from .servers import GRIPPER, MOVE_TO
from .world import World

APPROACH_HEIGHT = 0.12  # tool above the cube centre before descending (m)
GRASP_OFFSET = 0.005  # tool above the cube centre when closing (m)
LIFT_HEIGHT = 0.15
PLACE_OFFSET = 0.008  # tool above the resting cube centre when releasing (m)
STOP_TOPIC = "sm_stop"
KEYS = ["cube_pose", "attempts", "grasp"]


def _cube_yaw(yaw: float) -> float:
    """A cube looks the same every quarter turn: the equivalent yaw nearest zero."""
    return (yaw + math.pi / 4) % (math.pi / 2) - math.pi / 4


def _over_cube(ud: Any, dz: float) -> dict:
    c = ud.cube_pose
    return {"x": c["x"], "y": c["y"], "z": c["z"] + dz, "yaw": _cube_yaw(c["yaw"])}


def build_task_machine(world: World, bus=None, max_retries: int = 3) -> smach.Concurrence:
    """The whole machine: the task beside a 'sm_stop' monitor, in one Concurrence.

    ``execute()`` returns 'succeeded', 'aborted' or 'preempted'. The action servers
    (``sim.servers.start_servers(world, bus)``) must be running on the same bus.
    """
    from fsm.ros.monitor_state import MonitorState
    from fsm.ros.simple_action_state import SimpleActionState

    target = world.target_pos

    def move(label: str, goal_fn: Callable[[Any], dict], *, check_held: bool = False,
             input_keys=(), output_keys=(), outcomes=(), result_cb=None):
        def goal_cb(ud, _default=None):
            world.label = label
            goal = dict(goal_fn(ud))
            if check_held:
                goal["check_held"] = True
            return goal

        return SimpleActionState(MOVE_TO, goal_cb=goal_cb, input_keys=list(input_keys),
                                 output_keys=list(output_keys), outcomes=list(outcomes),
                                 result_cb=result_cb, bus=bus)

    def grip(label: str, command: str, *, goal_hook=None, result_cb=None,
             input_keys=(), output_keys=(), outcomes=()):
        def goal_cb(ud, _default=None):
            world.label = label
            if goal_hook is not None:
                goal_hook(ud)
            return {"command": command}

        return SimpleActionState(GRIPPER, goal_cb=goal_cb, input_keys=list(input_keys),
                                 output_keys=list(output_keys), outcomes=list(outcomes),
                                 result_cb=result_cb, bus=bus)

    # ---------------------------------------------------------------- PICK
    pick = smach.StateMachine(outcomes=["succeeded", "grasp_failed", "aborted", "preempted"],
                              input_keys=KEYS, output_keys=KEYS)

    def count_attempt(ud):
        ud.attempts = int(ud.attempts or 0) + 1

    def store_grasp(ud, status, result):
        ud.grasp = result
        return None

    def verify_result(ud, status, result):
        ud.grasp = result
        if status == GoalStatus.SUCCEEDED and not (result or {}).get("held"):
            return "failed"
        return None

    def reopen_result(ud, status, result):
        if status != GoalStatus.SUCCEEDED:
            return None
        ud.cube_pose = world.cube_pose()  # look again: the cube may have moved
        return "retry" if int(ud.attempts or 0) <= max_retries else "give_up"

    with pick:
        smach.StateMachine.add(
            "APPROACH", move("PICK/APPROACH", lambda ud: {"pose": _over_cube(ud, APPROACH_HEIGHT)},
                             input_keys=["cube_pose"]),
            transitions={"succeeded": "DESCEND", "aborted": "aborted", "preempted": "preempted"})
        smach.StateMachine.add(
            "DESCEND", move("PICK/DESCEND", lambda ud: {"pose": _over_cube(ud, GRASP_OFFSET)},
                            input_keys=["cube_pose"]),
            transitions={"succeeded": "CLOSE", "aborted": "REOPEN", "preempted": "preempted"})
        smach.StateMachine.add(
            "CLOSE", grip("PICK/CLOSE", "close", goal_hook=count_attempt, result_cb=store_grasp,
                          input_keys=["attempts"], output_keys=["attempts", "grasp"]),
            transitions={"succeeded": "VERIFY", "aborted": "REOPEN", "preempted": "preempted"})
        smach.StateMachine.add(
            "VERIFY", grip("PICK/VERIFY", "verify", result_cb=verify_result,
                           output_keys=["grasp"], outcomes=["failed"]),
            transitions={"succeeded": "LIFT", "failed": "REOPEN", "aborted": "REOPEN",
                         "preempted": "preempted"})
        smach.StateMachine.add(
            "LIFT", move("PICK/LIFT", lambda ud: {"pose": _over_cube(ud, LIFT_HEIGHT)},
                         check_held=True, input_keys=["cube_pose"]),
            transitions={"succeeded": "succeeded", "aborted": "REOPEN", "preempted": "preempted"})
        smach.StateMachine.add(
            "REOPEN", grip("PICK/REOPEN", "open", result_cb=reopen_result,
                           input_keys=["attempts"], output_keys=["cube_pose"],
                           outcomes=["retry", "give_up"]),
            transitions={"retry": "APPROACH", "give_up": "grasp_failed", "succeeded": "grasp_failed",
                         "aborted": "aborted", "preempted": "preempted"})

    # ---------------------------------------------------------------- PLACE
    place = smach.StateMachine(outcomes=["succeeded", "aborted", "preempted"],
                               input_keys=KEYS, output_keys=KEYS)
    tx, ty, tz = (float(v) for v in target)

    with place:
        smach.StateMachine.add(
            "TRANSPORT", move("PLACE/TRANSPORT",
                              lambda ud: {"pose": {"x": tx, "y": ty, "z": tz + LIFT_HEIGHT, "yaw": 0.0}},
                              check_held=True),
            transitions={"succeeded": "LOWER", "aborted": "aborted", "preempted": "preempted"})
        smach.StateMachine.add(
            "LOWER", move("PLACE/LOWER",
                          lambda ud: {"pose": {"x": tx, "y": ty, "z": tz + PLACE_OFFSET, "yaw": 0.0}},
                          check_held=True),
            transitions={"succeeded": "RELEASE", "aborted": "aborted", "preempted": "preempted"})
        smach.StateMachine.add(
            "RELEASE", grip("PLACE/RELEASE", "open", result_cb=store_grasp, output_keys=["grasp"]),
            transitions={"succeeded": "RETREAT", "aborted": "aborted", "preempted": "preempted"})
        smach.StateMachine.add(
            "RETREAT", move("PLACE/RETREAT",
                            lambda ud: {"pose": {"x": tx, "y": ty, "z": tz + LIFT_HEIGHT, "yaw": 0.0}}),
            transitions={"succeeded": "succeeded", "aborted": "aborted", "preempted": "preempted"})

    # ---------------------------------------------------------------- TASK
    task = smach.StateMachine(outcomes=["succeeded", "aborted", "preempted"],
                              input_keys=KEYS, output_keys=KEYS)

    def sense(ud):
        world.label = "SENSE"
        ud.cube_pose = world.cube_pose()
        ud.attempts = 0
        ud.grasp = None
        return "succeeded"

    with task:
        smach.StateMachine.add(
            "SENSE", smach.CBState(sense, outcomes=["succeeded"], output_keys=KEYS),
            transitions={"succeeded": "PICK"})
        smach.StateMachine.add(
            "PICK", pick,
            transitions={"succeeded": "PLACE", "grasp_failed": "SAFE_HOME", "aborted": "SAFE_OPEN",
                         "preempted": "preempted"})
        smach.StateMachine.add(
            "PLACE", place,
            transitions={"succeeded": "GO_HOME", "aborted": "SAFE_OPEN", "preempted": "preempted"})
        smach.StateMachine.add(
            "GO_HOME", move("GO_HOME", lambda ud: {"waypoint": "home"}),
            transitions={"succeeded": "succeeded", "aborted": "aborted", "preempted": "preempted"})
        smach.StateMachine.add(
            "SAFE_OPEN", grip("SAFE_OPEN", "open"),
            transitions={"succeeded": "SAFE_HOME", "aborted": "SAFE_HOME", "preempted": "preempted"})
        smach.StateMachine.add(
            "SAFE_HOME", move("SAFE_HOME", lambda ud: {"waypoint": "home"}),
            transitions={"succeeded": "aborted", "aborted": "aborted", "preempted": "preempted"})

    # ---------------------------------------------------------------- RUN
    def stop_requested(ud, msg):
        world.label = "STOP requested"
        return False  # any message on 'sm_stop' ends the monitor 'invalid'

    run = smach.Concurrence(
        outcomes=["succeeded", "aborted", "preempted"],
        default_outcome="preempted",
        input_keys=KEYS, output_keys=KEYS,
        child_termination_cb=lambda outcomes: True,
        outcome_map={
            "succeeded": {"TASK": "succeeded"},
            "aborted": {"TASK": "aborted"},
            "preempted": {"MONITOR": "invalid"},
        },
    )
    run.userdata.cube_pose = world.cube_pose()
    run.userdata.attempts = 0
    run.userdata.grasp = None
    with run:
        smach.Concurrence.add("TASK", task)
        smach.Concurrence.add("MONITOR", MonitorState(STOP_TOPIC, dict, stop_requested, bus=bus))
    return run
