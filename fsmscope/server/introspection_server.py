"""Serve the dashboard from inside a program, the smach_ros way.

    sis = IntrospectionServer("server_name", sm, "/SM_ROOT")
    sis.start()          # a web server in a background thread, attached to sm
    print(sis.url)       # http://127.0.0.1:PORT/?token=...
    outcome = sm.execute()
    sis.stop()
"""

from __future__ import annotations

from typing import Any

from .http_server import ServerThread


class IntrospectionServer:
    """smach_ros.IntrospectionServer's call shape: ``(name, machine, path)``, then ``start()`` and ``stop()``."""

    def __init__(self, name: str, machine: Any, path: str = "/SM_ROOT", host: str = "127.0.0.1", port: int = 0,
                 token: str | None = None, can_start: bool = True, starter: Any = None) -> None:
        self.name = name
        self.machine = machine
        self.path = path
        self._server = ServerThread(host=host, port=port, token=token)
        self.hub = self._server.hub
        self.entry = self.hub.add_local(machine, name=name, path=path, can_start=can_start, starter=starter)
        self._started = False

    @property
    def url(self) -> str:
        return self._server.url

    @property
    def port(self) -> int:
        return self._server.port

    @property
    def token(self) -> str | None:
        return self._server.token

    def start(self) -> IntrospectionServer:
        if not self._started:
            self._server.start()
            self._started = True
        return self

    def stop(self) -> None:
        if self._started:
            self._started = False
            self._server.stop()
        self.hub.remove(self.entry.name)

    def __enter__(self) -> IntrospectionServer:
        return self.start()

    def __exit__(self, *exc: Any) -> None:
        self.stop()
