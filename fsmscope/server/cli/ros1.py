"""``fsmscope ros1``: every SMACH machine that smach_ros's IntrospectionServer publishes on a ROS 1
master, live on the dashboard and in a recording, with no ROS on this computer (docs/ros.md)."""

from __future__ import annotations

import argparse
import os
from typing import Any

from .ros_live import add_live_arguments, add_recording_arguments, join, serve_live, unused_live
from .serving import add_server_arguments, foxglove_unused

HELP = "show and record the SMACH machines of a live ROS 1 robot (its master's IntrospectionServers)"
PASSES_ARGUMENTS_ON = False
DEFAULT_PORT = 8765
DEFAULT_MASTER = "http://localhost:11311/"


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--master", metavar="URI", default=os.environ.get("ROS_MASTER_URI", DEFAULT_MASTER),
                        help="the ROS master (default: $ROS_MASTER_URI, else %s)" % DEFAULT_MASTER)
    add_ros_host_argument(parser)
    add_recording_arguments(parser)
    add_live_arguments(parser)
    add_server_arguments(parser, DEFAULT_PORT)


def add_ros_host_argument(parser: argparse.ArgumentParser | argparse._ArgumentGroup) -> None:
    """The address the master and the robots reach this computer's node at."""
    parser.add_argument("--ros-host", default=os.environ.get("ROS_IP") or os.environ.get("ROS_HOSTNAME") or "127.0.0.1",
                        help="the address this computer's ROS node is reached at by the master and the robots "
                             "(default: $ROS_IP, else $ROS_HOSTNAME, else 127.0.0.1: this computer only)")


def unused(args: argparse.Namespace, given: set[str]) -> str | None:
    return unused_live(args, given) or foxglove_unused(args, given)


def graph(master: str, host: str) -> tuple[str, Any, Any]:
    """The master's graph in words, a node that joined it, ROS 1's flavour; CannotServe saying why not."""
    from fsmscope.interop.ros_watcher import ROS1
    from fsmscope.ros1 import Node

    return join("the ROS 1 master at %s" % master, lambda: Node(master, host=host), ROS1)


def main(args: argparse.Namespace) -> int:
    return serve_live(args, lambda: graph(args.master, args.ros_host))
