"""A publication of one topic: the subscribers connected to it over TCPROS, and each message sent
to all of them (and kept for a late one when latched).

A subscriber connects to the node's listener (fsmscope/ros1/listener.py), which hands it here with
its connection header; it must ask for this type's md5sum (or ``*``, as ``rostopic echo`` does).
Subscribers send nothing after their header, so a thread per connection waits only to see it close.
"""

from __future__ import annotations

import socket
import threading
from typing import Any, Callable

from . import tcpros
from .errors import Ros1Error
from .messages import MessageType

SEND_TIMEOUT = 5.0  # a subscriber that reads nothing for this long is dropped, not waited for


class Publication:
    """Node ``caller_id``'s publication of ``topic`` with type ``kind``; ``latch`` keeps the last message
    for subscribers that connect later; ``on_close(self)`` when it is closed."""

    def __init__(self, caller_id: str, topic: str, kind: MessageType, latch: bool = False,
                 on_close: Callable[[Publication], Any] | None = None) -> None:
        self.caller_id = caller_id
        self.topic = topic
        self.kind = kind
        self.latch = latch
        self._on_close = on_close
        self._lock = threading.Lock()
        self._subscribers: dict[socket.socket, str] = {}  # connection -> the subscriber's caller id
        self._latched: bytes | None = None
        self._closed = False

    @property
    def subscribers(self) -> list[str]:
        """The caller ids of the connected subscribers."""
        with self._lock:
            return sorted(self._subscribers.values())

    def publish(self, fields: dict[str, Any]) -> None:
        """Sends the message ``fields`` makes to every connected subscriber; a Ros1Error if it makes
        no message of this type (nothing is sent then)."""
        data = tcpros.frame(self.kind.encode(fields))
        with self._lock:
            if self._closed:
                raise Ros1Error("%s is no longer published: its publication was closed" % self.topic)
            if self.latch:
                self._latched = data
            for sock in list(self._subscribers):
                try:
                    sock.sendall(data)
                except OSError:
                    self._drop(sock)

    def accept(self, sock: socket.socket, header: dict[str, str]) -> None:
        """A subscriber connected with ``header``: answered with ours (or an error, and closed)."""
        caller_id = header.get("callerid", "?")
        if header.get("md5sum") not in (self.kind.md5sum, "*"):
            _refuse(sock, "%s wants %s as %s (md5sum %s), but %s publishes %s (md5sum %s)" % (
                caller_id, self.topic, header.get("type", "?"), header.get("md5sum", "?"), self.caller_id,
                self.kind.name, self.kind.md5sum))
            return
        with self._lock:
            try:
                if self._closed:
                    raise OSError("closed")
                tcpros.write_header(sock, {"callerid": self.caller_id, "topic": self.topic, "type": self.kind.name,
                                           "md5sum": self.kind.md5sum, "message_definition": self.kind.definition,
                                           "latching": "1" if self.latch else "0"})
                if self._latched is not None:
                    sock.sendall(self._latched)
            except OSError:
                sock.close()
                return
            self._subscribers[sock] = caller_id
        threading.Thread(target=self._watch, args=(sock,), daemon=True,
                         name="ros1 pub %s -> %s" % (self.topic, caller_id)).start()

    def close(self) -> None:
        """Disconnects every subscriber (and the node unregisters the publication)."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            for sock in list(self._subscribers):
                self._drop(sock)
        if self._on_close is not None:
            self._on_close(self)

    def _watch(self, sock: socket.socket) -> None:
        """Until the subscriber closes its connection (it sends nothing else)."""
        while True:
            try:
                if not sock.recv(4096):
                    break
            except socket.timeout:
                continue
            except OSError:
                break
        with self._lock:
            self._drop(sock)

    def _drop(self, sock: socket.socket) -> None:
        if self._subscribers.pop(sock, None) is not None:
            try:
                sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
            sock.close()


def _refuse(sock: socket.socket, error: str) -> None:
    """Answers a connection with an error header, as a ROS 1 node does, and closes it."""
    try:
        tcpros.write_header(sock, {"error": error})
    except OSError:
        pass
    sock.close()


def serve_connection(sock: socket.socket, publications: dict[str, Publication]) -> None:
    """A connection to the node's TCPROS port: its header says which publication it is for."""
    try:
        sock.settimeout(SEND_TIMEOUT)
        tcpros.tune(sock)
        header = tcpros.read_header(sock)
    except (OSError, Ros1Error):
        sock.close()
        return
    publication = publications.get(header.get("topic", ""))
    if "service" in header:
        _refuse(sock, "this node offers no services")
    elif publication is None:
        _refuse(sock, "this node does not publish %s" % header.get("topic", "(no topic named)"))
    else:
        publication.accept(sock, header)
