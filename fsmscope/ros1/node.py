"""A ROS 1 node of fsmscope's own, with no ROS installed: it subscribes and publishes on a live
master as rospy would, speaking the master's API, its own API and TCPROS (the modules beside it).

A watchdog polls the master twice a second. A master that answers with another pid than before
(restarted: it knows none of our registrations) gets all of them again, and the publishers it
reports are connected; a master that does not answer makes ``master_connected`` false until it does.
"""

from __future__ import annotations

import itertools
import logging
import os
import re
import threading
from typing import Any, Callable

from .errors import Ros1Error
from .listener import Listener
from .master import Master, Unreachable, check_uri
from .messages import message_type
from .publication import Publication, serve_connection
from .slave import SlaveApi
from .subscription import Received, Subscription

WATCH_INTERVAL = 0.5

_log = logging.getLogger(__name__)
_NAME = re.compile(r"/?[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*)*")
_numbers = itertools.count(1)


def _graph_name(name: str, what: str) -> str:
    """``name`` made global (a leading ``/``) if it is a valid ROS graph name, else a Ros1Error."""
    if not _NAME.fullmatch(name):
        raise Ros1Error("%r is not a ROS %s name (letters, digits, '_' and '/', a letter first)" % (name, what))
    return name if name.startswith("/") else "/" + name


def _default_name() -> str:
    number = next(_numbers)
    return "/fsmscope_%d" % os.getpid() + ("" if number == 1 else "_%d" % number)


