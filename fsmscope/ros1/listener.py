"""The node's TCPROS port: a listening socket whose every connection is handed, in a thread of its
own, to the node (which reads its header and finds the publication it asks for)."""

from __future__ import annotations

import socket
import threading
from typing import Callable


class Listener:
    """Listens on ``host`` (a free port: ``port``); ``handle(connection)`` for each connection."""

    def __init__(self, host: str, handle: Callable[[socket.socket], None]) -> None:
        self._handle = handle
        self._sock = socket.create_server((host, 0))
        self.port: int = self._sock.getsockname()[1]
        self._closed = False
        threading.Thread(target=self._accept, daemon=True, name="ros1 tcpros :%d" % self.port).start()

    def _accept(self) -> None:
        while True:
            try:
                connection, _ = self._sock.accept()
            except OSError:
                if self._closed:
                    return
                continue
            threading.Thread(target=self._handle, args=(connection,), daemon=True,
                             name="ros1 tcpros connection").start()

    def close(self) -> None:
        self._closed = True
        try:
            self._sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self._sock.close()
