"""The node's own XML-RPC API, which the master and other nodes call (ROS 1's "slave" API,
http://wiki.ros.org/ROS/Slave_API): served by the standard library's XML-RPC server in a daemon
thread, on a free port of the given host.

The answers that matter are ``publisherUpdate`` (the master saying who publishes a topic we
subscribe to) and ``requestTopic`` (a subscriber asking where to connect for a topic we publish);
the others answer what tools (``rosnode info``, ``rosnode ping``) ask, minimally but validly.
"""

from __future__ import annotations

import os
import socketserver
import threading
import xmlrpc.server
from typing import Any, Protocol

from .errors import Ros1Error


class NodeState(Protocol):
    """What the API reads from and tells the node."""

    master_uri: str
    tcpros_host: str
    tcpros_port: int

    def subscribed(self) -> list[list[str]]: ...  # [topic, type] of each subscription

    def published(self) -> list[list[str]]: ...  # [topic, type] of each publication

    def bus_info(self) -> list[list[Any]]: ...  # getBusInfo's rows

    def publisher_update(self, topic: str, publishers: list[str]) -> None: ...

    def shutdown_requested(self, caller_id: str, reason: str) -> None: ...


class _ThreadingServer(socketserver.ThreadingMixIn, xmlrpc.server.SimpleXMLRPCServer):
    """One thread per call: the master calls publisherUpdate while a node calls requestTopic."""

    daemon_threads = True


class _Api:
    """The methods; each answers ``[code, statusMessage, value]`` as ROS 1 does."""

    def __init__(self, node: NodeState) -> None:
        self._node = node

    def getPid(self, caller_id: str) -> list:
        return [1, "", os.getpid()]

    def getMasterUri(self, caller_id: str) -> list:
        return [1, "", self._node.master_uri]

    def getSubscriptions(self, caller_id: str) -> list:
        return [1, "subscriptions", self._node.subscribed()]

    def getPublications(self, caller_id: str) -> list:
        return [1, "publications", self._node.published()]

    def getBusInfo(self, caller_id: str) -> list:
        return [1, "bus info", self._node.bus_info()]

    def getBusStats(self, caller_id: str) -> list:
        return [1, "bus stats", [[], [], [0, 0, 0]]]

    def paramUpdate(self, caller_id: str, key: str, value: Any) -> list:
        return [1, "", 0]

    def publisherUpdate(self, caller_id: str, topic: str, publishers: list[str]) -> list:
        self._node.publisher_update(topic, list(publishers))
        return [1, "", 0]

    def requestTopic(self, caller_id: str, topic: str, protocols: list) -> list:
        if topic not in dict(self._node.published()):
            return [0, "this node does not publish %s" % topic, []]
        if not any(protocol and protocol[0] == "TCPROS" for protocol in protocols):
            return [0, "this node speaks only TCPROS", []]
        return [1, "ready on %s:%d" % (self._node.tcpros_host, self._node.tcpros_port),
                ["TCPROS", self._node.tcpros_host, self._node.tcpros_port]]

    def shutdown(self, caller_id: str, reason: str = "") -> list:
        self._node.shutdown_requested(caller_id, reason)
        return [1, "", 0]


class SlaveApi:
    """The API of ``node``, served on ``host``: its URI is ``uri``."""

    def __init__(self, node: NodeState, host: str) -> None:
        try:
            self._server = _ThreadingServer((host, 0), logRequests=False, allow_none=False)
        except OSError as error:
            raise Ros1Error("cannot serve the node's API on %s: %s" % (host, error)) from error
        self._server.register_instance(_Api(node))
        self.uri = "http://%s:%d/" % (host, self._server.server_address[1])
        self._thread = threading.Thread(target=self._server.serve_forever, kwargs={"poll_interval": 0.2},
                                        daemon=True, name="ros1 api %s" % self.uri)
        self._thread.start()

    def close(self) -> None:
        self._server.shutdown()
        self._server.server_close()
        self._thread.join(5)
