"""A generated task machine of hundreds or thousands of states, the shape real ones grow to: nested
StateMachines several levels deep, some Concurrences, leaves with keys and remapping, a class
docstring; for the big-machine tests and benchmarks (issue 11).

    sm, stop = big_machine(branching=3, depth=4, leaves=14)   # 40 containers, 560 leaves: 600 states
    threading.Thread(target=sm.execute).start(); ...; stop.set()

The root loops through its children until ``stop`` is set, so a benchmark can run it as long as
it measures; every leaf waits ``tick`` seconds and counts its visits in its container's userdata.
"""

from __future__ import annotations

import threading
import time

import fsm

DONE, STOP = "done", "stopped"
KEY = "visits"  # the userdata key every container passes down: the leaves count into it
REMAPPING = {"count": KEY}  # a leaf's own key, remapped to its container's


class Work(fsm.State):
    """One unit of a task: waits a moment, counts its visits in ``count``, and says it is done."""

    def __init__(self, tick: float, stop: threading.Event) -> None:
        super().__init__(outcomes=[DONE, STOP], input_keys=["count"], output_keys=["count"])
        self.tick = tick
        self.stop = stop

    def execute(self, ud: fsm.UserData) -> str:
        if self.tick:
            time.sleep(self.tick)
        ud.count = ud.count + 1
        return STOP if self.stop.is_set() or self.preempt_requested() else DONE


def count_states(branching: int, depth: int, leaves: int) -> int:
    """How many states ``big_machine`` builds with these numbers (containers and leaves, the root included)."""
    containers = sum(branching ** level for level in range(depth))
    return containers + containers * leaves


def big_machine(branching: int = 3, depth: int = 4, leaves: int = 14, tick: float = 0.0,
                names: str = "TASK") -> tuple[fsm.StateMachine, threading.Event]:
    """(the machine, the event that ends it). Each container has ``leaves`` leaf states and, above the
    deepest level, ``branching`` sub-containers; every second container of the deepest level is a
    Concurrence of its leaves. ``names``: the prefix of container names (a test puts markup in it)."""
    stop = threading.Event()
    root = _container(0, "", branching, depth, leaves, tick, stop, names, loop=True)
    return root, stop


def _container(level: int, index: str, branching: int, depth: int, leaves: int, tick: float,
               stop: threading.Event, names: str, loop: bool = False) -> fsm.Container:
    deepest = level == depth - 1
    work = [("W%s_%d" % (index, i), Work(tick, stop)) for i in range(leaves)]
    if deepest and index and int(index.rsplit("_", 1)[-1]) % 2 == 1:
        cc = fsm.Concurrence(outcomes=[DONE, STOP], default_outcome=STOP,
                             outcome_map={DONE: {label: DONE for label, _ in work}}, input_keys=[KEY],
                             output_keys=[KEY])
        with cc:
            for label, state in work:
                fsm.Concurrence.add(label, state, remapping=REMAPPING)
        return cc
    subs = [] if deepest else [("%s%s_%d" % (names, index, i),
                                _container(level + 1, "%s_%d" % (index, i), branching, depth, leaves, tick, stop,
                                           names))
                               for i in range(branching)]
    children = work + subs
    sm = fsm.StateMachine(outcomes=[DONE, STOP], input_keys=[] if loop else [KEY], output_keys=[] if loop else [KEY])
    if loop:
        sm.userdata[KEY] = 0
    with sm:
        for i, (label, state) in enumerate(children):
            last = i == len(children) - 1
            after = (children[0][0] if loop else DONE) if last else children[i + 1][0]
            fsm.StateMachine.add(label, state, transitions={DONE: after, STOP: STOP},
                                 remapping=REMAPPING if isinstance(state, Work) else {})
    return sm
