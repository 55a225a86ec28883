"""``fsmscope replay LOG``: a recorded run printed as SMACH's log lines, then its statistics; with
``--serve``, fed to the dashboard at its recorded pace instead."""

from __future__ import annotations

import argparse
import sys
import time
from typing import TYPE_CHECKING

from .serving import add_server_arguments, start_server, wait_for_interrupt

if TYPE_CHECKING:
    from fsm.logfiles.log_reader import Reader

HELP = "print a recorded run as SMACH's log lines, then its statistics"
PASSES_ARGUMENTS_ON = False
EXIT_UNREADABLE = 2  # the log cannot be read, or holds not one complete event
MAX_GAP = 2.0  # seconds: the longest a browser replay waits between two events


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("log", metavar="RUN.jsonl", help="a log written by the recorder")
    parser.add_argument("--json", action="store_true", help="print only the summary, as JSON")
    parser.add_argument("--follow", "-f", action="store_true",
                        help="tail a log still being written, until its writer closes it")
    parser.add_argument("--no-transcript", action="store_true", help="print only the summary")
    parser.add_argument("--no-time", action="store_true", help="leave the timestamps out of the transcript")
    parser.add_argument("--serve", action="store_true",
                        help="replay into the dashboard instead of the terminal (view only)")
    parser.add_argument("--speed", type=float, default=1.0,
                        help="with --serve: pace relative to the recording (default 1; 0: as fast as possible)")
    add_server_arguments(parser, 0)


def main(args: argparse.Namespace) -> int:
    if args.serve:
        return replay_in_browser(args)
    return replay_in_terminal(args)


def reader_of(log: str) -> Reader:
    """The log's reader; each line it skips is said on stderr as it goes."""
    from fsm.logfiles.log_reader import Reader

    return Reader(log, on_problem=lambda p: print("fsmscope replay: %s: skipped %s" % (log, p),
                                                  file=sys.stderr, flush=True))


def no_events(reader: Reader) -> str:
    """What is wrong with a log that holds not one complete event (it is unreadable: exit 2)."""
    if reader.lineno == 0:
        return "%s: no events (the file is empty)" % reader.path
    skipped = len(reader.problems)
    return "%s: no events (%d line%s skipped)" % (reader.path, skipped, "" if skipped == 1 else "s")


def replay_in_terminal(args: argparse.Namespace) -> int:
    import json

    from fsm.logfiles.log_reader import LogError, follow, read_events
    from fsm.logfiles.summary import Summary
    from fsm.logfiles.transcript import Transcript

    reader = reader_of(args.log)
    summary = Summary()
    transcript = Transcript(summary.structures)
    show = not (args.json or args.no_transcript)
    out = sys.stdout
    events = follow(args.log, reader=reader) if args.follow else read_events(args.log, reader=reader)
    try:
        for event in events:
            summary.add(event)
            if show:
                for line in transcript.lines(event):
                    out.write(transcript.format(line, not args.no_time) + "\n")
                if args.follow:
                    out.flush()
    except LogError as exc:
        print("fsmscope replay: %s" % exc, file=sys.stderr)
        return EXIT_UNREADABLE
    except KeyboardInterrupt:
        pass
    summary.problems = reader.problems
    if not summary.machines:
        print("fsmscope replay: %s" % no_events(reader), file=sys.stderr)
    if args.json:
        data = summary.to_dict()
        data["file"] = args.log
        out.write(json.dumps(data, indent=2) + "\n")
    else:
        if show:
            out.write("\n")
        out.write(summary.format() + "\n")
    return summary.exit_code()


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
    """Feed a log to the dashboard at its recorded pace (times ``--speed``) through the hub's
    ingest path, so the page cannot tell it from a live machine. The first event is shown at once;
    the clock starts when a browser watches (``--speed 0``: no waiting at all)."""
    from fsm.logfiles.log_reader import LogError, read_events

    reader = reader_of(args.log)
    srv = start_server(args)
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
            print("fsmscope replay: %s" % no_events(reader), file=sys.stderr)
            return EXIT_UNREADABLE
        print("fsmscope: replayed %d events; still serving at %s (Ctrl-C stops)" % (count, srv.url),
              file=sys.stderr, flush=True)
        wait_for_interrupt()
        code = 0
    except LogError as exc:
        print("fsmscope replay: %s" % exc, file=sys.stderr)
        code = EXIT_UNREADABLE
    except KeyboardInterrupt:
        code = 0
    finally:
        srv.stop()
    return code
