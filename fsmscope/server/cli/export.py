"""``fsmscope export LOG --html OUT.html``: a recorded run as one HTML file that opens from disk with
no server and no network (fsmscope/server/export_html.py); ``--mcap OUT.mcap``: as MCAP, which Foxglove
opens (fsmscope/interop/mcap_log.py)."""

from __future__ import annotations

import argparse
import os
import sys

from fsm.observation.visible import terminal_text

from .serving import given_of

HELP = "write a recorded run as one HTML file that shows it in the dashboard, from disk, with no server"
PASSES_ARGUMENTS_ON = False
EXIT_UNREADABLE = 2  # the log cannot be read or exported, or the file cannot be written


def arguments(parser: argparse.ArgumentParser) -> None:
    from ..export_html import MAX_MB

    parser.add_argument("log", metavar="RUN.jsonl", help="a log written by the recorder")
    out = parser.add_mutually_exclusive_group(required=True)
    out.add_argument("--html", metavar="OUT.html",
                     help="the file to write: open it in a browser (file://); it needs nothing else")
    out.add_argument("--mcap", metavar="OUT.mcap",
                     help="an MCAP file for Foxglove (and `fsmscope replay`): events, active states, log lines, pose")
    parser.add_argument("--max-mb", type=float, default=MAX_MB,
                        help="refuse a log larger than this many megabytes (default %(default)s): the whole "
                             "run goes into the page, which the browser holds in memory")


def unused(args: argparse.Namespace, given: set[str]) -> str | None:
    return given_of(given, ("max_mb",), "limits --html's page; --mcap writes any log") if args.mcap else None


def main(args: argparse.Namespace) -> int:
    if args.mcap:
        return export_mcap(args)
    from fsm.logfiles.log_reader import LogError

    from ..export_html import ExportError, export_html

    def skipped(problem: object) -> None:
        print(terminal_text("fsmscope export: %s: skipped %s" % (args.log, problem)), file=sys.stderr, flush=True)

    if os.path.exists(args.html):  # as --mcap, import -o, run --record: no file is written over
        print("fsmscope export: %s exists already" % args.html, file=sys.stderr)
        return EXIT_UNREADABLE
    try:
        text = export_html(args.log, max_bytes=int(args.max_mb * 2**20), on_problem=skipped)
    except (ExportError, LogError) as exc:
        print(terminal_text("fsmscope export: %s" % exc), file=sys.stderr)
        return EXIT_UNREADABLE
    partial = args.html + ".partial"
    try:
        with open(partial, "w", encoding="utf-8") as handle:
            handle.write(text)
    except OSError as exc:
        os.remove(partial)
        return not_written(args.html, exc)
    os.replace(partial, args.html)
    print("fsmscope: wrote %s (%.1f MB); open it in a browser" % (args.html, len(text.encode()) / 2**20),
          file=sys.stderr)
    return 0


def export_mcap(args: argparse.Namespace) -> int:
    """The log's events as an MCAP file (fsmscope/interop/mcap_log.py); the arm's links as frames when the log
    recorded the demo's pose."""
    from fsm.logfiles.log_reader import LogError, read_events
    from fsmscope.interop.mcap_log import McapLogError, write_mcap

    from .arm_frames import arm_frames

    def skipped(problem: object) -> None:
        print(terminal_text("fsmscope export: %s: skipped %s" % (args.log, problem)), file=sys.stderr, flush=True)

    try:
        written = write_mcap(read_events(args.log, on_problem=skipped), args.mcap, frames=arm_frames())
    except (McapLogError, LogError) as exc:
        print(terminal_text("fsmscope export: %s" % exc), file=sys.stderr)
        return EXIT_UNREADABLE
    except OSError as exc:  # reading the log says LogError: this is the writing (a full disk); no file is left
        return not_written(args.mcap, exc)
    if not written:
        os.remove(args.mcap)
        print("fsmscope export: %s: no events" % args.log, file=sys.stderr)
        return EXIT_UNREADABLE
    print("fsmscope: wrote %s (%d events)" % (args.mcap, written), file=sys.stderr)
    return 0


def not_written(out: str, exc: OSError) -> int:
    """Say that ``out`` could not be written (a full disk) and was not left behind; the exit code."""
    print("fsmscope export: %s not written: %s" % (out, exc.strerror or exc), file=sys.stderr)
    return EXIT_UNREADABLE
