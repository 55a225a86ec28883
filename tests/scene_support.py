"""A page's frame of the 3D view without a browser: a real viser websocket client, connected with a
view id the way fsmscope/static/scene.js makes viser's page connect (ws://HOST:PORT/view/ID)."""

from __future__ import annotations

import secrets
import threading

import msgspec
import viser
from fsmscope.server.testing.polling import wait_for
from websockets.sync.client import connect

# What viser's page sends first: its camera. viser counts a client as connected from that message on.
_CAMERA = {"type": "ViewerCameraMessage", "wxyz": [1.0, 0.0, 0.0, 0.0], "position": [1.1, -0.85, 1.0],
           "fov": 1.0, "near": 0.01, "far": 100.0, "image_height": 900, "image_width": 700,
           "look_at": [0.3, 0.0, 0.5], "up_direction": [0.0, 0.0, 1.0]}


class ViewClient:
    """One viser client of ``scene`` (a sim.scene.Scene) belonging to page view ``view`` (a fresh
    random id when None): ``.id`` is its viser client id once connected; it reads (and drops) what
    viser sends it until ``close()``."""

    def __init__(self, scene, view: str | None = None) -> None:
        self.view = view or secrets.token_hex(16)
        known = set(scene.clients())
        self._ws = connect("ws://127.0.0.1:%d/view/%s" % (scene.port, self.view),
                           subprotocols=["viser-v" + viser.__version__], max_size=None)
        self._reader = threading.Thread(target=self._drain, daemon=True)
        self._reader.start()
        self._ws.send(msgspec.msgpack.encode(_CAMERA))
        self.id = wait_for(lambda: [c for c, v in scene.clients().items() if c not in known and v == self.view],
                           timeout=10, what="viser to count the view's client as connected")[0]

    def _drain(self) -> None:
        try:
            for _ in self._ws:
                pass
        except Exception:  # closed
            pass

    def close(self) -> None:
        self._ws.close()
        self._reader.join(5)
