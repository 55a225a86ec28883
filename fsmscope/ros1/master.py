"""ROS 1's XML-RPC calls: the master's API (http://wiki.ros.org/ROS/Master_API) and the one call
this client makes to another node (``requestTopic``, http://wiki.ros.org/ROS/Slave_API).

Every answer is ``[code, statusMessage, value]``; a code other than 1, an unreachable or silent
peer and a malformed answer all become a Ros1Error that says which call failed and why. Calls time
out in seconds: a dead master must not hang its caller.
"""

from __future__ import annotations

import http.client
import urllib.parse
import xmlrpc.client
from xml.parsers.expat import ExpatError
from typing import Any

from .errors import Ros1Error

TIMEOUT = 3.0


class Unreachable(Ros1Error):
    """The API did not answer: nothing listens there, or it stayed silent past the timeout."""


class _Transport(xmlrpc.client.Transport):
    """The standard transport, with a timeout on its connection."""

    def __init__(self, timeout: float) -> None:
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host: Any) -> http.client.HTTPConnection:
        connection = super().make_connection(host)
        connection.timeout = self._timeout
        return connection


def check_uri(uri: str) -> str:
    """``uri`` if it is an http URI with a host and a port (as ROS_MASTER_URI is), else a Ros1Error."""
    parsed = urllib.parse.urlsplit(uri)
    try:
        port = parsed.port
    except ValueError:
        port = None
    if parsed.scheme != "http" or not parsed.hostname or port is None:
        raise Ros1Error("%r is not a ROS URI (http://HOST:PORT/)" % uri)
    return uri


def call(uri: str, method: str, *args: Any, timeout: float = TIMEOUT) -> Any:
    """``method(*args)`` of the XML-RPC API at ``uri``: the value of a success (code 1)."""
    proxy = xmlrpc.client.ServerProxy(uri, transport=_Transport(timeout))
    try:
        answer = getattr(proxy, method)(*args)
    except OSError as error:
        raise Unreachable("%s at %s: cannot reach it (%s)" % (method, uri, error)) from error
    except (xmlrpc.client.Error, http.client.HTTPException, ExpatError) as error:
        raise Ros1Error("%s at %s: not a ROS API (%s)" % (method, uri, error)) from error
    finally:
        proxy("close")()
    if not (isinstance(answer, list) and len(answer) == 3 and isinstance(answer[0], int)):
        raise Ros1Error("%s at %s: an answer that is not [code, message, value]: %.80r" % (method, uri, answer))
    code, message, value = answer
    if code != 1:
        raise Ros1Error("%s at %s failed (code %d): %s" % (method, uri, code, message))
    return value


class Master:
    """The master at ``uri``, called as the node ``caller_id`` whose own API is at ``caller_api``."""

    def __init__(self, uri: str, caller_id: str, caller_api: str) -> None:
        self.uri = check_uri(uri)
        self.caller_id = caller_id
        self.caller_api = caller_api

    def _call(self, method: str, *args: Any) -> Any:
        return call(self.uri, method, self.caller_id, *args)

    def register_subscriber(self, topic: str, type_name: str) -> list[str]:
        """Registers the subscription; returns the API URIs of the topic's publishers."""
        return list(self._call("registerSubscriber", topic, type_name, self.caller_api))

    def unregister_subscriber(self, topic: str) -> None:
        self._call("unregisterSubscriber", topic, self.caller_api)

    def register_publisher(self, topic: str, type_name: str) -> list[str]:
        """Registers the publication; returns the API URIs of the topic's subscribers."""
        return list(self._call("registerPublisher", topic, type_name, self.caller_api))

    def unregister_publisher(self, topic: str) -> None:
        self._call("unregisterPublisher", topic, self.caller_api)

    def published_topics(self) -> dict[str, str]:
        """Every topic that has a publisher, with its type (``pkg/Type``)."""
        return {topic: type_name for topic, type_name in self._call("getPublishedTopics", "")}

    def topic_types(self) -> dict[str, str]:
        """Every topic the master knows (published or only subscribed), with its type."""
        return {topic: type_name for topic, type_name in self._call("getTopicTypes")}

    def lookup_node(self, name: str) -> str:
        """The API URI of the node ``name``; a Ros1Error if the master does not know it."""
        return self._call("lookupNode", name)

    def pid(self) -> int:
        return self._call("getPid")
