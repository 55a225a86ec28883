"""``fsmscope router``: a Zenoh router for a site's robots and dashboards, for a computer without
``zenohd`` (Zenoh's router is a Rust program, not a Python package). It is a Zenoh session in
router mode: the routing code ``zenohd`` runs, without zenohd's plugins (REST, storages). Robots
connect to it as peers (``--zenoh-connect tcp/ROUTER:7447``), dashboards as its clients (``--zenoh
tcp/ROUTER:7447 --zenoh-mode client``); routers of other sites are joined with ``--connect``
(docs/fleet.md, "Robots behind a zenohd router")."""

from __future__ import annotations

import argparse

from .zenoh_options import zenoh_config_file
from .cannot_serve import CannotServe
from .serving import wait_for_interrupt

HELP = "route Zenoh for a fleet's robots and dashboards (a stand-in for zenohd)"
PASSES_ARGUMENTS_ON = False
DEFAULT_LISTEN = "tcp/127.0.0.1:7447"


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--listen", action="append", default=[], metavar="ENDPOINT",
                        help="listen on this endpoint for robots, dashboards and other routers (default: %s; "
                             "tcp/0.0.0.0:7447 for a site's network)" % DEFAULT_LISTEN)
    parser.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                        help="connect to another site's router at this endpoint (tcp/HOST:PORT)")
    parser.add_argument("--scouting", action="store_true",
                        help="find peers on the LAN by multicast (off unless asked)")
    parser.add_argument("--zenoh-config", type=zenoh_config_file, metavar="FILE",
                        help="a Zenoh configuration file (JSON5): TLS certificates for tls/ endpoints, access "
                             "control; the options above are applied over it")


def main(args: argparse.Namespace) -> int:
    from fsmscope.fleet.config import open_session

    listen = args.listen or [DEFAULT_LISTEN]
    try:
        session = open_session(args.connect, listen, "router", args.scouting, args.zenoh_config)
    except ValueError as exc:
        raise CannotServe(str(exc)) from None
    wait_for_interrupt("fsmscope: routing Zenoh on %s; robots connect with --zenoh-connect ENDPOINT, dashboards "
                       "with --zenoh ENDPOINT --zenoh-mode client; Ctrl-C stops" % ", ".join(listen))
    session.close()
    return 0
