"""What ``fsmscope ros1``, ``fsmscope ros2`` and ``serve --ros1/--ros2`` share: a ROS graph's SMACH
machines (fsmscope/interop/ros_watcher.py) shown on the dashboard and recorded.

The watcher delivers each machine's events from a thread of its own: they are written to the log at
once (``--record``) and go through the hub's ingest door on the server's loop (each checked against
the schema, as a publisher's are). A machine gets ``RosControls`` (set initial state and preempt the
ROS way) when it first shows, and is shown disconnected while its robot publishes nothing.
"""

from __future__ import annotations

import argparse
import signal
import sys
from typing import TYPE_CHECKING, Any, Callable

from .cannot_serve import CannotServe
from .loop_inbox import LoopInbox, ingest_in_order
from .serving import SWITCH_INTERVAL

if TYPE_CHECKING:
    from fsm.logfiles.recorder import Recorder
    from fsmscope.interop.ros_watcher import Flavour, RosWatcher

    from ..hub import Hub


def add_live_arguments(parser: argparse.ArgumentParser) -> None:
    """What a ROS command takes besides where its graph is."""
    parser.add_argument("--stop-topic", action="append", default=[], metavar="[MACHINE=]TOPIC",
                        help="where Preempt publishes std_msgs/Empty, for every machine or for MACHINE "
                             "(default /sm_stop: what a MonitorState of the robot's machine listens to); repeatable")


def stop_topics(given: list[str]) -> Callable[[str], str]:
    """Each machine's stop topic, from ``--stop-topic`` values; CannotServe for one that is not a ROS name."""
    from fsmscope.interop.ros_watcher import STOP_TOPIC

    by_machine: dict[str, str] = {}
    default = STOP_TOPIC
    for value in given:
        machine, _, topic = value.rpartition("=")
        if not topic.startswith("/") or " " in topic:
            raise CannotServe("--stop-topic %s: a topic is a ROS name that starts with /" % value)
        if machine:
            by_machine[machine] = topic
        else:
            default = topic
    return lambda name: by_machine.get(name, default)


def follow(node: Any, flavour: Flavour, hub: Hub | None, recorder: Recorder | None,
           stop_topic: Callable[[str], str]) -> RosWatcher:
    """A watcher of ``node``'s graph feeding ``hub`` (on its loop) and ``recorder``, until the process ends."""
    from fsmscope.interop.ros_controls import RosControls
    from fsmscope.interop.ros_watcher import RosWatcher

    inbox = LoopInbox(hub.loop) if hub is not None else None
    if hub is not None:
        # The watcher's threads and the event loop take turns holding the GIL (fleet_bridge.py says why).
        sys.setswitchinterval(SWITCH_INTERVAL)

    def ingest(events: list[dict]) -> None:
        entry = ingest_in_order(hub, events, "the ROS graph")
        name = events[0]["machine"]
        machine = watcher.machine(name)
        if entry is None or machine is None:
            return
        entry.origin.robot = machine.publisher
        if not isinstance(entry.controls, RosControls):
            entry.controls = RosControls(watcher, name)
            entry.origin.connected = machine.up

    def seen(name: str, up: bool) -> None:
        entry = hub.get(name)
        if entry is not None:
            entry.origin.connected = up

    def deliver(events: list[dict]) -> None:
        if recorder is not None:
            for event in events:
                recorder(event)
        if inbox is not None:
            inbox.post(ingest, events)
            inbox.wake()

    def seen_from_watcher(name: str, up: bool) -> None:
        print("fsmscope: machine %s %s" % (name, "is back" if up else "is gone: its robot stopped publishing"),
              file=sys.stderr, flush=True)
        if inbox is not None:
            inbox.post(seen, name, up)
            inbox.wake()

    watcher = RosWatcher(node, flavour, deliver, seen_from_watcher, stop_topic=stop_topic)
    return watcher


def add_recording_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--record", metavar="RUN.jsonl",
                        help="also record every machine's events in fsmscope's log, a new file (replay it later)")
    parser.add_argument("--no-serve", action="store_true",
                        help="do not serve the dashboard (with --record: a headless recorder beside the robot)")


def unused_live(args: argparse.Namespace, given: set[str]) -> str | None:
    from .serving import SERVER_OPTIONS, given_of

    if args.no_serve and args.record is None:
        return "--no-serve needs --record (else nothing would be shown or kept)"
    return args.no_serve and given_of(given, SERVER_OPTIONS, "has no meaning with --no-serve (no dashboard)") or None


def join(graph: str, make_node: Callable[[], Any], flavour: Flavour) -> tuple[str, Any, Flavour]:
    """(``graph``, a node that joined it, ``flavour``); CannotServe saying why it could not join."""
    try:
        return graph, make_node(), flavour
    except Exception as exc:  # the wire clients say what failed in words
        raise CannotServe("cannot join %s: %s" % (graph, exc)) from None


def _interrupted(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def serve_live(args: argparse.Namespace, joined: Callable[[], tuple[str, Any, Flavour]]) -> int:
    """``fsmscope ros1/ros2``: the graph's machines served (unless --no-serve) and recorded (--record)
    until Ctrl-C."""
    import os

    from fsm.logfiles.recorder import Recorder

    from .serving import announce_viewer, start_server, wait_for_interrupt

    topics = stop_topics(args.stop_topic)
    if args.record is not None and os.path.exists(args.record):
        raise CannotServe("%s exists already: the recording is a new file" % args.record)
    graph, node, flavour = joined()
    signal.signal(signal.SIGTERM, _interrupted)  # a headless recorder stopped by its service manager closes its log
    recorder = Recorder(args.record) if args.record is not None else None
    srv = watcher = None
    try:
        if not args.no_serve:
            srv = start_server(args)
        watcher = follow(node, flavour, srv.hub if srv else None, recorder, topics)
        if srv is not None:
            print("fsmscope: dashboard at %s" % srv.url, file=sys.stderr, flush=True)
            announce_viewer(args, srv)
        if recorder is not None:
            print("fsmscope: recording to %s" % args.record, file=sys.stderr, flush=True)
        wait_for_interrupt("fsmscope: following the SMACH machines of %s (Ctrl-C stops)" % graph)
    finally:
        if watcher is not None:
            watcher.close()  # closes the node too
        else:
            node.close()
        if srv is not None:
            srv.stop()
        if recorder is not None:
            recorder.close()
    return 0
