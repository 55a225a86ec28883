"""A ROS 2 publisher: one DDS writer of one message type on one topic, as rmw makes it (reliable,
volatile, keep last 10, XCDR1), so that a robot's rclpy subscription receives what it writes.

DDS delivers a volatile message only to the subscriptions matched when it is written, as ROS 2
does: advertise ahead (``subscribers`` lists those matched) rather than just before
publishing.
"""

from __future__ import annotations

from typing import Any

from cyclonedds.core import DDSException
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.topic import Topic

from fsmscope.ros2.dds import WRITER_QOS, delete
from fsmscope.ros2.messages import from_fields


class Publisher:
    """Messages of one type, published on one topic."""

    def __init__(self, participant: DomainParticipant, dds_topic: Topic, topic: str, type_name: str) -> None:
        """A writer of ``dds_topic`` (``topic``'s, of ``type_name``'s class) in ``participant``."""
        self.topic = topic
        self.type_name = type_name
        self._class = dds_topic.data_type
        self._writer = DataWriter(participant, dds_topic, qos=WRITER_QOS)

    def publish(self, fields: dict[str, Any]) -> None:
        """Publish a message given as a dict (members left out are zero); ValueError for a member the
        message lacks or a value its type cannot hold."""
        message = from_fields(self._class, fields)
        try:
            self._writer.write(message)
        except DDSException:
            raise
        except Exception as exc:  # cyclonedds's serializer: a str where a number goes, a number > 255 in uint8[] ...
            raise ValueError(f"cannot write {fields!r} as {self.type_name}: {type(exc).__name__}: {exc}") from exc

    @property
    def subscribers(self) -> list[str]:
        """The subscriptions (readers) this publisher is matched with now, by their instance handles (as
        fsmscope.ros1's ``Publication.subscribers`` lists its subscribers)."""
        return [str(handle) for handle in self._writer.get_matched_subscriptions()]

    def close(self) -> None:
        delete(self._writer)
