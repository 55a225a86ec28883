"""Where fsmscope's DDS participant talks: a Cyclone DDS configuration for one network interface.

With no interface, Cyclone's own defaults apply (or the XML that ``CYCLONEDDS_URI`` names, as on a
ROS 2 machine that uses rmw_cyclonedds): discovery by multicast on the default interface, which is
what a ROS 2 robot does by default. With an interface, only that one is used; on the loopback, or
when peers are given, discovery is by unicast to the peers (multicast off), which is how a network
without multicast (many Wi-Fi networks, containers, the tests) is used with ROS 2 as well. In unicast
discovery Cyclone probes each peer's ports of participant indexes 0..MAX_PARTICIPANTS-1, so up to
that many participants per machine and domain are found (every ROS 2 process is one).
"""

from __future__ import annotations

import re
from xml.sax.saxutils import quoteattr

MAX_PARTICIPANTS = 32
# DDS's port mapping (7400 + 250 * domain + ...) leaves domains 0..232 under 65536.
MAX_DOMAIN_ID = 232
_ADDRESS = re.compile(r"^[A-Za-z0-9_.:%-]{1,255}$")


def check_domain_id(domain_id: int) -> int:
    if not isinstance(domain_id, int) or isinstance(domain_id, bool) or not 0 <= domain_id <= MAX_DOMAIN_ID:
        raise ValueError(f"a ROS 2 domain id is an integer from 0 to {MAX_DOMAIN_ID}, not {domain_id!r}")
    return domain_id


def _address(value: str, what: str) -> str:
    if not _ADDRESS.match(value):
        raise ValueError(f"not a network {what}: {value!r}")
    return quoteattr(value)


def cyclone_config(interface: str | None, peers: list[str] | None = None) -> str:
    """Cyclone's XML for a participant on ``interface`` (an address or an interface's name, None for
    Cyclone's choice) that discovers others by unicast to ``peers`` when given (multicast off); on
    the loopback the peer is the loopback itself unless ``peers`` says otherwise."""
    if peers is None and interface is not None and (interface.startswith("127.") or interface in ("lo", "localhost")):
        peers = ["127.0.0.1"]
    general = "<AllowMulticast>false</AllowMulticast>" if peers else ""
    if interface is not None:
        attribute = "address" if re.match(r"^[0-9.:]+$", interface) else "name"
        general = f"<Interfaces><NetworkInterface {attribute}={_address(interface, 'interface')}/></Interfaces>" + general
    discovery = ""
    if peers:
        listed = "".join(f"<Peer address={_address(peer, 'peer')}/>" for peer in peers)
        discovery = (f"<Discovery><ParticipantIndex>auto</ParticipantIndex>"
                     f"<MaxAutoParticipantIndex>{MAX_PARTICIPANTS - 1}</MaxAutoParticipantIndex>"
                     f"<Peers>{listed}</Peers></Discovery>")
    return f'<CycloneDDS><Domain id="any"><General>{general}</General>{discovery}</Domain></CycloneDDS>'
