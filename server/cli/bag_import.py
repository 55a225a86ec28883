"""``fsmscope import BAG -o LOG.jsonl``: a ROS bag's SMACH runs (smach_ros's introspection topics) as
fsmscope's own log, read with rosbags, no ROS needed (interop/, docs/interop.md)."""

from __future__ import annotations

import argparse
import sys

HELP = "turn a ROS bag of SMACH runs (ROS 1 .bag, ROS 2 sqlite3 or mcap) into an fsmscope log"
PASSES_ARGUMENTS_ON = False
EXIT_DAMAGED = 1  # the bag is damaged part way: the events before the damage were written
EXIT_UNREADABLE = 2  # the bag cannot be read, or holds no SMACH introspection


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bag", metavar="BAG", help="a ROS 1 .bag, or a ROS 2 bag (its folder, .db3 or .mcap)")
    parser.add_argument("-o", "--output", metavar="LOG.jsonl", required=True, help="the log to write (a new file)")


def convert(bag: str, log: str, command: str) -> int:
    """Write the bag's events to ``log``, saying what happened on stderr as ``fsmscope COMMAND``; the exit code."""
    from interop.bag_log import BagDamaged, write_log
    from interop.bag_reader import BagError

    try:
        written = write_log(bag, log)
    except BagDamaged as exc:
        print("fsmscope %s: %s; the %d events before it were kept" % (command, exc, exc.written), file=sys.stderr)
        return EXIT_DAMAGED
    except BagError as exc:
        print("fsmscope %s: %s" % (command, exc), file=sys.stderr)
        return EXIT_UNREADABLE
    if command == "import":
        print("fsmscope: wrote %s (%d events)" % (log, written), file=sys.stderr)
    return 0


def main(args: argparse.Namespace) -> int:
    return convert(args.bag, args.output, "import")
