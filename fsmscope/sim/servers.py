"""MoveTo and Gripper action servers on the fsm bus.

Each server's work is a plain method ``run(goal, handle)``; ``handle`` is the
``fsm.ros.actionlib.SimpleActionServer`` (or anything with ``is_preempt_requested``,
``publish_feedback``, ``set_succeeded``, ``set_preempted``, ``set_aborted``). Goals,
feedback and results are plain dicts.

MoveTo goal: ``{"waypoint": "home"}`` or ``{"pose": {"x", "y", "z", "yaw"}}``; optional
``"duration"`` (s), ``"check_held"`` (abort with 'object lost' when the cube leaves the
fingers), ``"timeout"`` (s of simulated time after the planned end). Feedback
``{"distance": m}``. Result ``{"position": [x, y, z], "distance": m}``. Aborts with
'no IK solution', 'timeout' or 'object lost'.

Gripper goal: ``{"command": "open" | "close" | "verify"}``. Feedback ``{"distance": m}``
(finger travel left). Result ``{"held": bool, "opening": m}``.

On preemption the arm holds its current joint position at once.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .ik import IKSolver, tool_down_rotation
from .world import ARM_JOINTS, FINGER_CLOSED, FINGER_OPEN, HOME_Q, World, WorldStopped

MOVE_TO = "move_to"
GRIPPER = "gripper"

POLL = 0.01  # s of simulated time between checks (preemption, feedback, held)
FEEDBACK_EVERY = 0.1  # s of simulated time between feedback messages
MAX_JOINT_SPEED = 0.9  # rad/s, average over a move
MAX_LIN_SPEED = 0.25  # m/s, average over a Cartesian move
MIN_DURATION = 0.4  # s
WAYPOINT_STEP = 0.02  # m between IK waypoints on a Cartesian line
REACHED_TOL = 0.006  # m
SETTLE_SPEED = 0.05  # rad/s


def _get(goal: Any, key: str, default: Any = None) -> Any:
    if goal is None:
        return default
    if isinstance(goal, dict):
        return goal.get(key, default)
    return getattr(goal, key, default)


def _pose_of(p: Any) -> tuple[np.ndarray, float]:
    if isinstance(p, (list, tuple)):
        return np.array(p[:3], dtype=float), float(p[3]) if len(p) > 3 else 0.0
    return (
        np.array([_get(p, "x"), _get(p, "y"), _get(p, "z")], dtype=float),
        float(_get(p, "yaw", 0.0) or 0.0),
    )


def tool_yaw(rot: np.ndarray) -> float:
    """Yaw of a (roughly) downward tool; 0 when its x axis points along world -x."""
    return math.atan2(-rot[1, 0], -rot[0, 0])


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


class MoveToServer:
    """Moves the tool to a Cartesian pose or a named waypoint."""

    def __init__(self, world: World, name: str = MOVE_TO, bus=None, start: bool = True):
        self.world = world
        self.name = name
        self.ik = IKSolver(world.model, "tcp", ARM_JOINTS)
        self.waypoints: dict[str, np.ndarray | dict] = {
            "home": HOME_Q.copy(),
            "above_target": {
                "x": float(world.target_pos[0]),
                "y": float(world.target_pos[1]),
                "z": float(world.target_pos[2]) + 0.15,
                "yaw": 0.0,
            },
        }
        self.server = None
        if start:
            from fsm.ros.actionlib import SimpleActionServer

            self.server = SimpleActionServer(name, self._execute, auto_start=True, bus=bus)

    def _execute(self, goal: Any) -> None:
        self.run(goal, self.server)

    # -------------------------------------------------------------- planning
    def plan(self, goal: Any) -> tuple[np.ndarray, float, np.ndarray] | str:
        """Joint waypoints, duration and goal tool position; or the reason it can't."""
        w = self.world
        q_now = w.arm_q()
        p_now, r_now = self.ik.forward(q_now)
        name = _get(goal, "waypoint")
        pose = _get(goal, "pose")
        if name is not None:
            wp = self.waypoints.get(str(name))
            if wp is None:
                return f"unknown waypoint {name!r}"
            if isinstance(wp, np.ndarray):
                q_goal = wp
                p_goal, _ = self.ik.forward(q_goal)
                joint_len = float(np.max(np.abs(q_goal - q_now)))
                duration = max(MIN_DURATION, joint_len / MAX_JOINT_SPEED)
                return np.array([q_now, q_goal]), self._duration(goal, duration), p_goal
            pose = wp
        if pose is None:
            return "goal has neither 'pose' nor 'waypoint'"
        p_goal, yaw_goal = _pose_of(pose)
        yaw_now = tool_yaw(r_now)
        # a two-finger gripper is symmetric under a half turn: take the nearer yaw
        yaw_goal = yaw_now + _wrap(yaw_goal - yaw_now)
        if abs(_wrap(yaw_goal + math.pi - yaw_now)) < abs(yaw_goal - yaw_now):
            yaw_goal = yaw_now + _wrap(yaw_goal + math.pi - yaw_now)
        dist = float(np.linalg.norm(p_goal - p_now))
        k = max(1, math.ceil(dist / WAYPOINT_STEP))
        qs = [q_now]
        q = q_now
        for i in range(1, k + 1):
            f = i / k
            p = p_now + (p_goal - p_now) * f
            yaw = yaw_now + (yaw_goal - yaw_now) * f
            q_next = self.ik.solve_robust(q, p, tool_down_rotation(yaw), seeds=(HOME_Q,))
            if q_next is None:
                return "no IK solution"
            qs.append(q_next)
            q = q_next
        qs = np.array(qs)
        joint_len = float(np.max(np.sum(np.abs(np.diff(qs, axis=0)), axis=0)))
        duration = max(MIN_DURATION, joint_len / MAX_JOINT_SPEED, dist / MAX_LIN_SPEED)
        return qs, self._duration(goal, duration), p_goal

    @staticmethod
    def _duration(goal: Any, planned: float) -> float:
        d = _get(goal, "duration")
        return float(d) if d else planned

    # -------------------------------------------------------------- execution
    def run(self, goal: Any, handle: Any) -> str:
        w = self.world
        planned = self.plan(goal)
        if isinstance(planned, str):
            handle.set_aborted({"position": w.tcp_pos().tolist(), "distance": None}, planned)
            return "aborted"
        qs, duration, p_goal = planned
        check_held = bool(_get(goal, "check_held", False))
        timeout = float(_get(goal, "timeout", 3.0) or 3.0)
        path = w.follow(qs, duration)
        t_end = path.end_time()
        next_fb = 0.0
        lost = 0
        try:
            while True:
                if handle.is_preempt_requested():
                    w.hold()
                    handle.set_preempted(self._result(p_goal), "preempted")
                    return "preempted"
                t = w.time
                dist = float(np.linalg.norm(w.tcp_pos() - p_goal))
                if t >= next_fb:
                    handle.publish_feedback({"distance": dist})
                    next_fb = t + FEEDBACK_EVERY
                if check_held:
                    lost = 0 if w.object_held() else lost + 1
                    if lost >= 3:
                        w.hold()
                        handle.set_aborted(self._result(p_goal), "object lost")
                        return "aborted"
                if t >= t_end:
                    speed = float(np.max(np.abs(w.arm_qvel())))
                    if dist < REACHED_TOL and speed < SETTLE_SPEED:
                        handle.set_succeeded(self._result(p_goal))
                        return "succeeded"
                    if t >= t_end + timeout:
                        w.hold()
                        handle.set_aborted(self._result(p_goal), "timeout")
                        return "aborted"
                w.sleep(POLL)
        except WorldStopped:
            handle.set_aborted(self._result(p_goal), "world stopped")
            return "aborted"

    def _result(self, p_goal: np.ndarray) -> dict:
        p = self.world.tcp_pos()
        return {"position": p.tolist(), "distance": float(np.linalg.norm(p - p_goal))}


