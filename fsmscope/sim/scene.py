"""The 3D view: the MuJoCo world drawn in viser, live at 30 Hz, and each page's recorded pose.

The bridge is the maintained ``mjviser`` package (``ViserMujocoScene``): it builds
the viser scene once from the model's geoms (batched per body group) and updates
every body pose in one ``server.atomic()`` + ``flush()``. Live, we feed it copies of
``xpos``/``xmat`` taken under the world's lock, so drawing never holds up physics
for longer than a copy. A text label above the table shows the task machine's
current state (``world.label``). These shared nodes are what every viser client sees.

Looking back is a page's own business. A dashboard page embeds viser's page with a random view
id of its own in the websocket's address (``ws://HOST:PORT/view/<id>``, fsmscope/static/scene.js), so each
viser client is known by the page it belongs to. ``show_pose(view, fields)`` draws a pose event's
fields (the instant that page looks back at) for that view's clients only: each gets its own copy
of the arm's moving nodes, under the shared nodes' names, which viser shows to that client instead
of the shared ones (a client-scoped node shadows the server's of the same name), posed by forward
kinematics (``mj_kinematics`` on the scene's own ``MjData``), no physics. The copies reuse the shared
nodes' GLB bytes (about 190 kB sent once, nothing rebuilt); a scrub step then sends that one client
a few small pose updates, while the live arm stays one broadcast. ``show_pose(view, None)`` removes
the copies: the client sees the shared arm, live, again. A client that goes away takes its copies
with it, so a page that closes while looking back leaves every other view as it was.

A scene with no world (``start_pose_scene``) draws one given pose as its shared arm (a replay's last
pose), and each page's own pose over it, so every page scrubs a recorded demo log independently.

viser runs its own server thread and event loop; it is bound to 127.0.0.1 here
(its default is 0.0.0.0) and may move to the next free port: read ``.port``.
"""

from __future__ import annotations

import contextlib
import io
import socket
import threading
from collections import OrderedDict
from typing import Any

import mujoco
import numpy as np
import viser.transforms as vtf

from .pose import DEFAULT_RATE, PoseFields, PoseLayout, tick_at
from .world import World, model_path

POSE_LABEL = "recorded pose"
LABEL = "/state_label"  # the state's words above the table (a page looking back: POSE_LABEL)
_LABEL_PLACE: dict[str, Any] = dict(position=(0.25, 0.0, 1.05), font_screen_scale=1.4, anchor="bottom-center")
VIEW_PATH = "/view/"  # a page's viser client connects to ws://HOST:PORT/view/<its view id>
REMEMBERED_VIEWS = 64  # the poses of this many views are kept for a client that (re)connects late


def _free_port(host: str) -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def _state_text(text: str) -> str:
    return f"**state:** {text}"


def _view_of(server: Any, client_id: int) -> str | None:
    """The view id a viser client connected with (its websocket's path, ``/view/<id>``); None for
    viser's page opened on its own. viser gives a client handle no public access to its request:
    its websocket server keeps each live connection (viser 1.1, tests/server/test_sim_pose.py)."""
    connection = server._websock_server._live_connections.get(client_id)
    path = getattr(getattr(connection, "request", None), "path", "").partition("?")[0]
    return (path[len(VIEW_PATH):] or None) if path.startswith(VIEW_PATH) else None


class _Client:
    """One viser client: the page's view it belongs to, its state line, and while its page looks
    back, its own copy of the arm (the client-scoped nodes, by the shared nodes' names)."""

    def __init__(self, handle: Any, view: str | None, state: str) -> None:
        self.handle = handle
        self.view = view
        self.state = handle.gui.add_markdown(state)
        self.copies: dict[str, Any] = {}


