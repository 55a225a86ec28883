"""An MCAP file's header, read to tell what wrote it (a ROS 2 bag's "ros2" profile, fsmscope's own
library) before choosing how to read the file."""

from __future__ import annotations

from mcap.reader import make_reader
from mcap.records import Header


def mcap_header(path: str) -> Header | None:
    """The header of the MCAP file at ``path``; None when it is no readable MCAP."""
    try:
        with open(path, "rb") as f:
            return make_reader(f).get_header()
    except Exception:  # not an MCAP at all, or unreadable: the caller reads it another way or says so
        return None
