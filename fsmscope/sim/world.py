"""The simulated world: model loading, seeded episodes, the physics thread.

One ``World`` owns one ``MjModel``/``MjData`` pair and the lock that guards them.
Physics steps in its own thread, either paced to wall-clock time (``speed`` times
real time) or, with ``fast=True`` (``speed`` None), on demand: the thread advances simulated time
only while someone waits in :meth:`World.sleep`, as fast as it can. On-demand
stepping makes an episode deterministic for a given seed: the task machine's
commands land at the same simulated instants whatever the thread scheduling.

The arm follows a :class:`JointPath` evaluated at simulated time inside the physics
thread; :meth:`World.hold` replaces it by the current joint position.

One piece because everything here touches ``MjData`` under the one lock the physics thread
holds: episode set-up, stepping, the arm's path, the gripper and the readings.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from importlib import resources

import mujoco
import numpy as np

from .joint_path import JointPath

ARM_JOINTS = ["j1", "j2", "j3", "j4", "j5", "j6"]
FINGER_JOINTS = ["finger_left", "finger_right"]
#: joint configuration of the safe HOME pose: tool 30 cm in front, 30 cm above the table
HOME_Q = np.array([0.0, 0.0309, 1.8094, 0.0, 1.3013, 0.0])
TABLE_Z = 0.40
CUBE_HALF = 0.02
#: where a cube may be placed at the start of an episode (x, y ranges) and its yaw range
CUBE_REGION = ((0.32, 0.50), (0.05, 0.28))
CUBE_YAW = (-math.pi / 4, math.pi / 4)
FINGER_OPEN = 0.04
FINGER_CLOSED = -0.008


def model_path() -> str:
    """Path of the MJCF model shipped in the package."""
    return str(resources.files("fsmscope.sim").joinpath("arm.xml"))


def load_model() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(model_path())


class WorldStopped(RuntimeError):
    """Raised in a waiter when the world is stopped."""


class World:
    """Model, data, lock and physics thread of the demo world."""

    def __init__(self, seed: int = 0, fast: bool = False, speed: float | None = 1.0):
        self.model = load_model()
        self.data = mujoco.MjData(self.model)
        self.speed = None if fast else speed  # None: on demand (fast mode)
        self._anchor: tuple[float, float] | None = None  # (sim time, wall time) of pacing
        self.label_hooks: list = []  # called with each new label, in the setter's thread
        self.lock = threading.RLock()
        self._cond = threading.Condition(self.lock)
        self._thread: threading.Thread | None = None
        self._stop = False
        self._waiting: list[float] = []  # simulated times waiters wait for (fast mode)
        self._path: JointPath | None = None
        self._label = ""
        self.labels: deque[tuple[float, str]] = deque(maxlen=256)  # (sim time, label) history
        self.steps = 0
        m = self.model
        self.arm_qadr = np.array([m.jnt_qposadr[m.joint(n).id] for n in ARM_JOINTS])
        self.arm_dofadr = np.array([m.jnt_dofadr[m.joint(n).id] for n in ARM_JOINTS])
        self.finger_qadr = np.array([m.jnt_qposadr[m.joint(n).id] for n in FINGER_JOINTS])
        self.arm_act = np.array([m.actuator(f"a{i}").id for i in range(1, 7)])
        self.grip_act = np.array([m.actuator("grip_left").id, m.actuator("grip_right").id])
        cube_j = m.joint("cube").id
        self.cube_qadr = m.jnt_qposadr[cube_j]
        self.cube_dofadr = m.jnt_dofadr[cube_j]
        self.cube_body = m.body("cube").id
        self.cube_geom = m.geom("cube").id
        self.pad_geoms = (m.geom("pad_left").id, m.geom("pad_right").id)
        self.tcp_site = m.site("tcp").id
        self.target_pos = m.body("target").pos.copy()
        self.target_pos[2] = TABLE_Z + CUBE_HALF
        self._cube_mass0 = float(m.body_mass[self.cube_body])
        self._cube_inertia0 = m.body_inertia[self.cube_body].copy()
        self.seed = seed
        self.reset(seed)

    @property
    def label(self) -> str:
        """The task machine's current state, as the scene draws it."""
        return self._label

    @label.setter
    def label(self, text: str) -> None:
        self._label = text
        self.labels.append((float(self.data.time), text))
        for hook in list(self.label_hooks):
            hook(text)

    # ------------------------------------------------------------------ episodes
    def reset(self, seed: int | None = None) -> dict:
        """Reset arm to HOME (gripper open), place the cube at a seeded random pose."""
        if seed is not None:
            self.seed = seed
        rng = np.random.default_rng(self.seed)
        x = rng.uniform(*CUBE_REGION[0])
        y = rng.uniform(*CUBE_REGION[1])
        yaw = rng.uniform(*CUBE_YAW)
        with self.lock:
            m, d = self.model, self.data
            mujoco.mj_resetData(m, d)
            d.qpos[self.arm_qadr] = HOME_Q
            d.ctrl[self.arm_act] = HOME_Q
            d.qpos[self.finger_qadr] = FINGER_OPEN
            d.ctrl[self.grip_act] = FINGER_OPEN
            a = self.cube_qadr
            d.qpos[a : a + 3] = (x, y, TABLE_Z + CUBE_HALF)
            d.qpos[a + 3 : a + 7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
            self._path = None
            mujoco.mj_forward(m, d)
            self._cond.notify_all()
        return self.cube_pose()

    def set_cube_mass(self, mass: float) -> None:
        """Change the cube's mass (inertia scaled with it); used to make a grasp fail."""
        with self.lock:
            scale = mass / self._cube_mass0
            self.model.body_mass[self.cube_body] = mass
            self.model.body_inertia[self.cube_body] = self._cube_inertia0 * scale
            d = self.data
            saved = (d.time, d.qpos.copy(), d.qvel.copy(), d.act.copy(), d.ctrl.copy())
            mujoco.mj_setConst(self.model, d)  # uses d as scratch: restore the state
            d.time, d.qpos[:], d.qvel[:], d.act[:], d.ctrl[:] = saved
            mujoco.mj_forward(self.model, d)

    # ------------------------------------------------------------------ sensing
    @property
    def time(self) -> float:
        return float(self.data.time)

    def cube_pose(self) -> dict:
        """Cube position and yaw (rad) as plain floats."""
        with self.lock:
            a = self.cube_qadr
            p = self.data.qpos[a : a + 3].tolist()
            w, qx, qy, qz = self.data.qpos[a + 3 : a + 7]
        yaw = math.atan2(2 * (w * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
        return {"x": p[0], "y": p[1], "z": p[2], "yaw": yaw}

    def arm_q(self) -> np.ndarray:
        with self.lock:
            return self.data.qpos[self.arm_qadr].copy()

    def arm_qvel(self) -> np.ndarray:
        with self.lock:
            return self.data.qvel[self.arm_dofadr].copy()

    def tcp_pos(self) -> np.ndarray:
        with self.lock:
            return self.data.site_xpos[self.tcp_site].copy()

    def finger_q(self) -> np.ndarray:
        with self.lock:
            return self.data.qpos[self.finger_qadr].copy()

    def pad_contacts(self) -> tuple[bool, bool]:
        """Whether the cube touches the left and the right finger pad."""
        with self.lock:
            d = self.data
            left = right = False
            for i in range(d.ncon):
                c = d.contact[i]
                g = (c.geom1, c.geom2)
                if self.cube_geom in g:
                    if self.pad_geoms[0] in g:
                        left = True
                    elif self.pad_geoms[1] in g:
                        right = True
            return left, right

    def object_held(self) -> bool:
        """The cube is between both pads, touching each, close to the tool point."""
        left, right = self.pad_contacts()
        if not (left and right):
            return False
        with self.lock:
            a = self.cube_qadr
            dist = np.linalg.norm(self.data.qpos[a : a + 3] - self.data.site_xpos[self.tcp_site])
        return bool(dist < 0.04)

    def cube_target_distance(self) -> float:
        """Horizontal distance from the cube's centre to the place target."""
        c = self.cube_pose()
        return math.hypot(c["x"] - self.target_pos[0], c["y"] - self.target_pos[1])

    # ------------------------------------------------------------------ commands
    def follow(self, waypoints: np.ndarray, duration: float) -> JointPath:
        """Start following joint waypoints from now on; returns the path."""
        with self.lock:
            path = JointPath(np.asarray(waypoints, dtype=float), self.time, duration)
            self._path = path
            return path

    def hold(self) -> None:
        """Stop the arm where it is: the set point becomes the current joint position."""
        with self.lock:
            self._path = None
            self.data.ctrl[self.arm_act] = self.data.qpos[self.arm_qadr]

    def set_gripper(self, opening: float) -> None:
        """Finger set point: opening of each finger from the centre line (m)."""
        with self.lock:
            self.data.ctrl[self.grip_act] = opening

    @property
    def path(self) -> JointPath | None:
        return self._path

    # ------------------------------------------------------------------ physics
    def _step_locked(self) -> None:
        path = self._path
        if path is not None:
            self.data.ctrl[self.arm_act] = path.at(self.data.time + self.model.opt.timestep)
        mujoco.mj_step(self.model, self.data)
        self.steps += 1

    def step(self, n: int = 1) -> None:
        """Step the physics ``n`` times in the calling thread (benchmarks, no thread)."""
        with self.lock:
            for _ in range(n):
                self._step_locked()

    def start(self) -> "World":
        if self._thread is not None:
            return self
        self._stop = False
        self._thread = threading.Thread(target=self._run, name="sim-physics", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        with self._cond:
            self._stop = True
            self._cond.notify_all()
        t = self._thread
        if t is not None and t is not threading.current_thread():
            t.join(timeout=5.0)
        self._thread = None

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def set_speed(self, speed: float | None) -> None:
        """Switch pacing at run time: ``speed`` x real time, or None for on demand (fast)."""
        with self._cond:
            self.speed = speed
            self._anchor = None
            self._cond.notify_all()

    @property
    def fast(self) -> bool:
        return self.speed is None

    def _run(self) -> None:
        dt = self.model.opt.timestep
        while True:
            pause = 0.0
            with self._cond:
                if self._stop:
                    return
                if self.speed is None:
                    # on demand: step only up to what the waiters in sleep() need
                    if not self._waiting or self.data.time >= max(self._waiting) - 0.5 * dt:
                        self._cond.wait()  # nobody needs more simulated time
                        continue
                    target = max(self._waiting)
                    first = min(self._waiting)
                    n = 0
                    while self.data.time < target - 0.5 * dt and n < 50:
                        self._step_locked()
                        n += 1
                        if self.data.time >= first - 0.5 * dt:
                            break
                    self._cond.notify_all()
                else:
                    speed = self.speed
                    now = time.perf_counter()
                    # (re-)anchor on start, on a speed change, when reset() rewound time,
                    # and when we fell behind (never try to catch up a backlog)
                    if (self._anchor is None or self.data.time < self._anchor[0]
                            or self._anchor[0] + (now - self._anchor[1]) * speed - self.data.time
                            > 0.25 * speed):
                        self._anchor = (self.data.time, now)
                    sim0, wall0 = self._anchor
                    target = sim0 + (now - wall0) * speed
                    n = 0
                    while self.data.time < target and n < 100:
                        self._step_locked()
                        n += 1
                    if n:
                        self._cond.notify_all()
                    pause = max((self.data.time - target) / speed, 0.0) + min(0.004, 2 * dt / speed)
            # the lock is free here: waiters, servers and the scene get their turn
            if pause:
                time.sleep(pause)

    def sleep(self, duration: float) -> None:
        """Wait until ``duration`` seconds of simulated time have passed.

        In fast mode this is what makes physics advance. Raises WorldStopped when the
        world is stopped meanwhile.
        """
        with self._cond:
            target = self.data.time + duration
            if self._thread is None:
                raise WorldStopped("world is not running")
            self._waiting.append(target)
            try:
                self._cond.notify_all()
                while self.data.time < target - 0.5 * self.model.opt.timestep:
                    if self._stop:
                        raise WorldStopped("world stopped")
                    self._cond.wait(0.5)
            finally:
                self._waiting.remove(target)
