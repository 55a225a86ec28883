"""An in-process message bus: topics, services and action servers by name, in place of ROS.

Subscriber callbacks and service handlers run synchronously in the thread that publishes or
calls, so a message is handled before ``publish`` returns. Waits for a name accept a ``wake``
Event: a state passes the Event its ``request_preempt`` sets, and a preempt ends the wait.
"""

import threading
import traceback
from typing import Any, Callable

from ..core import log


class ServiceException(Exception):
    """A service call failed: nobody offers the service, or its handler raised (as rospy's)."""


def call_logged(what: str, cb: Callable[..., Any], *args: Any) -> None:
    """Run a callback for someone who cannot handle its failure: log the traceback, go on."""
    try:
        cb(*args)
    except Exception:
        log.logerr("Exception in %s: %s" % (what, traceback.format_exc()))


class _Registry:
    """Named endpoints (services or action servers) that callers can wait for."""

    def __init__(self, kind: str) -> None:
        self._kind = kind
        self._lock = threading.Lock()
        self._items: dict[str, Any] = {}
        self._waiters: dict[str, set[threading.Event]] = {}

    def add(self, name: str, item: Any) -> None:
        with self._lock:
            if name in self._items:
                raise ValueError("%s '%s' is already registered" % (self._kind, name))
            self._items[name] = item
            waiters = self._waiters.pop(name, set())
        for event in waiters:
            event.set()

    def remove(self, name: str, item: Any) -> None:
        """Remove ``name`` only if ``item`` still holds it, so a stale handle cannot remove a successor."""
        with self._lock:
            if self._items.get(name) is item:
                del self._items[name]

    def get(self, name: str) -> Any:
        with self._lock:
            return self._items.get(name)

    def names(self) -> list[str]:
        with self._lock:
            return sorted(self._items)

    def wait(self, name: str, timeout: float | None, wake: threading.Event | None) -> bool:
        """True once ``name`` is registered; False on timeout or when ``wake`` is set first."""
        event = wake if wake is not None else threading.Event()
        with self._lock:
            if name in self._items:
                return True
            if timeout is not None and timeout <= 0:
                return False
            self._waiters.setdefault(name, set()).add(event)
        try:
            event.wait(timeout)
        finally:
            with self._lock:
                waiters = self._waiters.get(name)
                if waiters is not None:
                    waiters.discard(event)
                    if not waiters:
                        del self._waiters[name]
                return name in self._items


class Subscription:
    """Returned by ``Bus.subscribe``; ``unregister()`` stops the deliveries (idempotent)."""

    def __init__(self, bus: "Bus", topic: str, callback: Callable[[Any], Any]) -> None:
        self.topic = topic
        self.callback = callback
        self._bus = bus

    def unregister(self) -> None:
        self._bus._unsubscribe(self)


class ServiceHandle:
    """Returned by ``Bus.advertise_service``; ``shutdown()`` withdraws the service."""

    def __init__(self, bus: "Bus", name: str, handler: Callable[[Any], Any]) -> None:
        self.name = name
        self.handler = handler
        self._bus = bus

    def shutdown(self) -> None:
        self._bus._services.remove(self.name, self)


class Bus:
    """Topics, services and action servers of one process; thread-safe."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._subscribers: dict[str, list[Subscription]] = {}
        self._services = _Registry("service")
        self._action_servers = _Registry("action server")

    # Topics

    def publish(self, topic: str, msg: Any) -> int:
        """Deliver ``msg`` to every subscriber of ``topic``; returns how many subscribers it reached.

        A raising callback is logged and skipped (and still counted: the message reached it).
        """
        with self._lock:
            subscribers = list(self._subscribers.get(topic, ()))
        for sub in subscribers:
            call_logged("subscriber callback on topic '%s'" % topic, sub.callback, msg)
        return len(subscribers)

    def subscribe(self, topic: str, callback: Callable[[Any], Any]) -> Subscription:
        sub = Subscription(self, topic, callback)
        with self._lock:
            self._subscribers.setdefault(topic, []).append(sub)
        return sub

    def _unsubscribe(self, sub: Subscription) -> None:
        with self._lock:
            subs = self._subscribers.get(sub.topic, [])
            if sub in subs:
                subs.remove(sub)
            if not subs:
                self._subscribers.pop(sub.topic, None)

    def topics(self) -> list[str]:
        """Topics that have at least one subscriber now (where a publish has an effect)."""
        with self._lock:
            return sorted(self._subscribers)

    # Services

    def advertise_service(self, name: str, handler: Callable[[Any], Any]) -> ServiceHandle:
        """Offer ``handler(request) -> response`` under ``name``; a name can be offered once."""
        handle = ServiceHandle(self, name, handler)
        self._services.add(name, handle)
        return handle

    def wait_for_service(self, name: str, timeout: float | None = None,
                         wake: threading.Event | None = None) -> bool:
        return self._services.wait(name, timeout, wake)

    def call_service(self, name: str, request: Any, timeout: float | None = None) -> Any:
        """Call the handler in this thread; with a ``timeout``, first wait that long for the service."""
        if timeout is not None:
            self._services.wait(name, timeout, None)
        handle = self._services.get(name)
        if handle is None:
            raise ServiceException("service '%s' is not available" % name)
        try:
            return handle.handler(request)
        except Exception as ex:
            raise ServiceException("service '%s' raised %s: %s" % (name, type(ex).__name__, ex)) from ex

    def services(self) -> list[str]:
        return self._services.names()

    # Action servers (used by fsm.ros.actionlib)

    def register_action_server(self, name: str, server: Any) -> None:
        self._action_servers.add(name, server)

    def unregister_action_server(self, name: str, server: Any) -> None:
        self._action_servers.remove(name, server)

    def action_server(self, name: str) -> Any:
        """The server registered under ``name``, or None."""
        return self._action_servers.get(name)

    def wait_for_action_server(self, name: str, timeout: float | None = None,
                               wake: threading.Event | None = None) -> bool:
        return self._action_servers.wait(name, timeout, wake)

    def action_servers(self) -> list[str]:
        return self._action_servers.names()


default_bus = Bus()


def get_bus(bus: Bus | None = None) -> Bus:
    """``bus`` itself, or the process-wide default bus when None."""
    return default_bus if bus is None else bus
