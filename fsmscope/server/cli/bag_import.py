"""``fsmscope import BAG -o LOG.jsonl``: a ROS bag's SMACH runs (smach_ros's introspection topics) as
fsmscope's own log, read with rosbags, no ROS needed; an MCAP file ``fsmscope export --mcap`` wrote,
read back (interop/, docs/interop.md)."""

from __future__ import annotations

import argparse
import sys
from typing import Callable, Iterator

from fsm.observation.visible import terminal_text

HELP = "turn a ROS bag of SMACH runs (ROS 1 .bag, ROS 2 sqlite3 or mcap), or fsmscope's MCAP, into an fsmscope log"
PASSES_ARGUMENTS_ON = False
EXIT_DAMAGED = 1  # the bag is damaged part way: the events before the damage were written
EXIT_UNFINISHED = 1  # a machine's last run has no end the bag tells (the log was written; replay: it did not finish)
EXIT_UNREADABLE = 2  # the bag cannot be read, holds no SMACH introspection or no event that fits the schema,
                     # or the log cannot be written
SHOWN = 300  # characters of a reason a skipped line shows


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bag", metavar="BAG", help="a ROS 1 .bag, a ROS 2 bag (its folder, .db3 or .mcap), or an "
                                                   "MCAP file fsmscope wrote")
    parser.add_argument("-o", "--output", metavar="LOG.jsonl", required=True, help="the log to write (a new file)")


def convert(source: str, log: str, command: str) -> int:
    """Write the events of ``source`` (a ROS bag, or an MCAP file fsmscope wrote) to ``log``, saying
    what happened on stderr as ``fsmscope COMMAND``; the exit code."""
    from fsmscope.interop.to_log import Damaged, NoEvents, NotWritten, ReadError, write_log

    def skipped(problem: str) -> None:
        shown = problem if len(problem) <= SHOWN else problem[:SHOWN] + "…"  # its words may quote a huge path
        print(terminal_text("fsmscope %s: %s: skipped %s" % (command, source, shown)), file=sys.stderr, flush=True)

    untold: list[str] = []
    try:
        written = write_log(events_of(source, skipped, untold.append), log, skipped)
    except Damaged as exc:
        print(terminal_text("fsmscope %s: %s; the %d events before it were kept" % (command, exc, exc.written)),
              file=sys.stderr)
        return EXIT_DAMAGED
    except NoEvents as exc:
        print(terminal_text("fsmscope %s: %s: %s" % (command, source, exc)), file=sys.stderr)
        return EXIT_UNREADABLE
    except (ReadError, NotWritten) as exc:
        print(terminal_text("fsmscope %s: %s" % (command, exc)), file=sys.stderr)
        return EXIT_UNREADABLE
    if command == "import":
        print("fsmscope: wrote %s (%d events)" % (log, written), file=sys.stderr)
    for said in untold:
        print(terminal_text("fsmscope %s: %s: %s" % (command, source, said)), file=sys.stderr)
    return EXIT_UNFINISHED if untold else 0


def events_of(source: str, skipped: Callable[[str], None],
              untold: Callable[[str], None] | None = None) -> Iterator[dict]:
    """The events of an MCAP file fsmscope wrote, else of a ROS bag's SMACH runs (``untold`` hears of
    each machine whose last run's end the bag does not tell)."""
    from fsmscope.interop.bag_reader import read_bag
    from fsmscope.interop.mcap_log import is_fsmscope_mcap, read_mcap
    from fsmscope.interop.smach_events import events

    return read_mcap(source, skipped) if is_fsmscope_mcap(source) else events(read_bag(source), skipped, untold)


def converts(source: str) -> bool:
    """Whether ``source`` is read through ``convert`` (a ROS bag, or fsmscope's MCAP), not as a log."""
    from fsmscope.interop.bag_reader import is_bag
    from fsmscope.interop.mcap_log import is_fsmscope_mcap

    return is_fsmscope_mcap(source) or is_bag(source)


def main(args: argparse.Namespace) -> int:
    return convert(args.bag, args.output, "import")
