"""``--zenoh`` as the commands take it: its options, the robot they describe for ``run`` and ``demo``
(``fleet.robot.ZenohRobot``, which puts the machines on Zenoh as that robot's), and the line that
says where a command's Zenoh session meets the others. ``serve``'s side, the dashboard following
the fleet, is fsmscope/server/cli/fleet_bridge.py; Zenoh itself is imported only when a command uses it."""

from __future__ import annotations

import argparse
import os
import sys
from typing import TYPE_CHECKING

from .cannot_serve import CannotServe

if TYPE_CHECKING:
    from fsmscope.fleet.robot import ZenohRobot

    from ..hub import MachineEntry


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
    parser.add_argument("--zenoh-token", action="append", default=[], metavar="[ROBOT=]TOKEN",
                        help=("with --zenoh: the token the robot's batches and answers prove, and dashboards' "
                              "controls must prove (default: $%s; none: a new one, printed)" % TOKEN_ENV) if publish else
                             ("with --zenoh: the token of the robots whose machines are shown and controlled; "
                              "ROBOT=TOKEN for one robot's (default: $%s; a robot without one is not shown)"
                              % TOKEN_ENV))
    parser.add_argument("--zenoh-mode", choices=("peer", "client"), default="peer",
                        help="with --zenoh: peer (default; a robot connecting to a router stays one), or client of "
                             "a router (a dashboard behind one)")
    parser.add_argument("--zenoh-scouting", action="store_true",
                        help="with --zenoh: find the others on the LAN by multicast (off unless asked)")
    parser.add_argument("--zenoh-config", type=zenoh_config_file, metavar="FILE",
                        help="with --zenoh: a Zenoh configuration file (JSON5) for the rest, such as TLS "
                             "certificates for tls/ endpoints; the options above are applied over it")


def zenoh_config_file(path: str) -> str:
    """``--zenoh-config``'s check: a file Zenoh reads as its configuration (else the command says why)."""
    from fsmscope.fleet.config import read_config_file

    try:
        read_config_file(path)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return path


TOKEN_ENV = "FSMSCOPE_ZENOH_TOKEN"
ZENOH_OPTIONS = ("zenoh_connect", "zenoh_listen", "zenoh_token", "zenoh_mode", "zenoh_scouting", "zenoh_config")


def zenoh_tokens(args: argparse.Namespace) -> dict[str | None, str]:
    """The tokens of ``--zenoh-token`` by robot (None: any robot's), with $FSMSCOPE_ZENOH_TOKEN for any."""
    tokens: dict[str | None, str] = {}
    if os.environ.get(TOKEN_ENV):
        tokens[None] = os.environ[TOKEN_ENV]
    for value in args.zenoh_token:
        robot, _, token = value.rpartition("=")
        tokens[robot or None] = token
    return tokens


def zenoh_robot(args: argparse.Namespace, can_start: bool) -> ZenohRobot | None:
    """With ``--zenoh ROBOT``: the observer that publishes machines as that robot's, taking the
    controls that carry its token; else None."""
    if args.zenoh is None:
        return None
    from fsmscope.fleet.robot import ZenohRobot

    try:  # given no token, the robot makes one and says it
        robot = ZenohRobot(args.zenoh, connect=args.zenoh_connect, listen=args.zenoh_listen, mode=args.zenoh_mode,
                           scouting=args.zenoh_scouting, token=zenoh_tokens(args).get(None), can_start=can_start,
                           config_file=args.zenoh_config)
    except ValueError as exc:  # a name Zenoh cannot take, an endpoint it cannot use
        raise CannotServe(str(exc)) from None
    print("fsmscope: publishing on Zenoh as robot %r (%s)" % (args.zenoh, reach(args.zenoh_connect, args)),
          file=sys.stderr, flush=True)
    return robot


def robot_follows(robot: ZenohRobot, entry: MachineEntry) -> None:
    """A machine this process's dashboard serves too: the robot publishes the events the hub encodes
    anyway (a sink of its feed, rather than observing the machine itself), applies the dashboards'
    controls through the hub's handle, and answers state queries from the hub's Status."""
    feed = entry.feed
    feed.add_encoded_sink(robot.follow(entry.name, entry.local.handle, feed.lock, lambda: feed.status))


def reach(connect: list[str], args: argparse.Namespace) -> str:
    """Where the command's Zenoh session meets the others, for the line it starts with: a session
    given no endpoint, no scouting and no configuration file meets nobody, and says so."""
    parts = (["connect " + e for e in connect] + ["listen " + e for e in args.zenoh_listen]
             + (["multicast scouting"] if args.zenoh_scouting else [])
             + (["configured by " + args.zenoh_config] if args.zenoh_config else []))
    return ", ".join(parts) or "no endpoint and no scouting: it meets nobody"