class GripperServer:
    """Opens or closes the fingers; reports whether the cube is held."""

    def __init__(self, world: World, name: str = GRIPPER, bus=None, start: bool = True):
        self.world = world
        self.name = name
        self.server = None
        if start:
            from fsm.ros.actionlib import SimpleActionServer

            self.server = SimpleActionServer(name, self._execute, auto_start=True, bus=bus)

    def _execute(self, goal: Any) -> None:
        self.run(goal, self.server)

    def _result(self) -> dict:
        w = self.world
        return {"held": w.object_held(), "opening": float(np.mean(w.finger_q()))}

    def run(self, goal: Any, handle: Any) -> str:
        w = self.world
        command = str(_get(goal, "command", "") or "").lower()
        if command not in ("open", "close", "verify"):
            handle.set_aborted(self._result(), f"unknown gripper command {command!r}")
            return "aborted"
        try:
            if command == "verify":
                w.sleep(0.05)
                handle.publish_feedback({"distance": 0.0})
                handle.set_succeeded(self._result())
                return "succeeded"
            target = FINGER_OPEN if command == "open" else FINGER_CLOSED
            w.set_gripper(target)
            t0 = w.time
            still = 0
            prev = w.finger_q()
            next_fb = 0.0
            while True:
                if handle.is_preempt_requested():
                    if command == "open":  # stop where the fingers are
                        w.set_gripper(float(np.mean(w.finger_q())))
                    # when closing keep squeezing: never drop what may be held
                    handle.set_preempted(self._result(), "preempted")
                    return "preempted"
                w.sleep(POLL)
                fq = w.finger_q()
                dist = float(np.max(np.abs(fq - target)))
                t = w.time
                if t >= next_fb:
                    handle.publish_feedback({"distance": dist})
                    next_fb = t + FEEDBACK_EVERY
                moving = float(np.max(np.abs(fq - prev))) / POLL
                prev = fq
                still = still + 1 if moving < 0.005 else 0
                if command == "open" and dist < 0.002:
                    handle.set_succeeded(self._result())
                    return "succeeded"
                if command == "close" and still >= 10 and t - t0 > 0.15:
                    handle.set_succeeded(self._result())
                    return "succeeded"
                if t - t0 > 2.0:
                    if command == "close":  # fingers stuck but squeezing: report as is
                        handle.set_succeeded(self._result())
                        return "succeeded"
                    handle.set_aborted(self._result(), "timeout")
                    return "aborted"
        except WorldStopped:
            handle.set_aborted(self._result(), "world stopped")
            return "aborted"


def start_servers(world: World, bus=None) -> tuple[MoveToServer, GripperServer]:
    """Start both action servers on ``bus`` (the default bus when None)."""
    return MoveToServer(world, bus=bus), GripperServer(world, bus=bus)
