"""Benchmarks of the simulated arm: physics speed, episode wall time, CPU of the demo.

    .venv/bin/python bench/sim.py            # prints a table against the targets

Each figure is the median of 5 runs. CPU is process CPU time / wall time over a
window, in percent of one core, with no browser connected.
"""

from __future__ import annotations

import os
import resource
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

import fsm  # noqa: E402
from fsm.ros.bus import Bus  # noqa: E402
from fsmscope.sim.world import HOME_Q, World  # noqa: E402

RUNS = 5


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def bench_raw_steps(n: int = 20000) -> float:
    """Bare mj_step on the model, arm holding still (steps/s)."""
    w = World(seed=0)
    m, d = w.model, w.data
    t = time.perf_counter()
    for _ in range(n):
        mujoco.mj_step(m, d)
    return n / (time.perf_counter() - t)


def bench_world_steps(n: int = 20000) -> float:
    """World stepping while the arm follows a joint path (set point per step)."""
    w = World(seed=0)
    q1 = HOME_Q + np.array([0.6, 0.3, -0.3, 0.0, 0.2, 0.5])
    w.follow(np.array([HOME_Q, q1]), duration=n * w.model.opt.timestep)
    t = time.perf_counter()
    w.step(n)
    return n / (time.perf_counter() - t)


def bench_episode(seed: int) -> tuple[float, str]:
    from fsmscope.sim.demo import SimDemo

    d = SimDemo(seed=seed, fast=True, scene=False, bus=Bus())
    try:
        t = time.perf_counter()
        [info] = d.run(episodes=1)
        return time.perf_counter() - t, info["outcome"]
    finally:
        d.close()


def bench_cpu(window: float, scene: bool, always: bool) -> float:
    """CPU % of one core: physics at real time, optionally the viser view at 30 Hz."""
    w = World(seed=0).start()
    sc = None
    try:
        if scene:
            from fsmscope.sim.scene import start_scene

            sc = start_scene(w, always=always)
        time.sleep(0.5)
        c0, t0 = _cpu(), time.perf_counter()
        time.sleep(window)
        return 100.0 * (_cpu() - c0) / (time.perf_counter() - t0)
    finally:
        if sc is not None:
            sc.stop()
        w.stop()


def main() -> int:
    def quiet(msg):
        pass
    fsm.set_loggers(quiet, quiet, quiet, quiet)
    dt = World(seed=0).model.opt.timestep
    rows = []
    raw = statistics.median(bench_raw_steps() for _ in range(RUNS))
    rows.append(("physics, bare mj_step", f"{raw:,.0f} steps/s", ">= 60k steps/s"))
    rows.append(("  real-time factor", f"{raw * dt:,.0f}x", ">= 100x"))
    ws = statistics.median(bench_world_steps() for _ in range(RUNS))
    rows.append(("physics, World.step following a path", f"{ws:,.0f} steps/s", ">= 50k steps/s"))
    rows.append(("  real-time factor", f"{ws * dt:,.0f}x", ">= 100x"))
    eps = [bench_episode(s) for s in range(RUNS)]
    assert all(o == "succeeded" for _, o in eps), eps
    ep = statistics.median(t for t, _ in eps)
    rows.append(("episode wall time at --fast (seeds 0-4)", f"{ep * 1000:,.0f} ms", "< 1000 ms"))
    window = 4.0
    cpu_phys = bench_cpu(window, scene=False, always=False)
    rows.append(("CPU, physics at real time", f"{cpu_phys:.1f} %", "~2.5 %"))
    cpu_idle = bench_cpu(window, scene=True, always=False)
    rows.append(("CPU, + viser view, no browser (draws skipped)", f"{cpu_idle:.1f} %", "< 15 %"))
    cpu_30 = bench_cpu(window, scene=True, always=True)
    rows.append(("CPU, + viser view drawing at 30 Hz, no browser", f"{cpu_30:.1f} %", "< 15 %"))

    w1 = max(len(r[0]) for r in rows)
    w2 = max(len(r[1]) for r in rows)
    print(f"{'measure':<{w1}}  {'result':>{w2}}  target")
    print("-" * (w1 + w2 + 20))
    for name, val, target in rows:
        print(f"{name:<{w1}}  {val:>{w2}}  {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
