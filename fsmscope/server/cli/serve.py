"""``fsmscope serve``: a standalone dashboard that machines of other processes publish to
(``server.publisher.Publisher`` posting to /api/ingest), and, with ``--zenoh``, that follows the
fleet's robots on Zenoh (fleet_bridge.py)."""

from __future__ import annotations

import argparse
import sys

from .zenoh_options import ZENOH_OPTIONS, add_zenoh_arguments
from .cannot_serve import CannotServe
from .serving import add_server_arguments, announce_viewer, foxglove_unused, given_of, start_server, wait_for_interrupt

HELP = "serve the dashboard for machines of other processes (they publish to /api/ingest)"
PASSES_ARGUMENTS_ON = False
DEFAULT_PORT = 8765


def arguments(parser: argparse.ArgumentParser) -> None:
    add_server_arguments(parser, DEFAULT_PORT)
    add_zenoh_arguments(parser, publish=False)


def unused(args: argparse.Namespace, given: set[str]) -> str | None:
    zenoh = given_of(given, ZENOH_OPTIONS, "needs --zenoh") if args.zenoh is None else None
    return zenoh or foxglove_unused(args, given)


def main(args: argparse.Namespace) -> int:
    srv = start_server(args)
    if args.zenoh is not None:
        from .fleet_bridge import start_fleet

        try:
            start_fleet(args, srv.hub)
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
