"""``fsmscope demo``: the pick-and-place machine running episodes on the simulated arm.

With the dashboard (the default), one URL shows the graph, the 3D arm, userdata and the
event log; every episode is a run of the same machine, recorded to one log. A preempt
(the dashboard's button, ``POST .../preempt`` or a message on ``sm_stop``) stops the arm
and ends the episode 'preempted'; the loop then waits for Start. ``--headless`` runs with
no server and no 3D view, for CI and post-mortems (``fsmscope replay`` reads its log).

For embedding::

    demo = SimDemo(seed=0, fast=False, bus=None, scene=True)   # world, servers, 3D view
    results = demo.run(episodes=5, on_episode=print)            # blocks
    demo.request_stop()                                         # from any thread: preempt + end loop
    demo.close()                                                # threads joined, ports freed
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
import time
from typing import TYPE_CHECKING, Any, Callable

if TYPE_CHECKING:
    from .world import World

Machine = Any
MACHINE_NAME = "pick_place"


def run_episodes(world: World, machine_factory: Callable[[World], Machine], episodes: int,
                 on_episode: Callable[[dict], Any] | None = None, *, seed: int | None = None,
                 pause: float = 1.0, stop: threading.Event | None = None,
                 on_machine: Callable[[int, Machine], Any] | None = None,
                 resume: threading.Event | None = None, hold: threading.Event | None = None) -> list[dict]:
    """Run ``episodes`` episodes (0: until ``stop`` is set); a list of per-episode dicts.

    Each episode resets the world with seed ``seed + i`` (the cube at a seeded random
    place, the arm at HOME), builds a fresh machine with ``machine_factory(world)``,
    hands it to ``on_machine(i, machine)`` (to attach a dashboard or keep it for
    preemption), executes it, then calls ``on_episode(info)``. After a 'preempted' episode,
    and before any episode while ``hold`` is set, the loop waits for ``resume`` (without
    one it ends). ``pause`` is simulated seconds between episodes (with the arm holding still).
    """
    base = world.seed if seed is None else seed
    results: list[dict] = []
    i = 0
    while episodes <= 0 or i < episodes:
        if stop is not None and stop.is_set():
            break
        if hold is not None and hold.is_set():  # asked to stop after the last episode, or between two
            if resume is None or not _wait_either(resume, stop):
                break
            hold.clear()
        if resume is not None:
            resume.clear()  # a start asked for before this episode is used up by it
        ep_seed = base + i
        world.reset(ep_seed)
        world.label = "starting"
        machine = machine_factory(world)
        if on_machine is not None:
            on_machine(i, machine)
        if stop is not None and stop.is_set():
            break
        t_wall, t_sim = time.perf_counter(), world.time
        outcome = machine.execute()
        if outcome == "preempted":
            world.hold()
        ud = getattr(machine, "userdata", None)
        info = {
            "episode": i,
            "seed": ep_seed,
            "outcome": outcome,
            "cube_target_distance": world.cube_target_distance(),
            "attempts": getattr(ud, "attempts", None) if ud is not None else None,
            "sim_time": world.time - t_sim,
            "wall_time": time.perf_counter() - t_wall,
        }
        world.label = f"episode {i}: {outcome}"
        results.append(info)
        if on_episode is not None:
            on_episode(info)
        i += 1
        if outcome == "preempted":
            if resume is None or not _wait_either(resume, stop):
                break
        if pause > 0 and (stop is None or not stop.is_set()):
            try:
                world.sleep(pause)
            except Exception:
                break
    return results


def _wait_either(resume: threading.Event, stop: threading.Event | None) -> bool:
    """Wait for ``resume`` (True) or ``stop`` (False); a start asked for since the last episode
    began counts."""
    while not resume.wait(0.1):
        if stop is not None and stop.is_set():
            return False
    return stop is None or not stop.is_set()


class SimDemo:
    """World + action servers (+ 3D view) wired together; ``close()`` undoes all of it."""

    def __init__(self, seed: int = 0, fast: bool = False, bus=None, scene: bool = True,
                 host: str = "127.0.0.1", port: int = 0, speed: float = 1.0):
        from fsm.ros.bus import get_bus

        from .servers import start_servers
        from .world import World

        self.bus = get_bus(bus)
        self.world = World(seed=seed, fast=fast, speed=speed).start()
        self.move_to, self.gripper = start_servers(self.world, self.bus)
        self.scene = None
        if scene:
            from .scene import start_scene

            self.scene = start_scene(self.world, host=host, port=port)
        self.stop_event = threading.Event()
        self.machine: Machine | None = None
        self._closed = False

    def build_machine(self, world: World | None = None) -> Machine:
        from .task import build_task_machine

        return build_task_machine(world or self.world, bus=self.bus)

    def _keep(self, i: int, machine: Machine) -> None:
        self.machine = machine

    def run(self, episodes: int = 0, on_episode=None, *, seed: int | None = None,
            pause: float | None = None, machine_factory=None, on_machine=None,
            resume: threading.Event | None = None, hold: threading.Event | None = None) -> list[dict]:
        """Run episodes in the calling thread (see :func:`run_episodes`)."""
        def keep(i, m):
            self._keep(i, m)
            if on_machine is not None:
                on_machine(i, m)

        if pause is None:
            pause = 0.0 if self.world.fast else 1.0
        return run_episodes(self.world, machine_factory or self.build_machine, episodes, on_episode,
                            seed=seed, pause=pause, stop=self.stop_event, on_machine=keep, resume=resume, hold=hold)

    def request_stop(self) -> None:
        """Preempt the running machine and end the episode loop (safe from any thread)."""
        self.stop_event.set()
        m = self.machine
        if m is not None:
            m.request_preempt()

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self.stop_event.set()
        m = self.machine
        if m is not None:
            m.request_preempt()
        if self.scene is not None:
            self.scene.stop()
        for s in (self.move_to, self.gripper):
            if s.server is not None:
                s.server.shutdown(timeout=2.0)
        self.world.stop()


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--headless", action="store_true", help="no dashboard, no 3D view: episodes and a recording only")
    p.add_argument("--episodes", type=int, default=0, help="episodes to run (0: until stopped)")
    p.add_argument("--record", metavar="FILE", help="the log of every episode (default: runs/demo-<time>.jsonl)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first episode")
    p.add_argument("--fast", action="store_true", help="physics as fast as possible, not real time")
    p.add_argument("--host", default="127.0.0.1", help="dashboard address (default 127.0.0.1; any other needs a token)")
    p.add_argument("--port", type=int, default=0, help="dashboard port (0: a free one)")
    p.add_argument("--token", default=os.environ.get("FSMSCOPE_TOKEN"),
                   help="the dashboard's access token (default: $FSMSCOPE_TOKEN, else a random one)")
    p.add_argument("--verbose", action="store_true", help="print the machine's info/debug log")


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="fsmscope demo", description="pick-and-place on a simulated arm")
    add_arguments(p)
    return p.parse_args(argv)


def _quiet_loggers() -> None:
    import fsm

    def quiet(msg: object) -> None:
        pass

    fsm.set_loggers(quiet, lambda m: print("[  WARN ] : " + str(m), file=sys.stderr), quiet,
                    lambda m: print("[ ERROR ] : " + str(m), file=sys.stderr))


def _print_episode(info: dict) -> None:
    print("episode {episode} seed {seed}: {outcome} (cube {cube_target_distance:.3f} m from target, "
          "{attempts} attempt(s), {sim_time:.1f} s simulated, {wall_time:.2f} s wall)".format(**info), flush=True)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    return run_demo(args)


def run_demo(args: argparse.Namespace) -> int:
    """Physics, action servers, the task machine, its recording, and unless headless the dashboard
    with the 3D view; until the episodes are done, Ctrl-C or SIGTERM. Everything is undone on exit."""
    import fsm
    from fsm.logfiles.recorder import Recorder

    if not args.verbose:
        _quiet_loggers()
    record_path = args.record or os.path.join("runs", time.strftime("demo-%Y%m%d-%H%M%S.jsonl"))
    os.makedirs(os.path.dirname(os.path.abspath(record_path)), exist_ok=True)
    demo = SimDemo(seed=args.seed, fast=args.fast, scene=not args.headless)
    machine = demo.build_machine()
    recorder = Recorder(record_path)
    fsm.attach(machine, recorder, name=MACHINE_NAME)
    resume = threading.Event()
    hold = threading.Event()
    server = None
    try:
        if not args.headless:
            from server.introspection_server import ServerThread

            server = ServerThread(host=args.host, port=args.port, token=args.token or None,
                                  scene_url=demo.scene.url if demo.scene is not None else None).start()
            server.hub.add_local(machine, name=MACHINE_NAME, can_start=True, starter=resume.set, holder=hold.set)
            print("fsmscope demo: open %s" % server.url, flush=True)
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
    worker.start()
    try:
        while worker.is_alive():
            worker.join(0.2)
    finally:
        demo.close()
        worker.join(5.0)
        if server is not None:
            server.stop()
        recorder.close()
        for s, h in old.items():
            signal.signal(s, h)
    print("fsmscope demo: %d episode(s) recorded to %s" % (len(results), record_path), flush=True)
    if failure:
        raise failure[0]
    if interrupted:
        return 128 + interrupted[0]  # as a shell reports a process ended by that signal: 130 Ctrl-C, 143 SIGTERM
    return 0 if results and all(r["outcome"] == "succeeded" for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
