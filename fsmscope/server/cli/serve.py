"""``fsmscope serve``: a standalone dashboard that machines of other processes publish to
(``server.publisher.Publisher`` posting to /api/ingest), and, with ``--zenoh``, that follows the
fleet's robots on Zenoh (fleet_bridge.py), with ``--ros1``/``--ros2`` the SMACH machines of a live
ROS graph (ros_live.py)."""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any, Iterator

from . import ros1, ros2
from .ros_live import add_live_arguments, follow, stop_topics

from .zenoh_options import ZENOH_OPTIONS, add_zenoh_arguments
from .cannot_serve import CannotServe
from .serving import add_server_arguments, announce_viewer, foxglove_unused, given_of, start_server, wait_for_interrupt

HELP = "serve the dashboard for machines of other processes (they publish to /api/ingest)"
PASSES_ARGUMENTS_ON = False
DEFAULT_PORT = 8765


def arguments(parser: argparse.ArgumentParser) -> None:
    add_server_arguments(parser, DEFAULT_PORT)
    add_zenoh_arguments(parser, publish=False)
    ros = parser.add_argument_group("a live ROS graph's SMACH machines (as fsmscope ros1 / ros2)")
    ros.add_argument("--ros1", nargs="?", const=os.environ.get("ROS_MASTER_URI", ros1.DEFAULT_MASTER), metavar="URI",
                     help="also show the machines of this ROS 1 master (no URI: $ROS_MASTER_URI, else %s)"
                          % ros1.DEFAULT_MASTER)
    ros.add_argument("--ros2", nargs="?", type=int, const=int(os.environ.get("ROS_DOMAIN_ID") or 0), metavar="DOMAIN",
                     help="also show the machines of this ROS 2 domain (no DOMAIN: $ROS_DOMAIN_ID, else 0)")
    ros1.add_ros_host_argument(ros)
    ros2.add_interface_argument(ros)
    add_live_arguments(ros)


def unused(args: argparse.Namespace, given: set[str]) -> str | None:
    zenoh = given_of(given, ZENOH_OPTIONS, "needs --zenoh") if args.zenoh is None else None
    ros = (args.ros1 is None and given_of(given, ("ros_host",), "needs --ros1")
           or args.ros2 is None and given_of(given, ("interface",), "needs --ros2")
           or args.ros1 is None and args.ros2 is None and given_of(given, ("stop_topic",), "needs --ros1 or --ros2"))
    return zenoh or ros or foxglove_unused(args, given)


def main(args: argparse.Namespace) -> int:
    topics = stop_topics(args.stop_topic)
    srv = start_server(args)
    try:
        if args.zenoh is not None:
            from .fleet_bridge import start_fleet

            start_fleet(args, srv.hub)
        for graph, node, flavour in ros_graphs(args):
            follow(node, flavour, srv.hub, None, topics)
            print("fsmscope: following the SMACH machines of %s" % graph, file=sys.stderr, flush=True)
    except CannotServe:
        srv.stop()
        raise
    print("fsmscope: serving the dashboard at %s" % srv.url, file=sys.stderr)
    if args.zenoh is not None:
        print("fsmscope: the fleet overview at %s" % (srv.base_url + "/fleet" + ("?token=" + srv.token if srv.token else "")), file=sys.stderr)
    announce_viewer(args, srv)
    wait_for_interrupt("fsmscope: other processes publish with server.publisher.Publisher(%r, %r); Ctrl-C stops"
                       % (srv.base_url, srv.token))
    srv.stop()
    return 0


def ros_graphs(args: argparse.Namespace) -> Iterator[tuple[str, Any, Any]]:
    """Each ROS graph asked for, in words, with the node that joined it and its flavour. Raises CannotServe."""
    if args.ros1 is not None:
        yield ros1.graph(args.ros1, args.ros_host)
    if args.ros2 is not None:
        yield ros2.graph(args.ros2, args.interface)
