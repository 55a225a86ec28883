"""The live 3D view: the MuJoCo world drawn in viser, updated at 30 Hz.

The bridge is the maintained ``mjviser`` package (``ViserMujocoScene``): it builds
the viser scene once from the model's geoms (batched per body group) and updates
every body pose in one ``server.atomic()`` + ``flush()``. We feed it copies of
``xpos``/``xmat`` taken under the world's lock, so drawing never holds up physics
for longer than a copy. A text label above the table shows the task machine's
current state (``world.label``).

viser runs its own server thread and event loop; it is bound to 127.0.0.1 here
(its default is 0.0.0.0) and may move to the next free port: read ``.port``.
"""

from __future__ import annotations

import contextlib
import io
import socket
import threading
import time

from .world import World

DEFAULT_RATE = 30.0


def _free_port(host: str) -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


class Scene:
    """A viser server showing ``world``; call :meth:`stop` to free the port and thread."""

    def __init__(self, world: World, host: str = "127.0.0.1", port: int = 0,
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
        # mjviser writes visual scales into the model it is given: give it a copy
        import mujoco

        model = mujoco.MjModel.from_xml_path(world_model_path())
        self.bridge = ViserMujocoScene(self.server, model, num_envs=1)
        self.bridge.camera_tracking_enabled = False  # keep the world frame fixed
        self.server.scene.set_up_direction("+z")
        self.server.initial_camera.position = (1.1, -0.85, 1.0)
        self.server.initial_camera.look_at = (0.3, 0.0, 0.5)
        self._label_text = None
        self.label = self.server.scene.add_label(
            "/state_label", text="", position=(0.25, 0.0, 1.05), font_screen_scale=1.4,
            anchor="bottom-center")
        self._gui_state = self.server.gui.add_markdown("**state:** -")
        self._last_time = -1.0
        self._stop = threading.Event()
        self._draw(force=True)
        self._thread = threading.Thread(target=self._run, name="sim-scene", daemon=True)
        self._thread.start()

    @property
    def url(self) -> str:
        return f"http://{self.host}:{self.port}/"

    def _draw(self, force: bool = False) -> None:
        w = self.world
        text = w.label or "-"
        if text != self._label_text:
            self._label_text = text
            self.label.text = text
            self._gui_state.content = f"**state:** {text}"
        with w.lock:
            t = w.data.time
            if not force and t == self._last_time:
                return
            xpos = w.data.xpos.copy()
            xmat = w.data.xmat.copy()
        self._last_time = t
        self.bridge.update_from_arrays(xpos[None], xmat.reshape(-1, 3, 3)[None])
        self.frames += 1

    def _run(self) -> None:
        period = 1.0 / self.rate
        next_t = time.perf_counter()
        while not self._stop.is_set():
            if self.always or self.server.get_clients():
                try:
                    self._draw()
                except Exception:  # a vanished client must not end the view
                    if self._stop.is_set():
                        return
            next_t += period
            delay = next_t - time.perf_counter()
            if delay < 0:
                next_t = time.perf_counter()
                delay = 0.0
            self._stop.wait(delay)

    def stop(self) -> None:
        self._stop.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)
        self.server.stop()


def world_model_path() -> str:
    from .world import model_path

    return model_path()


def start_scene(world: World, host: str = "127.0.0.1", port: int = 0,
                rate: float = DEFAULT_RATE, always: bool = False) -> Scene:
    """Start the 3D view of ``world``; returns the Scene (``.port``, ``.url``, ``.stop()``)."""
    return Scene(world, host=host, port=port, rate=rate, always=always)


__all__ = ["Scene", "start_scene", "DEFAULT_RATE"]
