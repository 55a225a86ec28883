"""A subscription to one topic: a TCPROS connection to each of its publishers, each read by a thread
of its own, every message handed on as a plain dict.

The master tells which publishers there are (their APIs, as ``registerSubscriber`` returns them and
``publisherUpdate`` sends them); each is asked for its TCPROS port (``requestTopic``), and its
connection header must name the subscription's type and md5sum, else it is refused and said. A
connection that closes (its node killed) takes its publisher out of the connected set; what goes
wrong is counted and said in ``problems``, never raised into the caller.
"""

from __future__ import annotations

import collections
import socket
import threading
import time
from dataclasses import dataclass
from typing import Any, Callable

from . import tcpros
from .errors import Ros1Error
from .master import Unreachable, call
from .messages import MessageType

PROBLEMS_KEPT = 20
HANDSHAKE_TIMEOUT = 3.0


@dataclass(frozen=True)
class Received:
    """One message: its ``topic``, the ``publisher``'s caller id, ``t`` (time.time() on receipt),
    ``fields`` (a plain dict: fsmscope/ros1/messages.py) and ``stamp`` (its header's stamp in
    seconds, None when it has no header)."""

    topic: str
    publisher: str
    t: float
    fields: dict[str, Any]
    stamp: float | None


class Subscription:
    """The subscription of node ``caller_id`` to ``topic`` of type ``kind``: ``on_message(Received)``
    per message, in order per publisher; ``on_publishers(caller ids)`` when the connected set
    changes. ``problems`` (the last few, in words) and ``undecodable`` (a count) say what failed;
    ``on_close(self)`` when it is closed."""

    def __init__(self, caller_id: str, topic: str, kind: MessageType, on_message: Callable[[Received], Any],
                 on_publishers: Callable[[list[str]], Any] | None = None,
                 on_close: Callable[[Subscription], Any] | None = None) -> None:
        self.caller_id = caller_id
        self.topic = topic
        self.kind = kind
        self.undecodable = 0
        self._on_message = on_message
        self._on_publishers = on_publishers
        self._on_close = on_close
        self._problems: collections.deque[str] = collections.deque(maxlen=PROBLEMS_KEPT)
        self._lock = threading.Lock()
        self._telling = threading.Lock()  # on_publishers gets the sets in the order they were
        self._links: dict[str, _Link] = {}  # publisher API URI -> its connection, connecting or connected
        self._closed = False
        self._unreachable: set[str] = set()  # publisher APIs said not to answer (a killed robot stays listed)

    @property
    def problems(self) -> list[str]:
        return list(self._problems)

    @property
    def publishers(self) -> list[str]:
        """The caller ids of the connected publishers."""
        with self._lock:
            return sorted(link.caller_id for link in self._links.values() if link.caller_id is not None)

    def connections(self) -> list[tuple[str, str]]:
        """``(publisher API URI, caller id)`` of each connected publisher (the node's getBusInfo)."""
        with self._lock:
            return [(uri, link.caller_id) for uri, link in self._links.items() if link.caller_id is not None]

    def update_publishers(self, uris: list[str]) -> None:
        """The master says the topic's publishers are ``uris``: connect to those not connected. A
        connection to one it no longer lists is kept, as rospy keeps it: a publisher that leaves
        closes it, and a restarted master lists only the publishers that registered with it since."""
        with self._lock:
            if self._closed:
                return
            self._unreachable &= set(uris)
            for uri in uris:
                if uri not in self._links:
                    self._links[uri] = _Link(self, uri)
                    self._links[uri].start()

    def close(self) -> None:
        """Disconnects from every publisher (and the node unregisters the subscription); no callback
        is called after it returns but one under way."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            links, self._links = list(self._links.values()), {}
        for link in links:
            link.close()
        if self._on_close is not None:
            self._on_close(self)

    def said(self, problem: str) -> None:
        self._problems.append(problem)

    def _first_unreachable(self, uri: str) -> bool:
        """Whether ``uri`` is said not to answer for the first time since the master listed it."""
        with self._lock:
            first = uri not in self._unreachable
            self._unreachable.add(uri)
        return first

    def _connected(self, link: _Link, caller_id: str) -> bool:
        with self._lock:
            if self._links.get(link.uri) is not link:
                return False
            link.caller_id = caller_id
        self._tell_publishers()
        return True

    def _disconnected(self, link: _Link) -> None:
        with self._lock:
            was_connected = link.caller_id is not None
            if self._links.get(link.uri) is link:
                del self._links[link.uri]
        if was_connected:
            self._tell_publishers()

    def _tell_publishers(self) -> None:
        if self._on_publishers is None or self._closed:
            return
        with self._telling:
            try:
                self._on_publishers(self.publishers)
            except Exception as error:  # the caller's callback: said, never the end of our reader
                self.said("on_publishers raised %s: %s" % (type(error).__name__, error))

    def _received(self, publisher: str, raw: bytes, t: float) -> None:
        try:
            fields = self.kind.decode(raw)
        except Ros1Error as error:
            with self._lock:
                self.undecodable += 1
            self.said("a message from %s on %s does not decode: %s" % (publisher, self.topic, error))
            return
        stamp = None
        if self.kind.has_header:
            time_ = fields["header"]["stamp"]
            stamp = time_["sec"] + time_["nanosec"] * 1e-9
        try:
            self._on_message(Received(self.topic, publisher, t, fields, stamp))
        except Exception as error:  # the caller's callback: said, never the end of our reader
            self.said("on_message raised %s: %s" % (type(error).__name__, error))


class _Link:
    """The connection to one publisher (its API at ``uri``), made and read by a thread of its own."""

    def __init__(self, subscription: Subscription, uri: str) -> None:
        self.subscription = subscription
        self.uri = uri
        self.caller_id: str | None = None  # once connected
        self._sock: socket.socket | None = None
        self._closing = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True,
                                        name="ros1 sub %s <- %s" % (subscription.topic, uri))

    def start(self) -> None:
        self._thread.start()

    def close(self) -> None:
        self._closing.set()
        sock = self._sock
        if sock is not None:
            try:
                sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass

    def _run(self) -> None:
        sub = self.subscription
        try:
            try:
                caller_id = self._connect()
            except Unreachable as error:
                if not self._closing.is_set() and sub._first_unreachable(self.uri):
                    sub.said("the publisher at %s of %s does not answer: %s" % (self.uri, sub.topic, error))
                return
            except Ros1Error as error:
                if not self._closing.is_set():
                    sub.said("not connected to the publisher at %s of %s: %s" % (self.uri, sub.topic, error))
                return
            if not sub._connected(self, caller_id):
                return
            while not self._closing.is_set():
                raw = tcpros.read_message(self._sock)
                sub._received(caller_id, raw, time.time())
        except Ros1Error as error:
            if not self._closing.is_set() and not isinstance(error, tcpros.ConnectionClosed):
                sub.said("the connection to %s on %s ended: %s" % (self.caller_id, sub.topic, error))
        finally:
            if self._sock is not None:
                self._sock.close()
            sub._disconnected(self)

    def _connect(self) -> str:
        """Asks the publisher for its port, connects, exchanges headers; its caller id."""
        sub = self.subscription
        protocol = call(self.uri, "requestTopic", sub.caller_id, sub.topic, [["TCPROS"]])
        if not (isinstance(protocol, list) and len(protocol) == 3 and protocol[0] == "TCPROS"):
            raise Ros1Error("it offers no TCPROS connection (%.80r)" % (protocol,))
        _, host, port = protocol
        try:
            self._sock = socket.create_connection((host, port), timeout=HANDSHAKE_TIMEOUT)
        except (OSError, TypeError, ValueError) as error:
            raise Ros1Error("cannot connect to %s:%s (%s)" % (host, port, error)) from error
        if self._closing.is_set():
            raise Ros1Error("closed")
        try:
            tcpros.tune(self._sock)
            tcpros.write_header(self._sock, {"callerid": sub.caller_id, "topic": sub.topic,
                                             "md5sum": sub.kind.md5sum, "type": sub.kind.name,
                                             "message_definition": sub.kind.definition, "tcp_nodelay": "1"})
            header = tcpros.read_header(self._sock)
            self._sock.settimeout(None)
        except OSError as error:
            raise Ros1Error("the connection to %s:%s broke (%s)" % (host, port, error)) from error
        caller_id = header.get("callerid", self.uri)
        if "error" in header:
            raise Ros1Error("%s refused: %s" % (caller_id, header["error"]))
        if header.get("md5sum") not in (sub.kind.md5sum, "*"):
            raise Ros1Error("%s publishes it as %s (md5sum %s), not as %s (md5sum %s)"
                            % (caller_id, header.get("type", "?"), header.get("md5sum", "?"), sub.kind.name,
                               sub.kind.md5sum))
        return caller_id
