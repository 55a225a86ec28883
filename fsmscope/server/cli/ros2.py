"""``fsmscope ros2``: every SMACH machine that the ros2 branch's IntrospectionServer publishes on a ROS 2
network (DDS), live on the dashboard and in a recording, with no ROS on this computer (docs/ros.md)."""

from __future__ import annotations

import argparse
import os
from typing import Any

from .cannot_serve import CannotServe
from .ros_live import add_live_arguments, add_recording_arguments, join, serve_live, unused_live
from .serving import add_server_arguments, foxglove_unused

HELP = "show and record the SMACH machines of a live ROS 2 network (its IntrospectionServers, over DDS)"
PASSES_ARGUMENTS_ON = False
DEFAULT_PORT = 8765


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--domain", type=int, metavar="N", default=int(os.environ.get("ROS_DOMAIN_ID") or 0),
                        help="the ROS 2 domain id (default: $ROS_DOMAIN_ID, else 0)")
    add_interface_argument(parser)
    add_recording_arguments(parser)
    add_live_arguments(parser)
    add_server_arguments(parser, DEFAULT_PORT)


def add_interface_argument(parser: argparse.ArgumentParser | argparse._ArgumentGroup) -> None:
    """The network interface DDS uses."""
    parser.add_argument("--interface", metavar="ADDRESS",
                        help="the network interface's address DDS uses (default: the DDS library's choice; "
                             "127.0.0.1: this computer only)")


def unused(args: argparse.Namespace, given: set[str]) -> str | None:
    return unused_live(args, given) or foxglove_unused(args, given)


def graph(domain: int, interface: str | None) -> tuple[str, Any, Any]:
    """The domain's graph in words, a node that joined it, ROS 2's flavour; CannotServe saying why not."""
    from fsmscope.interop.ros_watcher import ROS2

    try:
        from fsmscope.ros2 import Node
    except ImportError as exc:
        raise CannotServe("ROS 2 needs the cyclonedds package, not installed here (%s): pip installs it with "
                          "fsmscope where it has a wheel (x86_64, Windows, macOS on arm64); elsewhere install Cyclone "
                          "DDS, then `pip install cyclonedds` (docs/ros2.md)" % exc) from None
    return join("the ROS 2 domain %d" % domain, lambda: Node(domain, interface=interface), ROS2)


def main(args: argparse.Namespace) -> int:
    return serve_live(args, lambda: graph(args.domain, args.interface))
