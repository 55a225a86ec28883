"""Clients that misbehave on purpose, to measure and test how the server copes with them."""

from __future__ import annotations

import socket
from typing import Any


def stalled_stream(srv: Any, name: str) -> socket.socket:
    """A websocket to ``name``'s stream on ``srv`` (a ServerThread) that completes the handshake and
    then never reads: a stalled browser. Its small receive buffer fills after a few frames."""
    raw = socket.create_connection(("127.0.0.1", srv.port))
    raw.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    raw.sendall(("GET /api/machines/%s/stream?token=%s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: websocket\r\n"
                 "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                 "Sec-WebSocket-Version: 13\r\n\r\n" % (name, srv.token, srv.port)).encode())
    answer = raw.recv(200)
    if b"101" not in answer:
        raw.close()
        raise ConnectionError("the stream refused the websocket: %r" % answer)
    return raw
