"""A robot's patrol, run by the fleet tests as a user's script (`fsmscope run robots/patrol.py --zenoh ROBOT`):
MOVE -> SCAN -> MOVE ... until preempted; with the argument "fail", SCAN raises on its third visit."""
import sys
import time

import fsm

FAIL = "fail" in sys.argv[1:]


class Step(fsm.State):
    def __init__(self, pause, fail=False):
        fsm.State.__init__(self, ["go", "preempted"])
        self.pause, self.fail, self.visits = pause, fail, 0

    def execute(self, ud):
        self.visits += 1
        end = time.monotonic() + self.pause
        while time.monotonic() < end:
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
            time.sleep(0.01)
        if self.fail and self.visits >= 3:
            raise RuntimeError("the scanner stopped answering")
        return "go"


sm = fsm.StateMachine(["preempted"])
with sm:
    fsm.StateMachine.add("MOVE", Step(0.2), {"go": "SCAN", "preempted": "preempted"})
    fsm.StateMachine.add("SCAN", Step(0.15, FAIL), {"go": "MOVE", "preempted": "preempted"})
sm.execute()
