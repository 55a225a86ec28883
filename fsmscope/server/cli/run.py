"""``fsmscope run FILE.py``: the user's script run with recording (``server.runner.Runner``) and,
unless ``--no-serve``, every machine it runs shown on the dashboard, where it can be started again."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from fsm.core.log import LEVELS, print_from

from .zenoh_options import ZENOH_OPTIONS, add_zenoh_arguments, robot_follows, zenoh_robot
from .serving import (SERVER_OPTIONS, SWITCH_INTERVAL, add_server_arguments, announce_viewer, foxglove_unused, given_of,
                      start_server, wait_for_interrupt)

if TYPE_CHECKING:
    from fsmscope.fleet.robot import ZenohRobot

    from ..runner import Runner

HELP = "run a SMACH-style script and record every machine it executes"
PASSES_ARGUMENTS_ON = True


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("script", metavar="FILE.py",
                        help="a SMACH script, run as __main__ as it is (its 'import smach' is the original where "
                             "installed, else fsm with ROS-free rospy and smach_ros); arguments fsmscope does not "
                             "know, and all after '--', are passed to it")
    parser.add_argument("--record", metavar="RUN.jsonl",
                        help="where to record the events, a new file (default: runs/<script>-<timestamp>.jsonl)")
    parser.add_argument("--append", action="store_true", help="with --record: add to the log if it exists")
    parser.add_argument("--no-serve", action="store_true", help="do not serve the dashboard while it runs")
    parser.add_argument("--exit", action="store_true",
                        help="exit when the script ends instead of keeping the dashboard up")
    parser.add_argument("--log-level", choices=LEVELS, default="info",
                        help="print SMACH's log lines of this level and above (default: info, as rospy does; "
                             "debug adds its 'Adding state ...' lines)")
    add_server_arguments(parser, 0)
    add_zenoh_arguments(parser, publish=True)


def unused(args: argparse.Namespace, given: set[str]) -> str | None:
    """The dashboard's options without a dashboard, Zenoh's without ``--zenoh``, Foxglove's without
    ``--foxglove``, ``--append`` without ``--record``."""
    return ((args.no_serve and given_of(given, SERVER_OPTIONS, "has no meaning with --no-serve (no dashboard)"))
            or (args.zenoh is None and given_of(given, ZENOH_OPTIONS, "needs --zenoh ROBOT"))
            or foxglove_unused(args, given)
            or (args.record is None and given_of(given, ("append",), "needs --record")))


def main(args: argparse.Namespace) -> int:
    from ..runner import Runner

    print_from(args.log_level)
    runner = Runner(args.script, list(args.extra), args.record, append=args.append)
    refused = runner.prepare()  # no dashboard or robot starts for a script or log that cannot be
    if refused is not None:
        return refused
    robot = zenoh_robot(args, can_start=True)
    if args.no_serve:
        return run_unserved(args, runner, robot)
    return run_with_dashboard(args, runner, robot)


def run_unserved(args: argparse.Namespace, runner: Runner, robot: ZenohRobot | None) -> int:
    """The script's machines observed by the robot and the Foxglove server, when asked, and no dashboard."""
    import fsm

    from .foxglove_bridge import open_foxglove

    if robot is not None:
        runner.on_machine.append(lambda name, container: fsm.attach(container, robot, name=name))
    live = open_foxglove(args) if args.foxglove is not None else None
    if live is not None:
        runner.on_machine.append(lambda name, container: fsm.attach(container, live.event))
    try:
        return runner.run()
    finally:
        if live is not None:
            live.stop()


def run_with_dashboard(args: argparse.Namespace, runner: Runner, robot: ZenohRobot | None = None) -> int:
    """Serve every machine the script runs; keep serving afterwards unless --exit, or unless a
    signal (Ctrl-C, SIGTERM) ended the script: one signal stops everything."""
    # The script's states run in this process's main thread, the server in others: a state that
    # computes in Python would hold the GIL for 5 ms at a time (the default), and a page then took
    # 17-25 s to open and its live view ran 1,600 events behind (bench/live_rewind.py).
    sys.setswitchinterval(SWITCH_INTERVAL)
    srv = start_server(args)
    hub = srv.hub

    def serve(name: str, container: Any) -> None:
        entry = hub.add_local(container, name=name, can_start=True, recording=runner.record_path, script=args.script)
        if robot is not None:  # publishes what the hub encodes; one handle and one Status serve both sides
            robot_follows(robot, entry)

    runner.on_machine.append(serve)
    runner.keep_open = True  # runs started from the dashboard after the script ends are recorded too
    print("fsmscope: dashboard at %s" % srv.url, file=sys.stderr, flush=True)
    announce_viewer(args, srv)
    try:
        code = runner.run()
        if not args.exit and runner.signalled is None:
            wait_for_interrupt("fsmscope: the script ended (exit code %d); still serving at %s (Ctrl-C stops)"
                               % (code, srv.url))
    finally:
        srv.stop()
        runner.close()
    return runner.exit_code(code)