class Node:
    """A node called ``name`` (``/fsmscope_<pid>`` by default) of the master at ``master_uri``, its
    APIs served on ``host`` (an address the master and the publishers can reach)."""

    def __init__(self, master_uri: str, name: str | None = None, host: str = "127.0.0.1") -> None:
        self.name = _graph_name(name or _default_name(), "node")
        self.master_uri = check_uri(master_uri)
        self.tcpros_host = host
        self.master_connected = False
        self._lock = threading.RLock()
        self._subscriptions: dict[str, list[Subscription]] = {}
        self._publications: dict[str, Publication] = {}
        self._master_pid: int | None = None
        self._listener = Listener(host, lambda sock: serve_connection(sock, self._publications))
        self.tcpros_port = self._listener.port
        try:
            self._api = SlaveApi(self, host)
        except Ros1Error:
            self._listener.close()
            raise
        self._master = Master(self.master_uri, self.name, self._api.uri)
        self._stop = threading.Event()
        self._check_master()
        self._watchdog = threading.Thread(target=self._watch, daemon=True, name="ros1 master watchdog")
        self._watchdog.start()

    @property
    def uri(self) -> str:
        """The node's own API, as the master knows it."""
        return self._api.uri

    def published_topics(self) -> dict[str, str]:
        """Every topic with a publisher, and its type (``pkg/Type``), as the master says now."""
        return self._master.published_topics()

    def subscribe(self, topic: str, type_name: str, on_message: Callable[[Received], Any],
                  on_publishers: Callable[[list[str]], Any] | None = None) -> Subscription:
        """Subscribes to ``topic`` as ``type_name``: ``on_message(Received)`` per message (from a reader
        thread, in order per publisher), ``on_publishers(caller ids)`` when the connected publishers
        change. A master that does not answer now gets the subscription when it does."""
        topic = _graph_name(topic, "topic")
        subscription = Subscription(self.name, topic, message_type(type_name), on_message, on_publishers,
                                    on_close=self._forget_subscription)
        with self._lock:
            self._subscriptions.setdefault(topic, []).append(subscription)
        self._register_subscriber(topic, type_name)
        return subscription

    def advertise(self, topic: str, type_name: str, latch: bool = False) -> Publication:
        """Publishes ``topic`` as ``type_name`` (``latch``: a late subscriber gets the last message)."""
        topic = _graph_name(topic, "topic")
        with self._lock:
            if topic in self._publications:
                raise Ros1Error("%s is already published by this node" % topic)
            publication = Publication(self.name, topic, message_type(type_name), latch,
                                      on_close=self._forget_publication)
            self._publications[topic] = publication
        try:
            self._master.register_publisher(topic, type_name)
        except Unreachable:
            self.master_connected = False
        return publication

    def close(self) -> None:
        """Unregisters everything (if the master answers), closes every connection and the node's APIs."""
        self._stop.set()
        self._watchdog.join(5)  # it registers nothing again after this
        with self._lock:
            subscriptions = [s for topic in self._subscriptions.values() for s in topic]
            publications = list(self._publications.values())
        for subscription in subscriptions:
            subscription.close()
        for publication in publications:
            publication.close()
        self._listener.close()
        self._api.close()

    # --- what the node's API reads and is told (fsmscope/ros1/slave.py's NodeState)

    def subscribed(self) -> list[list[str]]:
        with self._lock:
            return [[topic, subs[0].kind.name] for topic, subs in self._subscriptions.items()]

    def published(self) -> list[list[str]]:
        with self._lock:
            return [[topic, publication.kind.name] for topic, publication in self._publications.items()]

    def bus_info(self) -> list[list[Any]]:
        with self._lock:
            subscriptions = [s for topic in self._subscriptions.values() for s in topic]
            publications = list(self._publications.values())
        rows: list[list[Any]] = []
        for subscription in subscriptions:
            rows += [[len(rows) + 1, uri, "i", "TCPROS", subscription.topic, True]
                     for uri, _ in subscription.connections()]
        for publication in publications:
            rows += [[len(rows) + 1, caller_id, "o", "TCPROS", publication.topic, True]
                     for caller_id in publication.subscribers]
        return rows

    def publisher_update(self, topic: str, publishers: list[str]) -> None:
        with self._lock:
            subscriptions = list(self._subscriptions.get(topic, ()))
        for subscription in subscriptions:
            subscription.update_publishers(publishers)

    def shutdown_requested(self, caller_id: str, reason: str) -> None:
        _log.warning("%s asked ROS 1 node %s to shut down (%s); it goes on", caller_id, self.name, reason)

    # --- the master

    def _register_subscriber(self, topic: str, type_name: str) -> None:
        try:
            publishers = self._master.register_subscriber(topic, type_name)
        except Unreachable:
            self.master_connected = False
            return
        self.publisher_update(topic, publishers)

    def _watch(self) -> None:
        while not self._stop.wait(WATCH_INTERVAL):
            self._check_master()

    def _check_master(self) -> None:
        """Registers everything again with a master that is not the one it was registered with."""
        try:
            pid = self._master.pid()
            if pid != self._master_pid:
                with self._lock:
                    subscribed = [(topic, subs[0].kind.name) for topic, subs in self._subscriptions.items()]
                    published = [(topic, publication.kind.name) for topic, publication in self._publications.items()]
                for topic, type_name in published:
                    self._master.register_publisher(topic, type_name)
                for topic, type_name in subscribed:
                    self.publisher_update(topic, self._master.register_subscriber(topic, type_name))
                self._master_pid = pid
        except Unreachable:
            self.master_connected = False
            return
        except Ros1Error as error:
            _log.warning("ROS 1 node %s: %s", self.name, error)
        self.master_connected = True

    def _forget_subscription(self, subscription: Subscription) -> None:
        with self._lock:
            subscriptions = self._subscriptions.get(subscription.topic, [])
            if subscription in subscriptions:
                subscriptions.remove(subscription)
            last = not subscriptions
            if last:
                self._subscriptions.pop(subscription.topic, None)
        if last:
            self._unregister(self._master.unregister_subscriber, subscription.topic)

    def _forget_publication(self, publication: Publication) -> None:
        with self._lock:
            if self._publications.get(publication.topic) is publication:
                del self._publications[publication.topic]
        self._unregister(self._master.unregister_publisher, publication.topic)

    def _unregister(self, unregister: Callable[[str], None], topic: str) -> None:
        if not self.master_connected:
            return
        try:
            unregister(topic)
        except Ros1Error as error:
            _log.info("ROS 1 node %s could not unregister %s: %s", self.name, topic, error)
