"""TCPROS, ROS 1's topic transport: a connection header, then framed messages.

Both are length-prefixed (4 bytes, little-endian): the header is a block of ``key=value`` fields,
each with its own length; every message after it is its serialized bytes with their length
(http://wiki.ros.org/ROS/TCPROS, http://wiki.ros.org/ROS/Connection%20Header).
"""

from __future__ import annotations

import socket
import struct

from .errors import Ros1Error

# Bigger than any header or message a SMACH robot sends: a wrong length (another protocol on the
# port, a broken peer) is refused rather than allocated.
MAX_HEADER = 1 << 20
MAX_MESSAGE = 1 << 28

_LENGTH = struct.Struct("<I")


class ConnectionClosed(Ros1Error):
    """The peer closed the connection (or it broke) before a whole header or message arrived."""


def encode_header(fields: dict[str, str]) -> bytes:
    """A connection header: its length, then each ``key=value`` field with its own length."""
    encoded = [("%s=%s" % item).encode() for item in fields.items()]
    body = b"".join(_LENGTH.pack(len(field)) + field for field in encoded)
    return _LENGTH.pack(len(body)) + body


def decode_header(body: bytes) -> dict[str, str]:
    """The fields of a header's body (without its own length); a field without ``=`` or whose length
    runs past the end is a Ros1Error."""
    fields: dict[str, str] = {}
    at = 0
    while at < len(body):
        if at + 4 > len(body):
            raise Ros1Error("a connection header ends inside a field's length")
        (size,) = _LENGTH.unpack_from(body, at)
        field = body[at + 4:at + 4 + size]
        if len(field) < size:
            raise Ros1Error("a connection header's field runs past its end")
        key, equals, value = field.decode("utf-8", "replace").partition("=")
        if not equals:
            raise Ros1Error("a connection header's field has no '=': %r" % field[:60])
        fields[key] = value
        at += 4 + size
    return fields


def tune(sock: socket.socket) -> None:
    """No Nagle delay (a transition must reach the page in milliseconds) and keepalive probes, so a
    robot that vanishes from the network without closing is noticed in about ten seconds."""
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_KEEPALIVE, 1)
    for option, value in (("TCP_KEEPIDLE", 4), ("TCP_KEEPINTVL", 2), ("TCP_KEEPCNT", 3)):
        if hasattr(socket, option):
            sock.setsockopt(socket.IPPROTO_TCP, getattr(socket, option), value)


def frame(payload: bytes) -> bytes:
    """A message as it goes on the wire: its length, then its bytes."""
    return _LENGTH.pack(len(payload)) + payload


def read_header(sock: socket.socket) -> dict[str, str]:
    """The next connection header from ``sock``."""
    return decode_header(_read_block(sock, MAX_HEADER, "connection header"))


def write_header(sock: socket.socket, fields: dict[str, str]) -> None:
    sock.sendall(encode_header(fields))


def read_message(sock: socket.socket) -> bytes:
    """The next message's serialized bytes from ``sock``."""
    return _read_block(sock, MAX_MESSAGE, "message")


def _read_block(sock: socket.socket, limit: int, what: str) -> bytes:
    (size,) = _LENGTH.unpack(_read_exactly(sock, 4))
    if size > limit:
        raise Ros1Error("a %s of %d bytes is more than the %d this client reads" % (what, size, limit))
    return _read_exactly(sock, size)


def _read_exactly(sock: socket.socket, size: int) -> bytes:
    chunks = []
    left = size
    while left:
        try:
            chunk = sock.recv(min(left, 1 << 20))
        except OSError as error:
            raise ConnectionClosed("the connection broke: %s" % error) from error
        if not chunk:
            raise ConnectionClosed("the connection was closed")
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)
