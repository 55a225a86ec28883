"""The dashboard app served by uvicorn in a background thread, on a socket bound before it starts.

What every host of the dashboard shares: the CLI's commands, ``IntrospectionServer`` and the tests
start a ``ServerThread``, then give its hub machines to show.
"""

from __future__ import annotations

import socket
import threading
from typing import Any, Callable

from .auth import check_bind, new_token
from .hub import Hub
from .lease import Deadman
from .read_budget import ReadBudget


def ws_implementation() -> str:
    try:
        import uvicorn.protocols.websockets.websockets_sansio_impl  # noqa: F401
        return "websockets-sansio"
    except Exception:
        return "websockets"


def bind_socket(host: str, port: int) -> socket.socket:
    """The listening socket, made with proto IPPROTO_TCP: asyncio sets TCP_NODELAY on accepted
    sockets only when their proto says TCP. Without it, Nagle's algorithm holds every response
    on a kept-alive connection until the client's delayed ACK (~40 ms)."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM, socket.IPPROTO_TCP)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)  # inherited by accepted sockets on Linux
    sock.bind((host, port))
    sock.listen(128)
    sock.set_inheritable(True)
    return sock


def uvicorn_config(app: Any, log_level: str = "warning") -> Any:
    """uvicorn's configuration of the app; a refused client fills no log (fsmscope/server/middleware.py)."""
    import logging

    import uvicorn

    from .middleware import QUIET_CLIENTS

    config = uvicorn.Config(app, ws=ws_implementation(), ws_per_message_deflate=False, log_level=log_level,
                            lifespan="on", ws_max_size=8 * 1024 * 1024, access_log=False)
    logging.getLogger("uvicorn.error").addFilter(QUIET_CLIENTS)  # after Config, which configures logging
    return config


def display_url(host: str, port: int, token: str | None) -> str:
    shown = "127.0.0.1" if host in ("0.0.0.0", "") else ("[::1]" if host == "::" else host)
    if ":" in shown and not shown.startswith("["):
        shown = "[%s]" % shown
    url = "http://%s:%d/" % (shown, port)
    return url + ("?token=%s" % token if token else "")


class ServerThread:
    """A hub's app served by uvicorn in a background thread on a socket bound before it starts."""

    def __init__(self, hub: Hub | None = None, host: str = "127.0.0.1", port: int = 0, token: str | None = None,
                 log_level: str = "warning", scene_url: str | None = None,
                 show_pose: Callable[[str, dict | None], None] | None = None, viewer_token: str | None = None,
                 deadman: Deadman | None = None, reads: ReadBudget | None = None) -> None:
        from .app import create_app
        import uvicorn

        self.token = new_token() if token is None else token
        self.viewer_token = new_token() if viewer_token is None else viewer_token  # watch only (fsmscope/server/auth.py)
        check_bind(host, self.token)
        self.hub = hub if hub is not None else Hub()
        self.host = host
        self.sock = bind_socket(host, port)
        self.port = self.sock.getsockname()[1]
        self.app = create_app(self.hub, self.token, host=host, port=self.port, scene_url=scene_url,
                              show_pose=show_pose, viewer_token=self.viewer_token if self.token else None,
                              deadman=deadman, reads=reads)
        self.server = uvicorn.Server(uvicorn_config(self.app, log_level))
        self._thread: threading.Thread | None = None

    @property
    def url(self) -> str:
        return display_url(self.host, self.port, self.token)

    @property
    def viewer_url(self) -> str:
        """The dashboard for someone who may watch and not control (no token: the same as ``url``)."""
        return display_url(self.host, self.port, self.viewer_token if self.token else None)

    @property
    def base_url(self) -> str:
        return display_url(self.host, self.port, None).rstrip("/")

    def start(self, timeout: float = 10.0) -> ServerThread:
        self._thread = threading.Thread(target=self.server.run, kwargs={"sockets": [self.sock]},
                                        name="fsmscope-server", daemon=True)
        self._thread.start()
        deadline = threading.Event()
        for _ in range(int(timeout / 0.01)):
            if self.server.started or not self._thread.is_alive():
                break
            deadline.wait(0.01)
        if not self.server.started:
            raise RuntimeError("the fsmscope server did not start")
        return self

    def stop(self, timeout: float = 5.0) -> None:
        self.server.should_exit = True
        if self._thread is not None:
            self._thread.join(timeout)
            if self._thread.is_alive():
                self.server.force_exit = True
                self._thread.join(timeout)
        try:
            self.sock.close()
        except OSError:
            pass
