"""rospy, ROS-free, for a script run by ``fsmscope run`` (loaded under the name ``rospy``).

A node in this process alone: ``init_node``; logging through fsm's (so a state's
``rospy.loginfo`` lines reach the event log, as SMACH's own do); ``sleep``, ``Duration``,
``Time``, ``Rate``; shutdown (``is_shutdown``, ``signal_shutdown``, ``on_shutdown``, ``spin``);
topics and services on fsm's in-process bus (``Publisher``, ``Subscriber``, ``Service``,
``ServiceProxy``, ``wait_for_service``). Names resolve in the root namespace (``x`` is ``/x``).
Anything else of rospy (parameters, timers, remapping) is not covered: using it says so.
"""

from __future__ import annotations

import time
from typing import Any, Callable

import fsm
from fsm.ros.bus import ServiceException, get_bus
from fsmscope.counterparts import node
from fsmscope.counterparts.messages import coerce
from fsmscope.counterparts.names import not_covered

__all__ = ["init_node", "get_name", "loginfo", "logwarn", "logerr", "logfatal", "logdebug", "sleep", "Duration",
           "Time", "Rate", "get_time", "is_shutdown", "signal_shutdown", "on_shutdown", "spin", "Publisher",
           "Subscriber", "Service", "ServiceProxy", "wait_for_service", "ServiceException", "ROSException",
           "ROSInterruptException"]


def _logger(level: Callable[[object], None]) -> Callable[..., None]:
    def log(msg: Any, *args: Any, **kwargs: Any) -> None:
        """A line, formatted with ``args`` as rospy's (``loginfo("at %d", n)``), through fsm's log."""
        level(str(msg) % args if args else msg)
    return log


loginfo, logwarn, logerr, logdebug, logfatal = map(_logger, (fsm.loginfo, fsm.logwarn, fsm.logerr, fsm.logdebug,
                                                             fsm.logerr))


class ROSException(Exception):
    pass


class ROSInterruptException(ROSException, KeyboardInterrupt):
    pass


def init_node(name: str, argv: Any = None, anonymous: bool = False, **_options: Any) -> None:
    node.init(name + ("_%d" % (time.time_ns() % 10 ** 9) if anonymous else ""))


def get_name() -> str:
    return node.name()


class Duration:
    """Seconds and nanoseconds, as rospy's: ``Duration(2)``, ``Duration.from_sec(0.5)``, ``to_sec()``."""

    def __init__(self, secs: float = 0, nsecs: int = 0) -> None:
        self._ns = int(round(secs * 1e9)) + int(nsecs)

    @classmethod
    def from_sec(cls, secs: float) -> "Duration":
        return cls(secs)

    @property
    def secs(self) -> int:
        return self._ns // 10 ** 9

    @property
    def nsecs(self) -> int:
        return self._ns % 10 ** 9

    def to_sec(self) -> float:
        return self._ns / 1e9

    def to_nsec(self) -> int:
        return self._ns

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Duration) and other._ns == self._ns

    def __hash__(self) -> int:
        return hash(self._ns)

    def __repr__(self) -> str:
        return "rospy.Duration[%d]" % self._ns


class Time(Duration):
    """A wall-clock time: ``Time.now()``, ``to_sec()``; the difference of two is a ``Duration``."""

    @classmethod
    def now(cls) -> "Time":
        return cls(0, time.time_ns())

    def __sub__(self, other: "Time") -> Duration:
        return Duration(0, self._ns - other._ns)

    def __repr__(self) -> str:
        return "rospy.Time[%d]" % self._ns


def get_time() -> float:
    return time.time()


def sleep(duration: float | Duration) -> None:
    """Sleep, as rospy does: ``ROSInterruptException`` if the node shuts down meanwhile."""
    seconds = duration.to_sec() if isinstance(duration, Duration) else float(duration)
    if node.wait_for_shutdown(max(seconds, 0.0)):
        raise ROSInterruptException("ROS shutdown request")


class Rate:
    """Sleep to keep a loop at ``hz`` times a second."""

    def __init__(self, hz: float) -> None:
        self._period = 1.0 / hz
        self._last = time.monotonic()

    def sleep(self) -> None:
        now = time.monotonic()
        self._last = max(self._last + self._period, now)
        sleep(self._last - now)


def is_shutdown() -> bool:
    return node.is_shutdown()


def signal_shutdown(reason: str) -> None:
    node.signal_shutdown(reason)


def on_shutdown(h: Callable[[], Any]) -> None:
    node.on_shutdown(h)


def spin() -> None:
    """Wait until the node shuts down; Ctrl-C shuts it down, as rospy's handler does."""
    try:
        node.wait_for_shutdown(None)
    except KeyboardInterrupt:
        node.signal_shutdown("keyboard interrupt")


class Publisher:
    def __init__(self, name: str, data_class: type, queue_size: int | None = None, latch: bool = False,
                 **_options: Any) -> None:
        self.name, self.data_class = node.resolve(name), data_class

    def publish(self, *args: Any, **kwds: Any) -> None:
        """A message, or the fields to make one of ``data_class``, as rospy takes them."""
        msg = args[0] if len(args) == 1 and not kwds and isinstance(args[0], self.data_class) else \
            self.data_class(*args, **kwds)
        get_bus().publish(self.name, msg)

    def unregister(self) -> None:
        pass


class Subscriber:
    def __init__(self, name: str, data_class: type, callback: Callable[..., Any] | None = None,
                 callback_args: Any = None, queue_size: int | None = None, **_options: Any) -> None:
        self.name = node.resolve(name)

        def deliver(msg: Any) -> None:
            callback(msg) if callback_args is None else callback(msg, callback_args)
        self._sub = get_bus().subscribe(self.name, deliver) if callback is not None else None

    def unregister(self) -> None:
        if self._sub is not None:
            self._sub.unregister()
            self._sub = None


class Service:
    """``handler(request)`` offered as ``name``; what it returns becomes the response type, as
    rospy converts it (the response, a dict, a tuple or a single field)."""

    def __init__(self, name: str, service_class: type, handler: Callable[[Any], Any], **_options: Any) -> None:
        self.resolved_name = node.resolve(name)
        response = service_class._response_class
        self._handle = get_bus().advertise_service(self.resolved_name,
                                                   lambda request: coerce(response, handler(request)))
        node.on_shutdown(self.shutdown)

    def shutdown(self, reason: str = "") -> None:
        if self._handle is not None:
            self._handle.shutdown()
            self._handle = None


class ServiceProxy:
    """Call a service: ``proxy(request)`` or ``proxy(field, ...)``; ``ServiceException`` when it fails."""

    def __init__(self, name: str, service_class: type, **_options: Any) -> None:
        self.resolved_name = node.resolve(name)
        self._request = service_class._request_class

    def __call__(self, *args: Any, **kwds: Any) -> Any:
        return self.call(*args, **kwds)

    def call(self, *args: Any, **kwds: Any) -> Any:
        request = args[0] if len(args) == 1 and not kwds and isinstance(args[0], self._request) else \
            self._request(*args, **kwds)
        return get_bus().call_service(self.resolved_name, request)


def wait_for_service(service: str, timeout: float | Duration | None = None) -> None:
    seconds = timeout.to_sec() if isinstance(timeout, Duration) else timeout
    if not get_bus().wait_for_service(node.resolve(service), seconds):
        raise ROSException("timeout exceeded while waiting for service %s" % node.resolve(service))


def __getattr__(name: str) -> Any:
    raise not_covered("rospy", name, __all__)
