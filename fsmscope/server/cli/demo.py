"""``fsmscope demo``: the pick-and-place machine running episodes on the simulated arm (``sim``).

With the dashboard (the default), one URL shows the graph, the 3D arm, userdata and the
event log; every episode is a run of the same machine, recorded to one log. A preempt
(the dashboard's button, ``POST .../preempt`` or a message on ``sm_stop``) stops the arm
and ends the episode 'preempted'; the loop then waits for Start. ``--headless`` runs with
no server and no 3D view, for CI and post-mortems (``fsmscope replay`` reads its log).
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from typing import Any, Callable

from .zenoh_options import ZENOH_OPTIONS, add_zenoh_arguments, robot_follows, zenoh_robot
from .serving import SERVER_OPTIONS, add_server_arguments, announce_viewer, foxglove_unused, given_of, start_server

HELP = "pick-and-place on a simulated MuJoCo arm, with the dashboard and the 3D view"
PASSES_ARGUMENTS_ON = False
MACHINE_NAME = "pick_place"


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--headless", action="store_true",
                        help="no dashboard, no 3D view: episodes and a recording only")
    parser.add_argument("--episodes", type=int, default=0, help="episodes to run (0: until stopped)")
    parser.add_argument("--record", metavar="FILE",
                        help="the log of every episode, a new file (default: runs/demo-<time>.jsonl)")
    parser.add_argument("--append", action="store_true", help="with --record: add to the log if it exists")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first episode")
    parser.add_argument("--fast", action="store_true", help="physics as fast as possible, not real time")
    add_server_arguments(parser, 0)
    add_zenoh_arguments(parser, publish=True)
    parser.add_argument("--verbose", action="store_true", help="print the machine's info/debug log")


def unused(args: argparse.Namespace, given: set[str]) -> str | None:
    """The dashboard's options without a dashboard, Zenoh's without ``--zenoh``, Foxglove's without
    ``--foxglove``, ``--append`` without ``--record``."""
    return ((args.headless and given_of(given, SERVER_OPTIONS, "has no meaning with --headless (no dashboard)"))
            or (args.zenoh is None and given_of(given, ZENOH_OPTIONS, "needs --zenoh ROBOT"))
            or foxglove_unused(args, given)
            or (args.record is None and given_of(given, ("append",), "needs --record")))


def _quiet_loggers() -> None:
    import fsm

    def quiet(msg: object) -> None:
        pass

    fsm.set_loggers(quiet, lambda m: print("[  WARN ] : " + str(m), file=sys.stderr), quiet,
                    lambda m: print("[ ERROR ] : " + str(m), file=sys.stderr))


def _print_episode(info: dict) -> None:
    print("episode {episode} seed {seed}: {outcome} (cube {cube_target_distance:.3f} m from target, "
          "{attempts} attempt(s), {sim_time:.1f} s simulated, {wall_time:.2f} s wall)".format(**info), flush=True)


def pose_events(rep: Any) -> Callable[[dict], bool]:
    """What the pose tap gives each new pose to: a pose event of the machine's reporter ``rep``, on the
    machine's own clock (declined until the machine has started: a log opens with its structure)."""
    from fsm.observation import schema

    def record_pose(fields: dict) -> bool:
        if rep.run is None:
            return False
        rep.send(schema.build.pose, rep.root_path, fields["joints"], fields.get("bodies", schema.ABSENT))
        return True
    return record_pose


def main(args: argparse.Namespace) -> int:
    """Physics, action servers, the task machine, its recording, and unless headless the dashboard
    with the 3D view; until the episodes are done, Ctrl-C or SIGTERM. Everything is undone on exit."""
    import fsm
    from fsm.control.handle import MachineHandle
    from fsmscope.sim.demo import SimDemo
    from fsmscope.sim.pose import PoseTap

    from ..runner import EXIT_CANNOT_RECORD, EXIT_NOT_RECORDED, open_recorder

    if not args.verbose:
        _quiet_loggers()
    robot = zenoh_robot(args, can_start=False)  # first: an endpoint Zenoh cannot use ends the command before it starts
    record_path, recorder = open_recorder(args.record, args.append, "demo", "demo")
    if recorder is None:
        if robot is not None:
            robot.close()
        return EXIT_CANNOT_RECORD
    try:
        demo = SimDemo(seed=args.seed, fast=args.fast, scene=not args.headless)
    except BaseException:
        recorder.close()
        raise
    machine = demo.build_machine()
    rep = fsm.attach(machine, recorder, name=MACHINE_NAME)

    tap = PoseTap(demo.world, pose_events(rep))
    resume = threading.Event()
    hold = threading.Event()
    server = None
    live = None
    try:
        if args.headless:
            if robot is not None:  # no loop waits for a start: it ends
                fsm.attach(machine, robot, name=MACHINE_NAME)
                robot.take_controls(MachineHandle(machine, rep, False, holder=hold.set))
            if args.foxglove is not None:  # no hub to feed it: it observes the machine
                from .foxglove_bridge import open_foxglove

                live = open_foxglove(args)
                fsm.attach(machine, live.event)
        else:
            scene = demo.scene
            server = start_server(args, scene_url=scene.url if scene is not None else None,
                                  show_pose=scene.show_pose if scene is not None else None)
            entry = server.hub.add_local(machine, name=MACHINE_NAME, can_start=True, starter=resume.set,
                                         holder=hold.set, recording=record_path)
            if robot is not None:  # the dashboards on Zenoh take the same controls as this one
                robot_follows(robot, entry)
            print("fsmscope demo: open %s" % server.url, flush=True)
            announce_viewer(args, server)
        print("fsmscope demo: recording to %s" % record_path, flush=True)
    except BaseException:
        demo.close()
        recorder.close()
        raise

    interrupted: list[int] = []

    def on_signal(signum: int, frame: Any) -> None:
        interrupted.append(signum)
        demo.request_stop()

    old = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    results: list[dict] = []
    failure: list[BaseException] = []

    def work() -> None:
        try:
            results.extend(demo.run(args.episodes, on_episode=_print_episode, machine_factory=lambda world: machine,
                                    resume=None if server is None else resume, hold=hold))
        except BaseException as exc:  # reported below, after cleanup
            failure.append(exc)

    worker = threading.Thread(target=work, name="sim-episodes", daemon=True)
    tap.start()
    worker.start()
    try:
        while worker.is_alive():
            worker.join(0.2)
    finally:
        tap.stop()
        demo.close()
        worker.join(5.0)
        if server is not None:
            server.stop()
        if live is not None:
            live.stop()
        recorder.close()
        for s, h in old.items():
            signal.signal(s, h)
    if recorder.failure is None:  # else the recorder said where the recording ended
        print("fsmscope demo: %d episode(s) recorded to %s" % (len(results), record_path), flush=True)
    if failure:
        raise failure[0]
    if interrupted:
        return 128 + interrupted[0]  # as a shell reports a process ended by that signal: 130 Ctrl-C, 143 SIGTERM
    if recorder.failure is not None:
        return EXIT_NOT_RECORDED
    return 0 if results and all(r["outcome"] == "succeeded" for r in results) else 1
