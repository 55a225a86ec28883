"""``--zenoh`` of the commands: ``run`` and ``demo`` publish their machines as a robot's
(``fleet.robot.ZenohRobot``); ``serve`` shows the fleet's machines in the dashboard. A ``fleet.watcher.FleetWatcher``
follows every robot's machines on Zenoh; what it delivers goes through the hub's ingest door (each
event checked against the schema, as a publisher's are) on the server's event loop, and a machine
whose liveliness token is withdrawn is shown disconnected (``connected: false``) until it is back."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from fleet.robot import ZenohRobot
    from fleet.watcher import FleetWatcher

    from ..hub import Hub


def add_zenoh_arguments(parser: argparse.ArgumentParser, publish: bool) -> None:
    """``publish`` (run, demo): ``--zenoh ROBOT`` puts the machines on Zenoh as that robot's; else
    (serve): ``--zenoh [ENDPOINT ...]`` follows the fleet."""
    if publish:
        parser.add_argument("--zenoh", metavar="ROBOT",
                            help="also publish the machines on Zenoh as this robot's (docs/fleet.md)")
        parser.add_argument("--zenoh-connect", action="append", default=[], metavar="ENDPOINT",
                            help="with --zenoh: connect to this endpoint (tcp/HOST:PORT: a dashboard's or a router's)")
    else:
        parser.add_argument("--zenoh", nargs="*", metavar="ENDPOINT",
                            help="follow the fleet's machines on Zenoh, connecting to these endpoints (tcp/HOST:PORT: "
                                 "a robot's, or a zenohd router's); none: only --zenoh-listen and --zenoh-scouting")
    parser.add_argument("--zenoh-listen", action="append", default=[], metavar="ENDPOINT",
                        help="with --zenoh: also listen on this endpoint, for sessions that connect here")
    parser.add_argument("--zenoh-mode", choices=("peer", "client"), default="peer",
                        help="with --zenoh: peer (default), or client of a zenohd router")
    parser.add_argument("--zenoh-scouting", action="store_true",
                        help="with --zenoh: find the others on the LAN by multicast (off unless asked)")


def zenoh_robot(args: argparse.Namespace) -> ZenohRobot | None:
    """With ``--zenoh ROBOT``: the observer that publishes machines as that robot's; else None."""
    if args.zenoh is None:
        return None
    from fleet.robot import ZenohRobot

    robot = ZenohRobot(args.zenoh, connect=args.zenoh_connect, listen=args.zenoh_listen, mode=args.zenoh_mode,
                       scouting=args.zenoh_scouting)
    print("fsmscope: publishing on Zenoh as robot %r" % args.zenoh, file=sys.stderr, flush=True)
    return robot


def start_fleet(args: argparse.Namespace, hub: Hub) -> FleetWatcher:
    """The watcher, feeding ``hub`` on its loop until the process ends."""
    from fleet.watcher import FleetWatcher

    loop = hub.loop
    alive: dict[str, bool] = {}

    def ingest(event: dict) -> None:
        problem = hub.ingest(event, "ingest")
        if problem:
            print("fsmscope serve: refused an event of %s from Zenoh: %s" % (event.get("machine"), problem),
                  file=sys.stderr, flush=True)
            return
        entry = hub.get(event["machine"])
        if entry is not None:
            entry.connected = alive.get(entry.name, True)

    def seen(name: str, up: bool) -> None:
        alive[name] = up
        entry = hub.get(name)
        if entry is not None:
            entry.connected = up

    watcher = FleetWatcher(lambda event: loop.call_soon_threadsafe(ingest, event),
                           lambda name, up: loop.call_soon_threadsafe(seen, name, up),
                           connect=args.zenoh, listen=args.zenoh_listen, mode=args.zenoh_mode,
                           scouting=args.zenoh_scouting)
    print("fsmscope: following the fleet on Zenoh (%s)" % ", ".join(
        ["connect " + e for e in args.zenoh] + ["listen " + e for e in args.zenoh_listen]
        + (["multicast scouting"] if args.zenoh_scouting else [])) or "no endpoint", file=sys.stderr, flush=True)
    return watcher
