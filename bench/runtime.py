"""Runtime throughput: a two-state loop, a 3-level nested machine, a Concurrence of 4 children,
each with no observer, a no-op observer and the recorder. Prints a table of medians of 5 runs.

    .venv/bin/python bench/runtime.py [--runs 5]
"""

import argparse
import os
import statistics
import sys
import tempfile
import time
from typing import Any

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import fsm as smach  # noqa: E402
from fsm.logfiles.recorder import Recorder  # noqa: E402

LOOP_TRANSITIONS = 100_000
NESTED_STEPS = 100_000
CONCURRENCE_RUNS = 10_000


def flip_class(smach: Any = smach, counts: bool = False) -> type:
    """A state of ``smach`` (fsm, or the original SMACH for bench/original_smach.py) that returns
    'next' until its budget is spent, then 'done' (and re-arms when told to); with ``counts``, it
    also adds one to the userdata's ``count`` at each run, as a task's states write what they did."""

    class Flip(smach.State):
        def __init__(self, budget: list, rearm: int = 0) -> None:
            smach.State.__init__(self, outcomes=["next", "done"], io_keys=["count"] if counts else [])
            self.budget = budget
            self.rearm = rearm

        def execute(self, ud):
            if counts:
                ud.count += 1
            budget = self.budget
            budget[0] -= 1
            if budget[0] > 0:
                return "next"
            budget[0] = self.rearm
            return "done"
    return Flip


def two_state_loop(smach: Any = smach, userdata: dict | None = None) -> tuple:
    """A <-> B until LOOP_TRANSITIONS; with ``userdata`` (which must hold ``count``), the machine
    starts with it and each state adds one to ``count``."""
    Flip = flip_class(smach, userdata is not None)
    budget = [0]
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", Flip(budget), transitions={"next": "B"})
        smach.StateMachine.add("B", Flip(budget), transitions={"next": "A"})

    def run():
        budget[0] = LOOP_TRANSITIONS + 1
        for key, value in (userdata or {}).items():
            sm.userdata[key] = value
        assert sm.execute() == "done"
        return LOOP_TRANSITIONS  # LOOP_TRANSITIONS + 1 executions: that many transitions, then termination
    return sm, run


def nested_machine(smach: Any = smach, userdata: dict | None = None) -> tuple:
    """ROOT(MID <-> D) > MID(INNER <-> C) > INNER(A <-> B): every level loops between a child
    container and a leaf. One step = one child execution at any level (it ends in a transition
    or a termination of its parent). ``userdata`` as for ``two_state_loop``."""
    steps = [0]
    Flip = flip_class(smach, userdata is not None)

    class Counting(smach.StateMachine):
        def execute(self, parent_ud=None):
            steps[0] += 1
            return smach.StateMachine.execute(self, parent_ud)

    class Leaf(Flip):
        def execute(self, ud):
            steps[0] += 1
            return Flip.execute(self, ud)

    keys = {"input_keys": ["count"], "output_keys": ["count"]} if userdata is not None else {}
    inner_budget, mid_budget, root_budget = [8], [3], [0]
    inner = Counting(outcomes=["done"], **keys)
    with inner:
        smach.StateMachine.add("A", Leaf(inner_budget, rearm=8), transitions={"next": "B"})
        smach.StateMachine.add("B", Leaf(inner_budget, rearm=8), transitions={"next": "A"})
    mid = Counting(outcomes=["done"], **keys)
    with mid:
        smach.StateMachine.add("INNER", inner, transitions={"done": "C"})
        smach.StateMachine.add("C", Leaf(mid_budget, rearm=3), transitions={"next": "INNER"})
    root = smach.StateMachine(outcomes=["done"])
    with root:
        smach.StateMachine.add("MID", mid, transitions={"done": "D"})
        smach.StateMachine.add("D", Leaf(root_budget), transitions={"next": "MID"})

    def run():
        steps[0] = 0
        root_budget[0] = NESTED_STEPS // 32  # one MID run is 31 steps, plus one D
        for key, value in (userdata or {}).items():
            root.userdata[key] = value
        assert root.execute() == "done"
        return steps[0]
    return root, run


def concurrence(smach: Any = smach, userdata: dict | None = None) -> tuple:
    """A Concurrence of 4 children run CONCURRENCE_RUNS times; with ``userdata`` (which must hold
    ``count``), it starts with it and each child adds one to ``count``."""
    def child(ud):
        if userdata is not None:
            ud.count += 1
        return "ok"

    keys = {"io_keys": ["count"]} if userdata is not None else {}
    cc = smach.Concurrence(outcomes=["done"], default_outcome="done")
    with cc:
        for label in "ABCD":
            smach.Concurrence.add(label, smach.CBState(child, outcomes=["ok"], **keys))

    def run():
        for key, value in (userdata or {}).items():
            cc.userdata[key] = value
        for _ in range(CONCURRENCE_RUNS):
            cc.execute()
        return CONCURRENCE_RUNS
    return cc, run


def measure(factory, mode: str, runs: int) -> float:
    rates = []
    for _ in range(runs):
        machine, run = factory()
        recorder = None
        if mode == "no-op observer":
            smach.attach(machine, lambda event: None)
        elif mode == "recorder":
            fd, path = tempfile.mkstemp(suffix=".jsonl")
            os.close(fd)
            recorder = Recorder(path)
            smach.attach(machine, recorder)
        start = time.perf_counter()
        count = run()
        elapsed = time.perf_counter() - start
        if recorder is not None:
            recorder.close()
            os.unlink(path)
            if os.path.exists(path + ".idx"):
                os.unlink(path + ".idx")
        rates.append(count / elapsed)
    return statistics.median(rates)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    quiet = lambda msg: None  # noqa: E731  (loggers off, as the reference numbers were taken)
    smach.set_loggers(quiet, quiet, quiet, quiet)
    rows = [
        ("two-state loop", "transitions/s", two_state_loop, 400_000, 340_000),
        ("3-level nested", "steps/s", nested_machine, None, 140_000),
        ("Concurrence of 4", "executions/s", concurrence, 10_000, 640),
    ]
    print("| workload | unit | no observer | no-op observer | recorder | recorder cost | target (no observer) | reference SMACH |")
    print("|---|---|---|---|---|---|---|---|")
    for name, unit, factory, target, reference in rows:
        base = measure(factory, "none", args.runs)
        noop = measure(factory, "no-op observer", args.runs)
        rec = measure(factory, "recorder", args.runs)
        cost = 1 - rec / base
        verdict = "" if target is None else (" (ok)" if base >= target else " (MISSED)")
        print("| %s | %s | %s | %s | %s | %.0f%% (target <= 40%%)%s | %s%s | ~%s |" % (
            name, unit, f"{base:,.0f}", f"{noop:,.0f}", f"{rec:,.0f}", cost * 100,
            " (ok)" if cost <= 0.40 else " (MISSED)",
            "-" if target is None else f">= {target:,}", verdict, f"{reference:,}"))


if __name__ == "__main__":
    main()
