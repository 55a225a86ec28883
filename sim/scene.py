"""The 3D view: the MuJoCo world drawn in viser, live at 30 Hz, or a recorded pose.

The bridge is the maintained ``mjviser`` package (``ViserMujocoScene``): it builds
the viser scene once from the model's geoms (batched per body group) and updates
every body pose in one ``server.atomic()`` + ``flush()``. Live, we feed it copies of
``xpos``/``xmat`` taken under the world's lock, so drawing never holds up physics
for longer than a copy. A text label above the table shows the task machine's
current state (``world.label``).

``show_pose(fields)`` draws a pose event's fields instead (the instant a dashboard looks
back at): forward kinematics only (``mj_kinematics`` on the scene's own ``MjData``), no
physics. A scene with no world (``start_pose_scene``) only ever draws given poses, so a
recorded demo log replays with the arm and without the simulation.

viser runs its own server thread and event loop; it is bound to 127.0.0.1 here
(its default is 0.0.0.0) and may move to the next free port: read ``.port``.
"""

from __future__ import annotations

import contextlib
import io
import socket
import threading

import mujoco
import numpy as np

from .pose import DEFAULT_RATE, PoseFields, PoseLayout, tick_at
from .world import World, model_path

POSE_LABEL = "recorded pose"


def _free_port(host: str) -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


class Scene:
    """A viser server showing ``world`` (None: only poses given to :meth:`show_pose`); call
    :meth:`stop` to free the port and thread."""

    def __init__(self, world: World | None, host: str = "127.0.0.1", port: int = 0,
                 rate: float = DEFAULT_RATE, always: bool = False):
        import viser
        from mjviser import ViserMujocoScene

        self.world = world
        self.rate = rate
        self.always = always  # update even with no browser connected (e.g. to record)
        self.frames = 0
        # viser prints a banner with rich whatever ``verbose`` says; our caller prints the
        # URL itself. (redirect_stdout is process-wide, but only for the constructor.)
        with contextlib.redirect_stdout(io.StringIO()):
            self.server = viser.ViserServer(host=host, port=port or _free_port(host), verbose=False)
        self.port = self.server.get_port()
        self.host = host
        # mjviser writes visual scales into the model it is given: never the world's
        self.model = mujoco.MjModel.from_xml_path(model_path())
        self.layout = PoseLayout(self.model)
        self._kinematics = mujoco.MjData(self.model)
        self.bridge = ViserMujocoScene(self.server, self.model, num_envs=1)
        self.bridge.camera_tracking_enabled = False  # keep the world frame fixed
        self.server.scene.set_up_direction("+z")
        self.server.initial_camera.position = (1.1, -0.85, 1.0)
        self.server.initial_camera.look_at = (0.3, 0.0, 0.5)
        self._label_text: str | None = None
        self.label = self.server.scene.add_label(
            "/state_label", text="", position=(0.25, 0.0, 1.05), font_screen_scale=1.4,
            anchor="bottom-center")
        self._gui_state = self.server.gui.add_markdown("**state:** -")
        self._lock = threading.Lock()  # one drawer at a time: the live loop or show_pose
        self._showing_pose = False
        self._last_time = -1.0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        if world is None:
            with self._lock:
                self._draw_qpos(self.layout.qpos0, POSE_LABEL)
            return
        self._draw(force=True)
        self._thread = threading.Thread(target=tick_at, args=(rate, self._stop, self._tick),
                                        name="sim-scene", daemon=True)
        self._thread.start()

    @property
    def url(self) -> str:
        return f"http://{self.host}:{self.port}/"

    def show_pose(self, pose: PoseFields | None) -> None:
        """Draw ``pose`` (a pose event's fields) instead of the live world; None: back to live
        (a scene with no world keeps the pose it shows). Raises ValueError for a joint or body the
        model does not have."""
        if pose is None:
            with self._lock:
                self._showing_pose = False
                self._last_time = -1.0  # the next tick redraws the live world even if physics is idle
            return
        qpos = self.layout.qpos(pose)
        with self._lock:
            self._showing_pose = True
            self._draw_qpos(qpos, POSE_LABEL)

    def drawn_positions(self) -> dict[str, np.ndarray]:
        """Where viser was last told each moving body is, by body name: what a browser shows."""
        name = self.model.body
        with self._lock:
            return {name(int(b)).name: np.array(p) for group in self.bridge._mesh_groups if group.mocap_ids is None
                    for b, p in zip(group.body_ids, group.handle.batched_positions)}

    def _set_label(self, text: str) -> None:
        if text != self._label_text:
            self._label_text = text
            self.label.text = text
            self._gui_state.content = f"**state:** {text}"

    def _draw_qpos(self, qpos: np.ndarray, label: str) -> None:
        """Draw the bodies where ``qpos`` puts them (the caller holds ``_lock``)."""
        d = self._kinematics
        d.qpos[:] = qpos
        mujoco.mj_kinematics(self.model, d)
        self._set_label(label)
        self.bridge.update_from_arrays(d.xpos.copy()[None], d.xmat.reshape(-1, 3, 3).copy()[None])
        self.frames += 1

    def _draw(self, force: bool = False) -> None:
        w = self.world
        with self._lock:
            if self._showing_pose:
                return
            self._set_label(w.label or "-")
            with w.lock:
                t = w.data.time
                if not force and t == self._last_time:
                    return
                xpos = w.data.xpos.copy()
                xmat = w.data.xmat.copy()
            self._last_time = t
            self.bridge.update_from_arrays(xpos[None], xmat.reshape(-1, 3, 3)[None])
            self.frames += 1

    def _tick(self) -> None:
        if self.always or self.server.get_clients():
            try:
                self._draw()
            except Exception:  # a vanished client must not end the view
                pass

    def stop(self) -> None:
        self._stop.set()
        t = self._thread
        if t is not None and t.is_alive() and t is not threading.current_thread():
            t.join(timeout=2.0)
        self.server.stop()


def start_scene(world: World, host: str = "127.0.0.1", port: int = 0,
                rate: float = DEFAULT_RATE, always: bool = False) -> Scene:
    """Start the 3D view of ``world``; returns the Scene (``.port``, ``.url``, ``.stop()``)."""
    return Scene(world, host=host, port=port, rate=rate, always=always)


def start_pose_scene(pose: PoseFields | None = None, host: str = "127.0.0.1", port: int = 0) -> Scene:
    """Start a 3D view with no simulation that draws only the poses given to its ``show_pose``
    (first ``pose``, else the model's initial pose): for replaying a recorded demo log."""
    scene = Scene(None, host=host, port=port)
    if pose is not None:
        try:
            scene.show_pose(pose)
        except ValueError:
            scene.stop()
            raise
    return scene


__all__ = ["Scene", "start_scene", "start_pose_scene", "DEFAULT_RATE"]
