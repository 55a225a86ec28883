"""Machines of a few dozen states, the size a newcomer's own script is (issue 31 item 7): a mission of
31 states with three sub-machines, and a plain sequence; for the overview's tests and benchmark.

    sm = mission_machine(gate)   # waits in its first step until ``gate`` (a threading.Event) is set
"""

from __future__ import annotations

import threading

import fsm

# The mission's steps: twelve, three of them sub-machines of six; 31 states with the root.
MISSION = ["INIT", "CHECK_BATTERY", "LOCALIZE",
           ("NAVIGATE", ["PLAN_PATH", "FOLLOW_PATH", "AVOID", "REPLAN", "ARRIVE", "ALIGN"]), "DETECT",
           ("GRASP", ["OPEN_GRIPPER", "APPROACH", "DESCEND", "CLOSE", "VERIFY", "LIFT"]),
           ("DELIVER", ["TRANSPORT", "LOWER", "RELEASE", "RETREAT", "CONFIRM", "LOG_RESULT"]),
           "RETURN_HOME", "DOCK", "CHARGE", "REPORT", "SHUTDOWN"]


def mission_machine(gate: threading.Event | None = None) -> fsm.StateMachine:
    """``MISSION`` as a machine: each step says 'done' (a step waits for ``gate`` when one is given),
    'failed' ends its machine 'aborted'."""
    def step(ud) -> str:
        if gate is not None:
            gate.wait()
        return "done"

    def machine(steps: list) -> fsm.StateMachine:
        sm = fsm.StateMachine(outcomes=["succeeded", "aborted"])
        with sm:
            for i, entry in enumerate(steps):
                label = entry if isinstance(entry, str) else entry[0]
                after = steps[i + 1] if i + 1 < len(steps) else "succeeded"
                after = after if isinstance(after, str) else after[0]
                if isinstance(entry, str):
                    fsm.StateMachine.add(label, fsm.CBState(step, outcomes=["done", "failed"]),
                                         {"done": after, "failed": "aborted"})
                else:
                    fsm.StateMachine.add(label, machine(entry[1]), {"succeeded": after, "aborted": "aborted"})
        return sm

    return machine(MISSION)


def sequence_machine(steps: int) -> fsm.StateMachine:
    """S0 -> S1 -> ... -> succeeded, each step able to fail the whole ('aborted')."""
    sm = fsm.StateMachine(outcomes=["succeeded", "aborted"])
    with sm:
        for i in range(steps):
            after = "S%d" % (i + 1) if i + 1 < steps else "succeeded"
            fsm.StateMachine.add("S%d" % i, fsm.CBState(lambda ud: "done", outcomes=["done", "failed"]),
                                 {"done": after, "failed": "aborted"})
    return sm
