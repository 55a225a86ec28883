"""The arm's pose as the fields of a schema ``pose`` event, sampled from a World, and back.

``PoseTap`` samples the world at the rate the 3D view draws (30 Hz of wall time) in its own thread
and hands each pose that differs from the last one it sent to a callback: the demo's composition
root passes the task machine's reporter, so the poses go into the machine's own event stream (the
same seq clock as its transitions), its recording and the dashboard. An arm holding still costs
one copy of a few numbers per tick and no event.

Values are rounded to 10 micrometres / microradians: far below what the view can show, it keeps
the log small and makes "holding still" exact despite the solver's last-digit noise.

``pose_qpos`` is the inverse: the MuJoCo ``qpos`` a pose describes, so a scene can draw a
recorded pose with forward kinematics and no physics (fsmscope/sim/scene.py).
"""

from __future__ import annotations

import sys
import threading
import time
import traceback
from typing import TYPE_CHECKING, Any, Callable

import mujoco
import numpy as np

from fsm.observation import schema

if TYPE_CHECKING:
    from .world import World

DEFAULT_RATE = 30.0  # Hz of wall time: what the 3D view draws, and what the tap records
DECIMALS = 5

#: a pose's fields: {"joints": {name: position}, "bodies": {name: [x, y, z, qw, qx, qy, qz]}}
PoseFields = dict


class PoseLayout:
    """Where each field of a pose lives in a model's ``qpos``: its one-coordinate joints (hinge
    and slide: the arm's and the fingers') by joint name, its free bodies (the cube) by body name."""

    def __init__(self, model: mujoco.MjModel) -> None:
        kinds = [int(t) for t in model.jnt_type]
        one = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
        free = int(mujoco.mjtJoint.mjJNT_FREE)
        self.joints = {model.joint(j).name: int(model.jnt_qposadr[j]) for j in range(model.njnt) if kinds[j] in one}
        self.bodies = {model.body(int(model.jnt_bodyid[j])).name: int(model.jnt_qposadr[j])
                       for j in range(model.njnt) if kinds[j] == free}
        self.qpos0 = model.qpos0.copy()
        self.index = np.array(list(self.joints.values())
                              + [a + k for a in self.bodies.values() for k in range(7)], dtype=int)

    def sample(self, qpos: np.ndarray) -> np.ndarray:
        """The pose's numbers in ``qpos``, rounded (and no -0.0): what is compared and sent."""
        return np.round(qpos[self.index], DECIMALS) + 0.0

    def fields(self, values: np.ndarray) -> PoseFields:
        """A sample as a pose event's fields (made by the schema's ``fields_of.pose``)."""
        numbers = values.tolist()
        n = len(self.joints)
        joints = dict(zip(self.joints, numbers[:n]))
        bodies = {name: numbers[n + 7 * i: n + 7 * i + 7] for i, name in enumerate(self.bodies)}
        return schema.fields_of.pose(joints, bodies or schema.ABSENT)

    def qpos(self, pose: PoseFields) -> np.ndarray:
        """The ``qpos`` a pose describes; what it leaves out keeps the model's initial value.
        Raises ValueError for a joint or body this model does not have."""
        qpos = self.qpos0.copy()
        for name, value in pose.get("joints", {}).items():
            if name not in self.joints:
                raise ValueError("the model has no joint %r (it has %s)" % (name[:50], ", ".join(self.joints)))
            qpos[self.joints[name]] = value
        for name, value in (pose.get("bodies") or {}).items():
            if name not in self.bodies:
                raise ValueError("the model has no free body %r (it has %s)"
                                 % (name[:50], ", ".join(self.bodies) or "none"))
            a = self.bodies[name]
            qpos[a: a + 7] = value
        return qpos


def pose_qpos(model: mujoco.MjModel, pose: PoseFields) -> np.ndarray:
    """The MuJoCo ``qpos`` of ``model`` that a pose event's fields describe (see PoseLayout.qpos)."""
    return PoseLayout(model).qpos(pose)


def tick_at(rate: float, stop: threading.Event, tick: Callable[[], Any]) -> None:
    """Call ``tick`` ``rate`` times a second of wall time until ``stop`` is set; a late tick
    moves the schedule instead of catching up."""
    period = 1.0 / rate
    next_t = time.perf_counter()
    while not stop.is_set():
        tick()
        next_t += period
        delay = next_t - time.perf_counter()
        if delay < 0:
            next_t = time.perf_counter()
            delay = 0.0
        stop.wait(delay)


class PoseTap:
    """Samples ``world``'s pose ``rate`` times a second in its own thread and calls ``send(fields)``
    with each pose that differs from the last one sent. ``send`` may return False to decline a
    pose (it is offered again at the next tick); any other answer counts as sent."""

    def __init__(self, world: World, send: Callable[[PoseFields], Any], rate: float = DEFAULT_RATE) -> None:
        self.world = world
        self.send = send
        self.rate = rate
        self.layout = PoseLayout(world.model)
        self.sent = 0
        self._last: np.ndarray | None = None
        self._failed = False
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def poll(self) -> bool:
        """Take one sample; send it when it differs from the last pose sent. True when it was sent."""
        with self.world.lock:
            values = self.layout.sample(self.world.data.qpos)
        if self._last is not None and np.array_equal(values, self._last):
            return False
        if self.send(self.layout.fields(values)) is False:
            return False
        self._last = values
        self.sent += 1
        return True

    def _tick(self) -> None:
        try:
            self.poll()
        except Exception:  # a failing receiver must not end the recording of later poses; said once
            if not self._failed:
                self._failed = True
                sys.stderr.write("sim: the pose tap's receiver failed:\n" + traceback.format_exc())

    def start(self) -> PoseTap:
        if self._thread is None:
            self._thread = threading.Thread(target=tick_at, args=(self.rate, self._stop, self._tick),
                                            name="sim-pose", daemon=True)
            self._thread.start()
        return self

    def stop(self) -> None:
        """Stop sampling; returns once the thread is done (no pose is sent after this)."""
        self._stop.set()
        t = self._thread
        if t is not None and t is not threading.current_thread():
            t.join(timeout=2.0)


__all__ = ["DEFAULT_RATE", "PoseLayout", "PoseTap", "pose_qpos", "tick_at"]


class PoseFrames:
    """Every body of the model where a recorded pose puts it, by forward kinematics (no physics):
    ``(parent frame, body, [x, y, z], [qw, qx, qy, qz])`` with each body a frame of "world", as a
    tool that draws frames wants them (Foxglove's 3D panel, through ``fsmscope export --mcap``)."""

    def __init__(self) -> None:
        from .world import load_model

        self.model = load_model()
        self.layout = PoseLayout(self.model)
        self.data = mujoco.MjData(self.model)

    def __call__(self, pose: PoseFields) -> list[tuple[str, str, list[float], list[float]]]:
        """Raises ValueError for a joint or body this model does not have (a pose of another robot)."""
        self.data.qpos[:] = self.layout.qpos(pose)
        mujoco.mj_kinematics(self.model, self.data)
        return [("world", self.model.body(b).name, np.round(self.data.xpos[b], DECIMALS).tolist(),
                 np.round(self.data.xquat[b], DECIMALS).tolist()) for b in range(1, self.model.nbody)]
