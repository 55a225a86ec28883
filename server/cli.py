"""The ``fsmscope`` command line: one function per subcommand, registered in ``SUBCOMMANDS``.

To add a subcommand, write its argument setup and its handler and register them::

    def _serve_arguments(parser): parser.add_argument("--port", type=int, default=8000)

    @subcommand("serve", "serve the dashboard", _serve_arguments)
    def serve(args) -> int: ...   # import fastapi/uvicorn here, not at module level

Handlers return the process exit code. Nothing heavy is imported at module import time.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

if TYPE_CHECKING:
    from fsm.logfiles.log_reader import Reader

EXIT_OK, EXIT_ERROR, EXIT_UNREADABLE = 0, 1, 2

Handler = Callable[[argparse.Namespace], int]


@dataclass
class Subcommand:
    name: str
    help: str
    arguments: Callable[[argparse.ArgumentParser], None]
    handler: Handler
    extra_args: bool = False  # arguments it does not know are left in ``args.extra`` (for a script)


SUBCOMMANDS: dict[str, Subcommand] = {}


def subcommand(name: str, help: str, arguments: Callable[[argparse.ArgumentParser], None] = lambda p: None,
               extra_args: bool = False) -> Callable[[Handler], Handler]:
    def register(handler: Handler) -> Handler:
        SUBCOMMANDS[name] = Subcommand(name, help, arguments, handler, extra_args)
        return handler
    return register


# fsmscope run

def _run_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("script", metavar="FILE.py",
                        help="a SMACH-style script, run as __main__; arguments fsmscope does not know, and "
                             "all after '--', are passed to it")
    parser.add_argument("--record", metavar="RUN.jsonl",
                        help="where to record the events (default: runs/<script>-<timestamp>.jsonl)")
    parser.add_argument("--no-serve", action="store_true", help="do not serve the dashboard while it runs")
    parser.add_argument("--exit", action="store_true",
                        help="exit when the script ends instead of keeping the dashboard up")
    from .serve import add_server_arguments
    add_server_arguments(parser, 0)


@subcommand("run", "run a SMACH-style script and record every machine it executes", _run_arguments, extra_args=True)
def run(args: argparse.Namespace) -> int:
    from .runner import Runner

    runner = Runner(args.script, list(args.extra), args.record)
    if args.no_serve:
        return runner.run()
    from .serve import run_with_dashboard
    return run_with_dashboard(args, runner)


# fsmscope serve

def _serve_arguments(parser: argparse.ArgumentParser) -> None:
    from .serve import DEFAULT_PORT, add_server_arguments
    add_server_arguments(parser, DEFAULT_PORT)


@subcommand("serve", "serve the dashboard for machines of other processes (they publish to /api/ingest)",
            _serve_arguments)
def serve(args: argparse.Namespace) -> int:
    from .serve import serve as serve_main
    return serve_main(args)


# fsmscope demo

def _demo_arguments(parser: argparse.ArgumentParser) -> None:
    from sim.demo import add_arguments  # light: mujoco and viser load only when the demo runs
    add_arguments(parser)


@subcommand("demo", "pick-and-place on a simulated MuJoCo arm, with the dashboard and the 3D view", _demo_arguments)
def demo(args: argparse.Namespace) -> int:
    from sim.demo import run_demo
    return run_demo(args)


# fsmscope replay

def _replay_arguments(parser: argparse.ArgumentParser) -> None:
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
    from .serve import add_server_arguments
    add_server_arguments(parser, 0)


@subcommand("replay", "print a recorded run as SMACH's log lines, then its statistics", _replay_arguments)
def replay(args: argparse.Namespace) -> int:
    if args.serve:
        from .serve import replay_in_browser
        return replay_in_browser(args)
    import json

    from fsm.logfiles.log_reader import LogError, Reader, follow, read_events
    from fsm.logfiles.summary import Summary
    from fsm.logfiles.transcript import Transcript

    reader = Reader(args.log, on_problem=lambda p: print("fsmscope replay: %s: skipped %s" % (args.log, p),
                                                         file=sys.stderr, flush=True))
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


def no_events(reader: Reader) -> str:
    """What is wrong with a log that holds not one complete event (it is unreadable: exit 2)."""
    if reader.lineno == 0:
        return "%s: no events (the file is empty)" % reader.path
    skipped = len(reader.problems)
    return "%s: no events (%d line%s skipped)" % (reader.path, skipped, "" if skipped == 1 else "s")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="fsmscope", description="Run, watch, record and replay SMACH-style state machines.")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    commands.required = True
    for sub in SUBCOMMANDS.values():
        sub.arguments(commands.add_parser(sub.name, help=sub.help, description=sub.help))
    return parser


def _split_passed_on(argv: list[str]) -> tuple[list[str], list[str]]:
    """For a subcommand that passes arguments on (to a script): its own arguments, and those after
    the first '--', as they are. argparse cannot be left to it: it keeps that '--' among the
    unknown arguments or drops it, depending on what precedes it (and on the Python version)."""
    if argv and argv[0] in SUBCOMMANDS and SUBCOMMANDS[argv[0]].extra_args and "--" in argv:
        cut = argv.index("--")
        return argv[:cut], argv[cut + 1:]
    return argv, []


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    own, passed_on = _split_passed_on(sys.argv[1:] if argv is None else list(argv))
    args, extra = parser.parse_known_args(own)
    if extra and not SUBCOMMANDS[args.command].extra_args:
        parser.error("unrecognized arguments: %s" % " ".join(extra))
    args.extra = extra + passed_on
    try:
        return SUBCOMMANDS[args.command].handler(args)
    except BrokenPipeError:  # `fsmscope replay run.jsonl | head`
        sys.stderr.close()
        return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