class Scene:
    """A viser server showing ``world`` (None: ``pose``, else the model's initial pose) to every client,
    and to the clients of a page looking back the pose that page gives :meth:`show_pose`; call
    :meth:`stop` to free the port and thread."""

    def __init__(self, world: World | None, host: str = "127.0.0.1", port: int = 0,
                 rate: float = DEFAULT_RATE, always: bool = False, pose: PoseFields | None = None):
        import viser
        from mjviser import ViserMujocoScene

        # mjviser writes visual scales into the model it is given: never the world's
        self.model = mujoco.MjModel.from_xml_path(model_path())
        self.layout = PoseLayout(self.model)
        shown = self.layout.qpos0 if pose is None else self.layout.qpos(pose)  # first: a ValueError starts nothing
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
        self._kinematics = mujoco.MjData(self.model)
        self.bridge = ViserMujocoScene(self.server, self.model, num_envs=1)
        self.bridge.camera_tracking_enabled = False  # keep the world frame fixed
        # the nodes a pose moves, each with the bodies its batch draws: what a page's copy holds
        self._moving = [(g.handle, g.body_ids) for g in self.bridge._mesh_groups if g.mocap_ids is None] + \
            [(h, np.array([body])) for (body, _), h in self.bridge.site_handles_by_group.items()]
        self.server.scene.set_up_direction("+z")
        self.server.initial_camera.position = (1.1, -0.85, 1.0)
        self.server.initial_camera.look_at = (0.3, 0.0, 0.5)
        self._label_text = "-"
        self.label = self.server.scene.add_label(LABEL, text=self._label_text, **_LABEL_PLACE)
        self._lock = threading.Lock()  # one drawer at a time: the live loop, show_pose, a client arriving
        self._clients: dict[int, _Client] = {}
        self._poses: OrderedDict[str, np.ndarray] = OrderedDict()  # view id: the qpos its page looks back at
        self._last_time = -1.0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.server.on_client_connect(self._connected)
        self.server.on_client_disconnect(self._disconnected)
        if world is None:
            with self._lock:
                self._set_label(POSE_LABEL)
                self._draw_shared(shown)
            return
        self._draw(force=True)
        self._thread = threading.Thread(target=tick_at, args=(rate, self._stop, self._tick),
                                        name="sim-scene", daemon=True)
        self._thread.start()

    @property
    def url(self) -> str:
        return f"http://{self.host}:{self.port}/"

    def show_pose(self, view: str, pose: PoseFields | None) -> None:
        """Draw ``pose`` (a pose event's fields) for the viser clients of page view ``view`` only, now
        and when one (re)connects; None: that view shows the shared arm (the live world) again.
        Raises ValueError for a joint or body the model does not have."""
        qpos = None if pose is None else self.layout.qpos(pose)
        with self._lock:
            if qpos is None:
                self._poses.pop(view, None)
            else:
                self._poses[view] = qpos
                self._poses.move_to_end(view)
                while len(self._poses) > REMEMBERED_VIEWS:
                    self._poses.popitem(last=False)
            for client in self._clients.values():
                if client.view == view:
                    self._show(client, qpos)

    def clients(self) -> dict[int, str | None]:
        """The connected viser clients by id, each with the page view it belongs to (None: viser's
        page opened on its own, which always shows the shared arm)."""
        with self._lock:
            return {cid: client.view for cid, client in self._clients.items()}

    def drawn_positions(self, client: int | None = None) -> dict[str, np.ndarray]:
        """Where viser was last told each moving body is, by body name, for viser client ``client``
        (None: the shared arm, what every client sees whose page does not look back): what that
        browser shows."""
        name = self.model.body
        with self._lock:
            copies = {} if client is None else self._clients[client].copies
            return {name(int(b)).name: np.array(p) for shared, bodies in self._moving
                    for b, p in zip(bodies, copies.get(shared.name, shared).batched_positions)}

    def drawn_label(self, client: int | None = None) -> str:
        """The text viser was last told to show above the table to ``client`` (None: every client
        whose page does not look back)."""
        with self._lock:
            copy = None if client is None else self._clients[client].copies.get(LABEL)
            return (copy or self.label).text

    def _connected(self, handle: Any) -> None:
        view = _view_of(self.server, handle.client_id)
        with self._lock:
            if handle.client_id not in self.server.get_clients():
                return  # gone again before this ran: its disconnect has been handled
            client = self._clients[handle.client_id] = _Client(handle, view, _state_text(self._label_text))
            qpos = None if view is None else self._poses.get(view)
            if qpos is not None:
                self._show(client, qpos)

    def _disconnected(self, handle: Any) -> None:
        with self._lock:  # its client-scoped nodes went with its connection
            self._clients.pop(handle.client_id, None)

    def _show(self, client: _Client, qpos: np.ndarray | None) -> None:
        """Show ``client`` its page's pose ``qpos`` over the shared arm (None: the shared arm again);
        the caller holds ``_lock``."""
        if qpos is None:
            for node in client.copies.values():
                node.remove()
            client.copies.clear()
            client.state.content = _state_text(self._label_text)
            return
        d = self._kinematics
        d.qpos[:] = qpos
        mujoco.mj_kinematics(self.model, d)
        wxyz = vtf.SO3.from_matrix(d.xmat.reshape(-1, 3, 3)).wxyz
        scene, copies = client.handle.scene, client.copies
        with client.handle.atomic():
            for shared, bodies in self._moving:
                copy = copies.get(shared.name)
                if copy is None:
                    copies[shared.name] = scene.add_batched_glb(
                        shared.name, shared.glb_data, batched_wxyzs=wxyz[bodies], batched_positions=d.xpos[bodies],
                        lod=shared.lod, cast_shadow=shared.cast_shadow, receive_shadow=shared.receive_shadow,
                        visible=shared.visible)
                else:
                    copy.batched_positions = d.xpos[bodies]
                    copy.batched_wxyzs = wxyz[bodies]
            if LABEL not in copies:
                copies[LABEL] = scene.add_label(LABEL, text=POSE_LABEL, **_LABEL_PLACE)
                client.state.content = _state_text(POSE_LABEL)
        client.handle.flush()
        self.frames += 1

    def _set_label(self, text: str) -> None:
        """The live state's words above the shared arm and on every client's panel whose page does
        not look back (the caller holds ``_lock``)."""
        if text != self._label_text:
            self._label_text = text
            self.label.text = text
            for client in self._clients.values():
                if not client.copies:
                    client.state.content = _state_text(text)

    def _draw_shared(self, qpos: np.ndarray) -> None:
        """Draw the shared arm where ``qpos`` puts it (the caller holds ``_lock``)."""
        d = self._kinematics
        d.qpos[:] = qpos
        mujoco.mj_kinematics(self.model, d)
        self.bridge.update_from_arrays(d.xpos.copy()[None], d.xmat.reshape(-1, 3, 3).copy()[None])
        self.frames += 1

    def _draw(self, force: bool = False) -> None:
        w = self.world
        with self._lock:
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
    """Start a 3D view with no simulation: its shared arm is ``pose`` (else the model's initial pose),
    and each page's view the pose it gives ``show_pose``; for replaying a recorded demo log.
    Raises ValueError for a joint or body the model does not have."""
    return Scene(None, host=host, port=port, pose=pose)


__all__ = ["Scene", "start_scene", "start_pose_scene", "DEFAULT_RATE", "VIEW_PATH"]
