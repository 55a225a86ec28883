"""``fsmscope serve`` (a standalone server that other processes publish to) and the dashboard of ``fsmscope run``."""

from __future__ import annotations

import argparse
import os
import sys
import threading
import time
from typing import Any

DEFAULT_PORT = 8765
MAX_GAP = 2.0  # seconds: the longest a browser replay waits between two events


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
    """``fsmscope run``: serve every machine the script runs; keep serving afterwards unless --exit,
    or unless a signal (Ctrl-C, SIGTERM) ended the script: one signal stops everything."""
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
        if not args.exit and runner.signalled is None:
            print("fsmscope: the script ended (exit code %d); still serving at %s (Ctrl-C stops)"
                  % (code, srv.url), file=sys.stderr, flush=True)
            wait_for_interrupt()
    finally:
        srv.stop()
        runner.close()
    return code


def _sleep_until_due(start: float, offset: float) -> float:
    """Sleep until ``start + offset`` (monotonic), waiting MAX_GAP at the most: a long idle gap
    in a log is shortened, and the returned start shifts by what was skipped."""
    delay = start + offset - time.monotonic()
    if delay > MAX_GAP:
        start -= delay - MAX_GAP
        delay = MAX_GAP
    if delay > 0:
        time.sleep(delay)
    return start


def replay_in_browser(args: argparse.Namespace) -> int:
    """``fsmscope replay LOG --serve``: feed a log to the dashboard at its recorded pace (times
    ``--speed``) through the hub's ingest path, so the page cannot tell it from a live machine.
    The first event is shown at once; the clock starts when a browser watches (``--speed 0``:
    no waiting at all)."""
    from fsm.logfiles.log_reader import LogError, Reader, read_events

    reader = Reader(args.log, on_problem=lambda p: print("fsmscope replay: %s: skipped %s" % (args.log, p),
                                                         file=sys.stderr, flush=True))
    try:
        srv = start_server(args)
    except (ValueError, OSError) as exc:
        print("fsmscope replay: %s" % exc, file=sys.stderr)
        return 1
    print("fsmscope: replaying %s at %s" % (args.log, srv.url), file=sys.stderr, flush=True)
    count = 0
    try:
        start = first = None
        for event in read_events(args.log, reader=reader):
            t = event.get("t")
            paced = args.speed > 0 and isinstance(t, (int, float))
            if paced and first is not None:
                start = _sleep_until_due(start, (t - first) / args.speed)
            srv.hub.loop.call_soon_threadsafe(srv.hub.ingest, event, "replay")
            count += 1
            if paced and first is None:
                print("fsmscope: the replay starts when a browser opens it", file=sys.stderr, flush=True)
                while not any(entry.clients for entry in srv.hub.machines()):
                    time.sleep(0.1)
                first, start = t, time.monotonic()
        if not count:
            from .cli import no_events
            print("fsmscope replay: %s" % no_events(reader), file=sys.stderr)
            return 2
        print("fsmscope: replayed %d events; still serving at %s (Ctrl-C stops)" % (count, srv.url),
              file=sys.stderr, flush=True)
        wait_for_interrupt()
        code = 0
    except LogError as exc:
        print("fsmscope replay: %s" % exc, file=sys.stderr)
        code = 2
    except KeyboardInterrupt:
        code = 0
    finally:
        srv.stop()
    return code
