"""fsmscope's ROS 2 node: one DDS participant on a ROS 2 domain, with no ROS installed.

It finds what is published from DDS's own discovery (the DCPSPublication builtin topic: every
writer of every participant on the domain, its topic and type names), subscribes and publishes
with ROS 2's names (fsmscope.ros2.names), QoS and layouts (fsmscope.ros2.messages).
"""

from __future__ import annotations

import threading
from typing import Any, Callable

from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication
from cyclonedds.core import DDSException, InstanceState, ReadCondition, SampleState, ViewState
from cyclonedds.domain import Domain, DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.topic import Topic

from fsmscope.ros2.config import check_domain_id, cyclone_config
from fsmscope.ros2.dds import delete
from fsmscope.ros2.messages import message_class
from fsmscope.ros2.names import dds_topic, ros_topic, ros_type
from fsmscope.ros2.publisher import Publisher
from fsmscope.ros2.subscription import Received, Subscription

MAX_PUBLICATIONS = 65536


class Node:
    """A participant on ROS 2 domain ``domain_id``.

    ``interface`` (an address or an interface's name) restricts it to one network interface; on the
    loopback (``"127.0.0.1"``) discovery is by unicast to the loopback, multicast off. ``peers``
    makes discovery unicast to those addresses on any interface (fsmscope.ros2.config). With neither,
    Cyclone DDS's defaults apply, or the configuration ``CYCLONEDDS_URI`` names: multicast discovery,
    as a ROS 2 robot does by default. A process configures a domain id once: Nodes on the same
    domain id in one process share the first one's configuration."""

    def __init__(self, domain_id: int = 0, interface: str | None = None, peers: list[str] | None = None) -> None:
        check_domain_id(domain_id)
        self.domain_id = domain_id
        self._configured = interface is not None or bool(peers)
        if self._configured:
            _configure(domain_id, cyclone_config(interface, peers))
        self.participant = DomainParticipant(domain_id)
        self._lock = threading.Lock()
        self._topics: dict[tuple[str, type], Topic] = {}
        self._subscriptions: list[Subscription] = []
        self._publishers: list[Publisher] = []
        self._publications = BuiltinDataReader(self.participant, BuiltinTopicDcpsPublication)
        self._alive = ReadCondition(self._publications, SampleState.Any | ViewState.Any | InstanceState.Alive)

    def topic(self, ros_name: str, message_class: type[IdlStruct]) -> Topic:
        """The DDS topic of a ROS topic and message class (one per pair, shared by readers and writers)."""
        name = dds_topic(ros_name)
        with self._lock:
            if (name, message_class) not in self._topics:
                self._topics[(name, message_class)] = Topic(self.participant, name, message_class)
            return self._topics[(name, message_class)]

    def publications(self, ros_name: str | None = None) -> list[Any]:
        """Every writer on the domain discovered and alive now (cyclonedds's DcpsEndpoint: key,
        participant_key, topic_name, type_name, qos), or those on one ROS topic."""
        with self._lock:
            found = self._publications.read(N=MAX_PUBLICATIONS, condition=self._alive)
        if ros_name is None:
            return found
        name = dds_topic(ros_name)
        return [publication for publication in found if publication.topic_name == name]

    def published_topics(self) -> dict[str, str]:
        """ROS topic -> ROS type, for every ROS topic some participant on the domain publishes now
        (this node's own writers too). A topic published with several types shows the first in
        sorted order; a subscription says which others it does not receive (``problems``)."""
        topics: dict[str, str] = {}
        for publication in sorted(self.publications(), key=lambda p: p.type_name):
            name = ros_topic(publication.topic_name)
            if name is not None:
                topics.setdefault(name, ros_type(publication.type_name))
        return topics

    def subscribe(self, topic: str, type_name: str, on_message: Callable[[Received], None],
                  on_publishers: Callable[[list[str]], None] | None = None) -> Subscription:
        """Receive ``type_name`` messages on ``topic`` (fsmscope.ros2.subscription says how)."""
        dds_topic = self.topic(topic, message_class(type_name))
        subscription = Subscription(self.participant, dds_topic, topic, type_name, self.publications, on_message,
                                    on_publishers)
        with self._lock:
            self._subscriptions.append(subscription)
        return subscription

    def advertise(self, topic: str, type_name: str) -> Publisher:
        """A publisher of ``type_name`` messages on ``topic``."""
        publisher = Publisher(self.participant, self.topic(topic, message_class(type_name)), topic, type_name)
        with self._lock:
            self._publishers.append(publisher)
        return publisher

    def close(self) -> None:
        """Close every subscription and publisher and leave the domain (the others see this node's
        writers go at once)."""
        with self._lock:
            subscriptions, self._subscriptions = self._subscriptions, []
            publishers, self._publishers = self._publishers, []
        for subscription in subscriptions:
            subscription.close()
        for publisher in publishers:
            publisher.close()
        delete(self.participant)
        if self._configured:
            _release(domain_id=self.domain_id)


# A configured domain of this process -> (its Domain entity, the Nodes using it). Deleting a Domain
# deletes every participant in it, so it goes with the last Node that configured it.
_domains: dict[int, list[Any]] = {}
_domains_lock = threading.Lock()


def _configure(domain_id: int, config: str) -> None:
    with _domains_lock:
        if domain_id in _domains:
            _domains[domain_id][1] += 1
            return
        try:
            _domains[domain_id] = [Domain(domain_id, config), 1]
        except DDSException:
            _domains[domain_id] = [None, 1]  # joined by a participant of Cyclone's default configuration first


def _release(domain_id: int) -> None:
    with _domains_lock:
        entry = _domains[domain_id]
        entry[1] -= 1
        if entry[1] == 0:
            del _domains[domain_id]
            delete(entry[0])
