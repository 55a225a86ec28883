"""What the commands that serve a dashboard share: the ``--host/--port/--token`` arguments, starting
the server from them, and serving until Ctrl-C."""

from __future__ import annotations

import argparse
import os
import sys
import threading
from typing import TYPE_CHECKING, Any

from fsm.control.frames import DEADMAN_ACTIONS
from fsmscope.interop.foxglove_door import FOXGLOVE_WEB_APP

from ..lease import Deadman
from .cannot_serve import CannotServe

if TYPE_CHECKING:
    from ..http_server import ServerThread


def add_server_arguments(parser: argparse.ArgumentParser, default_port: int) -> None:
    parser.add_argument("--host", default="127.0.0.1",
                        help="address to listen on (default 127.0.0.1; any other needs a token)")
    parser.add_argument("--port", type=int, default=default_port,
                        help="port (default %d%s)" % (default_port, "; 0 picks a free one" if default_port else
                                                      ", a free one"))
    parser.add_argument("--token", default=os.environ.get("FSMSCOPE_TOKEN"),
                        help="the access token (default: $FSMSCOPE_TOKEN, else a random one per run)")
    parser.add_argument("--viewer", action="store_true",
                        help="also print a URL to share with someone who may watch and not control (a viewer's "
                             "token, random per run)")
    parser.add_argument("--deadman", type=float, default=Deadman.after, metavar="SECONDS",
                        help="when the page in control sends no heartbeat for this long, the machine does "
                             "--deadman-action (default %(default)s)")
    parser.add_argument("--deadman-action", choices=DEADMAN_ACTIONS, default=Deadman.action,
                        help="what the machine does then: pause (default), preempt, or none")
    parser.add_argument("--foxglove", type=int, metavar="PORT",
                        help="also serve the Foxglove WebSocket protocol on this port (0: a free one), on 127.0.0.1 "
                             "only (it has no token): each machine's events and active states, the log, the "
                             "arm's frames")
    parser.add_argument("--foxglove-origin", action="append", metavar="ORIGIN",
                        help="a web page's origin that may connect to --foxglove besides Foxglove's web app "
                             "(%s), e.g. null for a local file's page; repeatable" % FOXGLOVE_WEB_APP)
    parser.add_argument("--foxglove-host", action="append", metavar="NAME",
                        help="a Host name that --foxglove answers besides the loopback's (127.0.0.1, localhost, "
                             "::1); repeatable")


SERVER_OPTIONS = ("host", "port", "token", "viewer", "deadman", "deadman_action")  # the dashboard's
FOXGLOVE_OPTIONS = ("foxglove_origin", "foxglove_host")  # --foxglove's


def foxglove_unused(args: argparse.Namespace, given: set[str]) -> str | None:
    """``--foxglove``'s options without ``--foxglove``."""
    return given_of(given, FOXGLOVE_OPTIONS, "needs --foxglove PORT") if args.foxglove is None else None


def given_of(given: set[str], options: tuple[str, ...], why: str) -> str | None:
    """``--OPTION ... why`` for those of ``options`` that were ``given``; None when none was."""
    found = ["--" + o.replace("_", "-") for o in options if o in given]
    return "%s %s" % (", ".join(found), why) if found else None


def start_server(args: argparse.Namespace, **options: Any) -> ServerThread:
    """The dashboard's server on ``--host/--port/--token``, started (and, with ``--foxglove``, the
    Foxglove server fed from its hub); ``options`` go to ``ServerThread`` (``scene_url``,
    ``show_pose``). Raises CannotServe."""
    from ..http_server import ServerThread

    try:
        srv = ServerThread(host=args.host, port=args.port, token=args.token or None,
                           deadman=Deadman(args.deadman, args.deadman_action), **options).start()
    except (ValueError, OSError) as exc:
        raise CannotServe(str(exc)) from exc
    if args.foxglove is not None:
        from .foxglove_bridge import start_foxglove

        try:
            start_foxglove(args, srv.hub)
        except CannotServe:
            srv.stop()
            raise
    return srv


def announce_viewer(args: argparse.Namespace, srv: ServerThread) -> None:
    """With --viewer, the watch-only URL on stderr (the operator's was printed just before)."""
    if args.viewer:
        print("fsmscope: viewer (watch only) at %s" % srv.viewer_url, file=sys.stderr, flush=True)


INTERRUPT_CHECK = 0.2  # s between two looks for a Ctrl-C that reached another thread (wait_for_interrupt)
SWITCH_INTERVAL = 0.0005  # s a thread may hold the GIL while another waits for it (Python's default: 5 ms)


def wait_for_interrupt(announcement: str) -> None:
    """Say ``announcement`` (the line that says Ctrl-C stops) on stderr, then wait for Ctrl-C. The
    line is written inside the wait's guard: a Ctrl-C sent as soon as it is read stops the command as
    cleanly as one sent later. The wait wakes every ``INTERRUPT_CHECK`` seconds: the kernel may hand the
    signal to another of the process's threads (the server's), and a wait with no end in the main
    thread would then never return to run Python's handler."""
    never = threading.Event()
    try:
        print(announcement, file=sys.stderr, flush=True)
        while not never.wait(INTERRUPT_CHECK):
            pass
    except KeyboardInterrupt:
        pass
