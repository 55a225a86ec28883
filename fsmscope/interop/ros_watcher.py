"""Every SMACH machine of a live ROS graph, followed as smach_viewer followed them: each
IntrospectionServer that a ROS 1 master or a ROS 2 network shows, turned into fsmscope events while
it runs, with no ROS on this computer.

A ``node`` (``fsmscope.ros1.Node`` or ``fsmscope.ros2.Node``: the same calls) is asked every
``POLL`` seconds which topics it sees. Each ``<server>/smach/container_status`` of smach_msgs' type is
a server: its status and structure topics are subscribed, and ``/rosout`` once for all, for the
SMACH lines that tell the real outcomes. A topic with a SMACH name and another type is said once and
left alone. Each publisher of a server's status is one machine (two nodes that publish the same
server's topics are two machines), followed by the converter bags use
(``smach_events.Follower``), so a live robot and its bag say the same.

The topics arrive on connections of their own, so a node's SMACH line and the status it precedes
may come in either order: each message waits ``WINDOW`` seconds after it arrived, then those that
waited long enough go to the followers in the order of their stamps (the robot's clock). A machine
whose every status publisher went away is said gone (``seen(name, False)``), what can still be told
of its run is delivered, and it comes back when one publishes again.
"""

from __future__ import annotations

import heapq
import itertools
import sys
import threading
import time
from dataclasses import dataclass
from typing import Any, Callable, Protocol

from fsm.observation import names

from .bag_reader import Message, introspection_fields
from .smach_follower import Follower

POLL = 1.0  # s between two looks for servers that came or went
WINDOW = 0.02  # s a message waits for those stamped before it on the other topics (within the page's 50 ms)
STATUS_SUFFIX = "/smach/container_status"
STRUCTURE_SUFFIX = "/smach/container_structure"
INIT_SUFFIX = "/smach/container_init"
ROSOUT = "/rosout"
SUBSCRIBED_WAIT = 2.0  # s a control waits for a subscriber of its topic
STOP_TOPIC = "/sm_stop"  # where a robot's MonitorState waits for std_msgs/Empty, unless told otherwise


class Unheard(Exception):
    """A message that no subscriber would take."""


@dataclass(frozen=True)
class Flavour:
    """What differs between ROS 1 and ROS 2 here: the names of the types, and how ``local_data``
    travels (noetic: base64 of the pickle in a string; ROS 2: the pickle's bytes)."""

    status: str
    structure: str
    init: str
    log: str
    empty: str
    base64_local_data: bool


ROS1 = Flavour("smach_msgs/SmachContainerStatus", "smach_msgs/SmachContainerStructure",
               "smach_msgs/SmachContainerInitialStatusCmd", "rosgraph_msgs/Log", "std_msgs/Empty", True)
ROS2 = Flavour("smach_msgs/msg/SmachContainerStatus", "smach_msgs/msg/SmachContainerStructure",
               "smach_msgs/msg/SmachContainerInitialStatusCmd", "rcl_interfaces/msg/Log", "std_msgs/msg/Empty", False)


class Node(Protocol):
    """What this module asks of fsmscope.ros1.Node and fsmscope.ros2.Node."""

    def published_topics(self) -> dict[str, str]: ...

    def subscribe(self, topic: str, type_name: str, on_message: Callable[[Any], None],
                  on_publishers: Callable[[list[str]], None] | None = None) -> Any: ...

    def advertise(self, topic: str, type_name: str) -> Any: ...

    def close(self) -> None: ...


@dataclass
class Machine:
    """One publisher's server, as this watcher follows it."""

    name: str
    server: str  # the ROS name its topics hang under ("/robot1/sm")
    publisher: str  # the publishing node's id (ROS 1: its caller id, which /rosout's lines name)
    follower: Follower
    stop_topic: str  # where its preempt is published
    up: bool = True


