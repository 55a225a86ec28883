"""The ``fsmscope`` command line: the one place where fsmscope's parts are put together.

Each subcommand is a module of this package that composes the components for one use: the
runtime (``fsm``), the recorder, the script runner (``fsmscope.server.runner``), the dashboard's server
(``fsmscope.server.http_server.ServerThread`` and its hub), the simulator (``sim``), the robotics world's files
(``interop``) and the fleet (``fleet``). Nothing else in
``server`` imports ``sim``, and ``sim`` never imports ``server``.

A subcommand module has::

    HELP = "serve the dashboard"        # one line, for ``fsmscope --help``
    PASSES_ARGUMENTS_ON = False         # True: arguments it does not know go to ``args.extra`` (for a script)
    def arguments(parser) -> None: ...  # its options
    def main(args) -> int: ...          # the exit code; import fastapi, uvicorn, sim in here, not at module level

and, when some of its options mean nothing together, ``def unused(args, given) -> str | None``:
what is wrong with the options ``given`` (the set of those given a value other than their
default), said as the command's usage error (exit code 2) rather than silently ignored.

To add one, write the module and list it in ``SUBCOMMANDS``.
"""

from __future__ import annotations

import argparse
import signal
import sys
from typing import Protocol

from . import bag_import, demo, export, replay, ros1, ros2, router, run, serve
from .cannot_serve import CannotServe


class Subcommand(Protocol):
    HELP: str
    PASSES_ARGUMENTS_ON: bool

    def arguments(self, parser: argparse.ArgumentParser) -> None: ...

    def main(self, args: argparse.Namespace) -> int: ...


SUBCOMMANDS: dict[str, Subcommand] = {"run": run, "serve": serve, "replay": replay, "export": export,
                                      "import": bag_import, "demo": demo, "router": router,
                                      "ros1": ros1, "ros2": ros2}


def build_parser() -> tuple[argparse.ArgumentParser, dict[str, argparse.ArgumentParser]]:
    """The command line's parser, and each subcommand's."""
    parser = argparse.ArgumentParser(prog="fsmscope", description="Run, watch, record and replay SMACH-style state machines.")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    commands.required = True
    parsers = {}
    for name, sub in SUBCOMMANDS.items():
        parsers[name] = commands.add_parser(name, help=sub.HELP, description=sub.HELP)
        sub.arguments(parsers[name])
    return parser, parsers


def _refuse_unused(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """``parser``'s usage error (exit 2) when options of its command were given that mean nothing together."""
    unused = getattr(SUBCOMMANDS[args.command], "unused", None)
    if unused is None:
        return
    given = {dest for dest, value in vars(args).items() if value != parser.get_default(dest)}
    problem = unused(args, given)
    if problem:
        parser.error(problem)


def _split_passed_on(argv: list[str]) -> tuple[list[str], list[str]]:
    """For a subcommand that passes arguments on (to a script): its own arguments, and those after
    the first '--', as they are. argparse cannot be left to it: it keeps that '--' among the
    unknown arguments or drops it, depending on what precedes it (and on the Python version)."""
    if argv and argv[0] in SUBCOMMANDS and SUBCOMMANDS[argv[0]].PASSES_ARGUMENTS_ON and "--" in argv:
        cut = argv.index("--")
        return argv[:cut], argv[cut + 1:]
    return argv, []


def main(argv: list[str] | None = None) -> int:
    parser, parsers = build_parser()
    own, passed_on = _split_passed_on(sys.argv[1:] if argv is None else list(argv))
    args, extra = parser.parse_known_args(own)
    if extra and not SUBCOMMANDS[args.command].PASSES_ARGUMENTS_ON:
        parser.error("unrecognized arguments: %s" % " ".join(extra))
    _refuse_unused(parsers[args.command], args)
    args.extra = extra + passed_on
    # Ctrl-C (SIGINT) stops every command cleanly, also when it was started with SIGINT ignored, as a
    # non-interactive shell starts a command it puts in the background (`fsmscope serve &` in a script):
    # Python then installs no handler of its own and the command could only be killed.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        return SUBCOMMANDS[args.command].main(args)
    except CannotServe as exc:
        print("fsmscope %s: %s" % (args.command, exc), file=sys.stderr)
        return 1
    except BrokenPipeError:  # `fsmscope replay run.jsonl | head`
        sys.stderr.close()
        return 0
