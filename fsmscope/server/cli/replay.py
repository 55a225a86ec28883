"""``fsmscope replay LOG``: a recorded run printed as SMACH's log lines, then its statistics; with
``--serve``, the whole log loaded into the dashboard instead, where the page scrubs and plays it."""

from __future__ import annotations

import argparse
import math
import sys
from typing import TYPE_CHECKING, Any

from fsm.observation.visible import terminal_text

from .serving import FOXGLOVE_OPTIONS, SERVER_OPTIONS, add_server_arguments, given_of, start_server, wait_for_interrupt

if TYPE_CHECKING:
    from fsm.logfiles.log_reader import Reader

    from ..hub import Hub

HELP = "print a recorded run as SMACH's log lines, then its statistics"
PASSES_ARGUMENTS_ON = False
EXIT_UNREADABLE = 2  # the log cannot be read, or holds not one complete event
SPEEDS = (0.1, 10.0)  # the page's play speeds


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("log", metavar="RUN.jsonl", help="a log written by the recorder, a ROS bag of SMACH runs or "
                                                         "fsmscope's MCAP (read as `fsmscope import` reads them)")
    parser.add_argument("--json", action="store_true", help="print only the summary, as JSON")
    parser.add_argument("--follow", "-f", action="store_true",
                        help="tail a log still being written, until its writer closes it")
    parser.add_argument("--no-transcript", action="store_true", help="print only the summary")
    parser.add_argument("--no-time", action="store_true", help="leave the timestamps out of the transcript")
    parser.add_argument("--serve", action="store_true",
                        help="load it into the dashboard instead, to scrub and play there (view only)")
    parser.add_argument("--speed", type=play_speed, default=1.0,
                        help="with --serve: the page's play speed when it opens, relative to the recording "
                             "(%g to %g, default 1)" % SPEEDS)
    add_server_arguments(parser, 0)


def play_speed(text: str) -> float:
    """``--speed``: a number within the page's play speeds."""
    try:
        speed = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError("%r is not a number" % text) from None
    if not (math.isfinite(speed) and SPEEDS[0] <= speed <= SPEEDS[1]):
        raise argparse.ArgumentTypeError("%s is not within %g to %g" % (text, *SPEEDS))
    return speed


def unused(args: argparse.Namespace, given: set[str]) -> str | None:
    """The dashboard's options without ``--serve``, the terminal's with it; and ``--foxglove``: a
    replay is no live run (Foxglove opens the recording as a file, ``export --mcap``)."""
    if args.foxglove is not None or given & set(FOXGLOVE_OPTIONS):
        return ("--foxglove serves a live run's channels; a recorded one opens in Foxglove as a file: "
                "fsmscope export %s --mcap OUT.mcap" % args.log)
    if not args.serve:
        return given_of(given, SERVER_OPTIONS + ("speed",), "needs --serve")
    return given_of(given, ("json", "no_transcript", "no_time", "follow"),
                    "has no meaning with --serve (the dashboard shows the whole log)")


def main(args: argparse.Namespace) -> int:
    from .bag_import import converts

    if converts(args.log):
        return replay_converted(args)
    if args.serve:
        return replay_in_browser(args)
    return replay_in_terminal(args)


def replay_converted(args: argparse.Namespace) -> int:
    """A ROS bag's SMACH runs, or fsmscope's MCAP, turned into a log in a temporary folder (as
    ``fsmscope import`` does), replayed."""
    import os
    import tempfile

    from .bag_import import EXIT_UNREADABLE as SOURCE_UNREADABLE, convert

    if args.follow:
        print("fsmscope replay: --follow tails a log being written; %s is read whole" % args.log, file=sys.stderr)
        return EXIT_UNREADABLE
    with tempfile.TemporaryDirectory(prefix="fsmscope-replay-") as folder:
        source, args.log = args.log, os.path.join(folder, os.path.basename(args.log.rstrip("/")) + ".jsonl")
        converted = convert(source, args.log, "replay")
        if converted == SOURCE_UNREADABLE:
            return EXIT_UNREADABLE
        return (replay_in_browser(args) if args.serve else replay_in_terminal(args)) or converted


def reader_of(log: str) -> Reader:
    """The log's reader; each line it skips is said on stderr as it goes."""
    from fsm.logfiles.log_reader import Reader

    return Reader(log, on_problem=lambda p: print(terminal_text("fsmscope replay: %s: skipped %s" % (log, p)),
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
                    out.write(terminal_text(transcript.format(line, not args.no_time)) + "\n")
                if args.follow:
                    out.flush()
    except LogError as exc:
        print(terminal_text("fsmscope replay: %s" % exc), file=sys.stderr)
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
        out.write(terminal_text(summary.format()) + "\n")
    return summary.exit_code()


def load(hub: Hub, reader: Reader, speed: float) -> int:
    """Every complete event of the log into ``hub`` through its ingest door, in one scan: each
    machine is served as source "replay" with its Status at the log's end and its timeline index
    (fsmscope/server/timeline.py) built on the way, its history read from the log (fsmscope/server/history.py);
    returns the number of events."""
    from fsm.logfiles.log_reader import read_events

    from ..log_history import LogHistory

    count = 0
    for event in read_events(reader.path, reader=reader):
        hub.ingest(event, "replay")
        count += 1
    for entry in hub.machines():
        entry.origin.replay = {"speed": speed}
        entry.read_past_from(LogHistory(reader.path, entry.name))
    return count


def replay_in_browser(args: argparse.Namespace) -> int:
    """Load the whole log, then serve it until Ctrl-C: a page (re)loaded at any time gets the
    whole run (it opens paused at the start, at ``--speed``), nothing is paced here."""
    from fsm.logfiles.log_reader import LogError

    from ..hub import Hub

    reader = reader_of(args.log)
    hub = Hub()
    try:
        count = load(hub, reader, args.speed)
    except LogError as exc:
        print(terminal_text("fsmscope replay: %s" % exc), file=sys.stderr)
        return EXIT_UNREADABLE
    except KeyboardInterrupt:
        return 0
    if not count:
        print("fsmscope replay: %s" % no_events(reader), file=sys.stderr)
        return EXIT_UNREADABLE
    scene = pose_scene(hub)
    try:
        srv = start_server(args, hub=hub, **({} if scene is None else {"scene_url": scene.url,
                                                                       "show_pose": scene.show_pose}))
        try:
            wait_for_interrupt("fsmscope: replaying %s at %s (%d events loaded; Ctrl-C stops)"
                               % (args.log, srv.url, count))
        finally:
            srv.stop()
    finally:
        if scene is not None:
            scene.stop()
    return 0


def pose_scene(hub: Hub) -> Any:
    """A 3D view that draws the recorded arm (no simulation runs) when the log recorded its pose, else None."""
    pose = next((entry.feed.status.pose for entry in hub.machines() if entry.feed.status.pose is not None), None)
    if pose is None:
        return None
    from fsmscope.sim.scene import start_pose_scene

    try:
        return start_pose_scene({"joints": pose["joints"], "bodies": pose["bodies"]})
    except ValueError as exc:  # a pose of another robot than the demo's arm
        print(terminal_text("fsmscope replay: no 3D view: %s" % exc), file=sys.stderr)
        return None