class RosWatcher:
    """The servers of ``node``'s graph, each publisher's as a machine: ``deliver(events)`` gets each
    machine's events in order (from this watcher's thread), ``seen(name, up)`` says a machine went
    away or came back. ``said(text)`` hears what this watcher says of the graph (a topic of another type,
    a message that did not decode, a master that went away)."""

    def __init__(self, node: Node, flavour: Flavour, deliver: Callable[[list[dict]], None],
                 seen: Callable[[str, bool], None], said: Callable[[str], None] | None = None,
                 stop_topic: Callable[[str], str] = lambda name: STOP_TOPIC, poll: float = POLL,
                 window: float = WINDOW) -> None:
        self.node = node
        self.flavour = flavour
        self._deliver = deliver
        self._seen = seen
        self._said = said or (lambda text: print("fsmscope: %s" % text, file=sys.stderr, flush=True))
        self._stop_topic = stop_topic
        self._poll = poll
        self._window = window
        self.machines: dict[tuple[str, str], Machine] = {}  # (server, publisher) -> its machine
        self._taken: set[str] = set()
        self._subscriptions: dict[str, Any] = {}  # topic -> its subscription
        self._publications: dict[str, Any] = {}  # topic -> its publication
        self._told: set[str] = set()  # what was said once
        self._problems: dict[str, list[str]] = {}  # topic -> its subscription's problems, as last said
        self._waiting: list[tuple[float, int, float, str, Any]] = []  # (stamp, order, arrived, kind, received)
        self._order = itertools.count()
        self._lock = threading.Lock()  # the followers, the machines and the waiting messages
        self._advertising = threading.Lock()  # the publications (a master's answer is not waited for under _lock)
        self._wake = threading.Condition(self._lock)
        self._stopped = threading.Event()
        self._threads = [threading.Thread(target=self._look, name="fsmscope-ros-look", daemon=True),
                         threading.Thread(target=self._follow, name="fsmscope-ros-follow", daemon=True)]
        for thread in self._threads:
            thread.start()

    def close(self) -> None:
        self._stopped.set()
        with self._wake:
            self._wake.notify()
        for thread in self._threads:
            thread.join(5)
        self.node.close()

    def machine(self, name: str) -> Machine | None:
        with self._lock:
            return self._named(name)

    def _named(self, name: str) -> Machine | None:
        return next((m for m in self.machines.values() if m.name == name), None)

    def emit(self, name: str, make: Callable[..., dict], path: str | None, *fields: Any) -> int:
        """An event this process adds to the machine's stream (a control and its result): made by its
        follower, after every event delivered so far; its seq."""
        with self._lock:
            machine = self._named(name)
            if machine is None:
                raise KeyError(name)
            event = machine.follower.event(make, path, *fields)
            self._deliver([event])
            return event["seq"]

    def advertise(self, topic: str, type_name: str) -> Any:
        """The publication of ``topic`` (made the first time): made when a machine is found, so that the
        robot's subscriptions have connected to it (ROS 1) or matched it (DDS) before a control uses it."""
        with self._advertising:
            publication = self._publications.get(topic)
            if publication is None:
                publication = self._publications[topic] = self.node.advertise(topic, type_name)
            return publication

    def publish(self, topic: str, type_name: str, fields: dict, wait: float = SUBSCRIBED_WAIT) -> list[str]:
        """``fields`` on ``topic``, once a subscriber is there (``wait`` seconds at most): the subscribers it
        reached. ``Unheard`` when none is: a message nobody takes is not said to be sent."""
        publication = self.advertise(topic, type_name)
        deadline = time.monotonic() + wait
        while not publication.subscribers and time.monotonic() < deadline:
            time.sleep(0.02)
        subscribers = publication.subscribers
        if not subscribers:
            raise Unheard("nobody subscribes to %s" % topic)
        publication.publish(fields)
        return subscribers

    def _advertise_controls(self, machine: Machine) -> None:
        """The topics of the machine's controls, advertised as soon as it is found (``advertise``)."""
        flavour = self.flavour
        for topic, type_name in ((machine.stop_topic, flavour.empty), (machine.server + INIT_SUFFIX, flavour.init)):
            try:
                self.advertise(topic, type_name)
            except Exception as exc:  # the control says so again when it is used
                self._once("pub " + topic, "cannot advertise %s: %s" % (topic, exc))

    # The looking thread: servers that came.
    def _look(self) -> None:
        self._subscribe(ROSOUT, self.flavour.log, "log")
        while not self._stopped.is_set():
            try:
                topics = self.node.published_topics()
            except Exception as exc:  # the master is away: said once until it answers again
                self._once("graph", "cannot ask the ROS graph for its topics: %s" % exc)
            else:
                self._told.discard("graph")
                for topic, type_name in sorted(topics.items()):
                    if topic.endswith(STATUS_SUFFIX) or topic.endswith(STRUCTURE_SUFFIX):
                        self._found(topic, type_name)
            for topic, subscription in list(self._subscriptions.items()):
                self._say_problems(topic, subscription.problems)
            self._stopped.wait(self._poll)

    def _say_problems(self, topic: str, problems: list[str]) -> None:
        """What a subscription refused or could not decode since it was last asked (its last few)."""
        before = self._problems.get(topic, [])
        for problem in problems:
            if problem not in before:
                self._said("%s: %s" % (topic, problem))
        self._problems[topic] = problems

    def _found(self, topic: str, type_name: str) -> None:
        status = topic.endswith(STATUS_SUFFIX)
        wanted = self.flavour.status if status else self.flavour.structure
        if type_name != wanted:
            self._once(topic, "%s has the name of a SMACH introspection topic but its type is %s, not %s: "
                              "it is not followed" % (topic, type_name, wanted))
            return
        server = topic[:-len(STATUS_SUFFIX if status else STRUCTURE_SUFFIX)]
        self._subscribe(server + STATUS_SUFFIX, self.flavour.status, "status", server)
        self._subscribe(server + STRUCTURE_SUFFIX, self.flavour.structure, "structure", server)

    def _subscribe(self, topic: str, type_name: str, kind: str, server: str | None = None) -> None:
        if topic in self._subscriptions:
            return
        on_publishers = (lambda publishers: self._publishers(server, publishers)) if kind == "status" else None
        try:
            self._subscriptions[topic] = self.node.subscribe(
                topic, type_name, lambda received: self._arrived(kind, received), on_publishers)
        except Exception as exc:
            self._once("sub " + topic, "cannot subscribe to %s: %s" % (topic, exc))

    # The readers' threads: what arrived waits for its window.
    def _arrived(self, kind: str, received: Any) -> None:
        with self._wake:
            heapq.heappush(self._waiting, (_stamp(received), next(self._order), time.monotonic(), kind, received))
            self._wake.notify()

    def _publishers(self, server: str, publishers: list[str]) -> None:
        with self._lock:
            gone = [m for (s, p), m in self.machines.items() if s == server and p not in publishers and m.up]
            for machine in gone:
                machine.up = False
                events = machine.follower.end()
                if events:
                    self._deliver(events)
                self._seen(machine.name, False)

    def _publishing(self, server: str, publisher: str) -> bool:
        """Whether ``publisher`` is connected on ``server``'s status topic now."""
        subscription = self._subscriptions.get(server + STATUS_SUFFIX)
        return subscription is not None and publisher in subscription.publishers

    # The following thread: messages to the followers, in stamp order, once they waited.
    def _follow(self) -> None:
        waiting = self._waiting
        with self._wake:
            while not self._stopped.is_set():
                if not waiting:
                    self._wake.wait()
                    continue
                ready_at = min(arrived for _, _, arrived, _, _ in waiting) + self._window
                now = time.monotonic()
                if now < ready_at:
                    self._wake.wait(ready_at - now)
                    continue
                due = [item for item in waiting if item[2] + self._window <= now]
                latest = max(item[0] for item in due)
                released = sorted(item for item in waiting if item[2] + self._window <= now or item[0] <= latest)
                kept = [item for item in waiting if not (item[2] + self._window <= now or item[0] <= latest)]
                waiting[:] = kept
                heapq.heapify(waiting)
                for _, _, _, kind, received in released:
                    self._feed(kind, received, _stamp(received))

    def _feed(self, kind: str, received: Any, stamp: float) -> None:
        fields = dict(received.fields)
        if kind == "log":
            line = {"msg": fields.get("msg", ""), "level": fields.get("level", 0), "name": fields.get("name", "")}
            for machine in self.machines.values():
                if received.publisher == machine.publisher or _same_node(machine.publisher, line["name"]):
                    self._give(machine, Message(stamp, machine.server, "log", line, line["name"]))
            return
        topic = received.topic
        server = topic[:-len(STATUS_SUFFIX if kind == "status" else STRUCTURE_SUFFIX)]
        fields = introspection_fields(fields.__getitem__, kind)
        key = (server, received.publisher)
        machine = self.machines.get(key)
        if machine is None:
            name = names.unique(server.strip("/") or "smach", self._taken)
            self._taken.add(name)
            machine = self.machines[key] = Machine(name, server, received.publisher, Follower(server, name),
                                                   self._stop_topic(name))
            threading.Thread(target=self._advertise_controls, args=(machine,), name="fsmscope-ros-advertise",
                             daemon=True).start()
        elif not machine.up and self._publishing(server, received.publisher):
            machine.up = True  # not by a message that waited for its window after its publisher went away
            self._seen(machine.name, True)
        self._give(machine, Message(stamp, server, kind, fields, received.publisher))

    def _give(self, machine: Machine, message: Message) -> None:
        try:
            events = machine.follower.feed(message)
        except Exception as exc:  # a message the converter cannot take: said, the others go on
            self._once("feed " + machine.name, "a %s message of %s was not understood: %s: %s"
                       % (message.kind, machine.name, type(exc).__name__, exc))
            return
        if events:
            self._deliver(events)

    def _once(self, key: str, text: str) -> None:
        if key not in self._told:
            self._told.add(key)
            self._said(text)


def _stamp(received: Any) -> float:
    """A message's time: its header's stamp (the robot's clock), else when it arrived."""
    return received.stamp if received.stamp else received.t


def _same_node(publisher: str, logger: str) -> bool:
    """Whether a /rosout line's ``name`` is the status publisher's node: a line that came through
    another node (/rosout_agg's aggregator) still names its own (ROS 1 names both "/robot1")."""
    return publisher.strip("/") == logger.strip("/")
