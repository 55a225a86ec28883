"""``fsmscope serve`` (a standalone server that other processes publish to) and the dashboard of ``fsmscope run``."""

from __future__ import annotations

import argparse
import os
import sys
import threading
from typing import Any

DEFAULT_PORT = 8765


def add_server_arguments(parser: argparse.ArgumentParser, default_port: int) -> None:
    parser.add_argument("--host", default="127.0.0.1",
                        help="address to listen on (default 127.0.0.1; any other needs a token)")
    parser.add_argument("--port", type=int, default=default_port,
                        help="port (default %d%s)" % (default_port, "; 0 picks a free one" if default_port else
                                                      ", a free one"))
    parser.add_argument("--token", default=os.environ.get("FSMSCOPE_TOKEN"),
                        help="the access token (default: $FSMSCOPE_TOKEN, else a random one per run)")


def start_server(args: argparse.Namespace) -> Any:
    from .introspection_server import ServerThread

    return ServerThread(host=args.host, port=args.port, token=args.token or None).start()


def wait_for_interrupt() -> None:
    try:
        threading.Event().wait()
    except KeyboardInterrupt:
        pass


def serve(args: argparse.Namespace) -> int:
    try:
        srv = start_server(args)
    except (ValueError, OSError) as exc:
        print("fsmscope serve: %s" % exc, file=sys.stderr)
        return 1
    print("fsmscope: serving the dashboard at %s" % srv.url, file=sys.stderr)
    print("fsmscope: other processes publish with server.publisher.Publisher(%r, %r); Ctrl-C stops"
          % (srv.base_url, srv.token), file=sys.stderr, flush=True)
    wait_for_interrupt()
    srv.stop()
    return 0


def run_with_dashboard(args: argparse.Namespace, runner: Any) -> int:
    """``fsmscope run``: serve every machine the script runs; keep serving afterwards unless --exit."""
    try:
        srv = start_server(args)
    except (ValueError, OSError) as exc:
        print("fsmscope run: %s" % exc, file=sys.stderr)
        return 1
    hub = srv.hub
    runner.on_machine.append(lambda name, container: hub.add_local(container, name=name, can_start=True))
    runner.keep_open = True  # runs started from the dashboard after the script ends are recorded too
    print("fsmscope: dashboard at %s" % srv.url, file=sys.stderr, flush=True)
    try:
        code = runner.run()
        if not args.exit:
            print("fsmscope: the script ended (exit code %d); still serving at %s (Ctrl-C stops)"
                  % (code, srv.url), file=sys.stderr, flush=True)
            wait_for_interrupt()
    finally:
        srv.stop()
        runner.close()
    return code
