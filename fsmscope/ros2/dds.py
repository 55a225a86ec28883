"""What fsmscope's readers and writers share of cyclonedds: ROS 2's default QoS, and deleting an
entity when fsmscope is done with it rather than when Python collects it."""

from __future__ import annotations

from typing import Any

from cyclonedds.core import Policy, Qos
from cyclonedds.util import duration

# rmw's default profile (rmw_qos_profile_default): reliable, volatile, keep last 10. A reliable
# reader matches reliable writers only, a volatile one both volatile and transient-local writers
# (smach_ros's publishers are reliable and volatile, /rosout's reliable and transient-local).
READER_QOS = Qos(
    Policy.Reliability.Reliable(duration(milliseconds=100)),
    Policy.Durability.Volatile,
    Policy.History.KeepLast(10),
)
# Written as XCDR1, the plain CDR every rmw reads (rmw_cyclonedds and Fast DDS write and expect it).
WRITER_QOS = Qos(
    Policy.Reliability.Reliable(duration(milliseconds=100)),
    Policy.Durability.Volatile,
    Policy.History.KeepLast(10),
    Policy.DataRepresentation(use_cdrv0_representation=True),
)

# DDS's QoS policy ids, for saying which policy made a publisher incompatible.
POLICY_NAMES = {2: "durability", 3: "presentation", 4: "deadline", 5: "latency budget", 6: "ownership",
                8: "liveliness", 10: "partition", 11: "reliability", 12: "destination order",
                13: "history", 14: "resource limits", 23: "data representation", 24: "type consistency"}


def delete(*entities: Any) -> None:
    """Delete DDS entities now (with their children). cyclonedds deletes an entity when its Python
    object is collected (its ``__del__``), which may be never for an object a thread still holds;
    that is the one way it offers, and calling it twice is harmless."""
    for entity in entities:
        if entity is not None:
            entity.__del__()
