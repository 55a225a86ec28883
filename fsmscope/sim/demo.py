"""The demo's simulation: the pick-and-place machine running episodes on the simulated arm.

``SimDemo`` wires the world, the action servers and the 3D view together; ``run_episodes``
is the loop (reset, build or reuse the machine, execute, wait for a start after a preempt).
``fsmscope demo`` (fsmscope/server/cli/demo.py) adds the recording and the dashboard.

For embedding::

    demo = SimDemo(seed=0, fast=False, bus=None, scene=True)   # world, servers, 3D view
    results = demo.run(episodes=5, on_episode=print)            # blocks
    demo.request_stop()                                         # from any thread: preempt + end loop
    demo.close()                                                # threads joined, ports freed
"""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING, Any, Callable

if TYPE_CHECKING:
    from .world import World

Machine = Any


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

